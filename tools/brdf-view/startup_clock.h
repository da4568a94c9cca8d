// Start-up timing for brdf-view (BRDF_VIEW_TIMING=1): how long after the process started a
// milestone was reached, in wall-clock and CPU time, as one line on stderr.
//
// "Process start" is the kernel's start time of this process (/proc/self/stat, field 22, in
// clock ticks of 10 ms since boot, on the same clock as CLOCK_BOOTTIME), so the figure includes
// loading the executable's shared libraries, which happens before any of our code runs.
// CPU time is user + system of every thread of the process so far (getrusage).
#pragma once

namespace brdf::view_tool {

struct StartupTime {
  double wall_ms = -1;  // −1 when /proc/self/stat cannot be read
  double cpu_ms = 0;
};

StartupTime TimeSinceProcessStart();

// Prints "brdf-view: timing: <milestone> at <wall> ms wall, <cpu> ms CPU after process start".
void PrintMilestone(const char* milestone);

}  // namespace brdf::view_tool
