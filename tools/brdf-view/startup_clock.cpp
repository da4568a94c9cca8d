#include "startup_clock.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>

namespace brdf::view_tool {

StartupTime TimeSinceProcessStart() {
  StartupTime t;
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) == 0) {
    t.cpu_ms = (usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) * 1e3 +
               (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-3;
  }
  std::ifstream stat("/proc/self/stat");
  std::string line;
  if (!std::getline(stat, line)) return t;
  // Field 2 (the command name) is in parentheses and may hold spaces: count from the last ')'.
  const std::size_t close = line.rfind(')');
  if (close == std::string::npos) return t;
  std::istringstream fields(line.substr(close + 1));
  std::string field;
  unsigned long long start_ticks = 0;
  for (int n = 3; n <= 22 && fields >> field; ++n) {
    if (n == 22) start_ticks = std::stoull(field);
  }
  const long ticks_per_s = sysconf(_SC_CLK_TCK);
  timespec now{};
  if (start_ticks == 0 || ticks_per_s <= 0 || clock_gettime(CLOCK_BOOTTIME, &now) != 0) return t;
  const double now_ms = now.tv_sec * 1e3 + now.tv_nsec * 1e-6;
  t.wall_ms = now_ms - static_cast<double>(start_ticks) * 1e3 / static_cast<double>(ticks_per_s);
  return t;
}

void PrintMilestone(const char* milestone) {
  const StartupTime t = TimeSinceProcessStart();
  std::fprintf(stderr, "brdf-view: timing: %s at %.0f ms wall, %.0f ms CPU after process start\n",
               milestone, t.wall_ms, t.cpu_ms);
}

}  // namespace brdf::view_tool
