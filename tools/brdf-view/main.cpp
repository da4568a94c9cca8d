// `brdf-view`: the VTK window onto a BRDF source (lobe, slice heat maps, environment-lit
// preview). This is the only translation unit of brdf-view that sees CLI11; it parses the
// options, makes sure there is an X display (running itself under xvfb-run for a
// screenshot when there is none), opens the sources and hands them to brdf::viewer::RunViewer.
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <filesystem>
#include <fstream>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/measurement.h"
#include "brdf/viewer/app.h"
#include "open_source.h"
#include "startup_clock.h"

namespace {

constexpr const char* kXvfbGuard = "BRDF_VIEW_UNDER_XVFB";
// Set (to anything non-empty) to print start-up milestones on stderr (docs/benchmarks.md).
constexpr const char* kTimingVariable = "BRDF_VIEW_TIMING";
// Exit code of a run under xvfb-run whose display could not be opened: concurrent
// `xvfb-run -a` calls sometimes pick the same display number, so the parent tries again.
constexpr int kDisplayRetry = 75;
constexpr int kXvfbAttempts = 3;

// "WxH" → width, height; an error text otherwise.
std::string ParseSize(const std::string& text, int* width, int* height) {
  const auto x = text.find_first_of("xX");
  const std::string bad = "expected WIDTHxHEIGHT in pixels (e.g. 960x720), got '" + text + "'";
  if (x == std::string::npos || x == 0 || x + 1 >= text.size()) return bad;
  const std::string w = text.substr(0, x), h = text.substr(x + 1);
  // Up to nine digits, so that 100000x100000 is refused for its size, not its form.
  auto digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 9 &&
           std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!digits(w) || !digits(h)) return bad;
  *width = std::stoi(w);
  *height = std::stoi(h);
  if (*width < 64 || *height < 64 || *width > 8192 || *height > 8192) {
    return "the size must be 64 to 8192 pixels each way, got '" + text + "'";
  }
  return {};
}

std::string FindOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string candidate = dirs.substr(start, end - start) + "/" + program;
    if (end > start && access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return {};
}

// xvfb-run sometimes leaves its Xvfb running after a short run (seen when the program exits
// within a second). That server is recognised exactly, by the unique status-file path in its
// environment (it inherits ours), and stopped by its pid.
void StopLeftoverXvfb(const std::string& status_path) {
  const std::string marker = std::string(kXvfbGuard) + "=" + status_path;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
    std::ifstream comm(entry.path() / "comm");
    std::string command;
    if (!std::getline(comm, command) || command != "Xvfb") continue;
    std::ifstream environ(entry.path() / "environ", std::ios::binary);
    std::string variable;
    while (std::getline(environ, variable, '\0')) {
      if (variable == marker) {
        kill(static_cast<pid_t>(std::stol(name)), SIGTERM);
        break;
      }
    }
  }
}

// Runs `xvfb-run -a -s "-screen 0 WxHx24" <this program> <args>` and returns the exit code of
// this program's run under it. That code travels through a file: xvfb-run itself sometimes
// exits 5 ("problem while cleaning up temporary directory") after a successful run when
// several Xvfb servers start and stop at once. Returns -1 if xvfb-run could not be started.
int RunUnderXvfb(const std::string& xvfb_run, int argc, char** argv, int width, int height) {
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) return -1;
  self[n] = '\0';
  char status_path[] = "/tmp/brdf-view-status-XXXXXX";
  const int fd = mkstemp(status_path);
  if (fd < 0) return -1;
  close(fd);
  setenv(kXvfbGuard, status_path, 1);
  const std::string screen = "-screen 0 " + std::to_string(std::max(width, 1280)) + "x" +
                             std::to_string(std::max(height, 1024)) + "x24";
  std::vector<std::string> args = {xvfb_run, "-a", "-s", screen, self};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  // xvfb-run's own complaint about its temporary folder is not the user's business: stderr
  // passes through a pipe that drops it.
  int err_pipe[2];
  if (pipe(err_pipe) != 0) return -1;
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    close(err_pipe[0]);
    dup2(err_pipe[1], STDERR_FILENO);
    close(err_pipe[1]);
    execv(xvfb_run.c_str(), cargs.data());
    _exit(127);
  }
  close(err_pipe[1]);
  if (FILE* err = fdopen(err_pipe[0], "r")) {
    char line[4096];
    while (std::fgets(line, sizeof line, err) != nullptr) {
      if (std::strstr(line, "xvfb-run: error: problem while cleaning up") == nullptr) {
        std::fputs(line, stderr);
      }
    }
    std::fclose(err);
  }
  int wstatus = 0;
  while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
  }
  StopLeftoverXvfb(status_path);
  int code = -1;
  if (FILE* f = std::fopen(status_path, "r")) {
    if (std::fscanf(f, "%d", &code) != 1) code = -1;
    std::fclose(f);
  }
  std::remove(status_path);
  if (code >= 0) return code;
  return WIFEXITED(wstatus) && WEXITSTATUS(wstatus) != 0 ? WEXITSTATUS(wstatus) : 1;
}

// Under RunUnderXvfb: leaves the exit code where the parent reads it, then exits.
int Finish(int code) {
  if (const char* status_path = std::getenv(kXvfbGuard)) {
    if (FILE* f = std::fopen(status_path, "w")) {
      std::fprintf(f, "%d\n", code);
      std::fclose(f);
    }
  }
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  const char* timing_variable = std::getenv(kTimingVariable);
  const bool timing = timing_variable != nullptr && *timing_variable != '\0';
  if (timing) brdf::view_tool::PrintMilestone("main");
  CLI::App app{
      "brdf-view: reflection lobes, LUT slice heat maps and environment-lit previews of any "
      "BRDF the toolchain reads (capture, material, exported LUT, RGL, MERL, tables)"};
  app.set_version_flag("--version", std::string("brdf-toolchain ") + brdf::SoftwareVersion());
  std::string source, compare, mode_name = "lobe", screenshot, size_text = "960x720";
  double theta_in_deg = 0;
  app.add_option("source", source,
                 "File to view (.bpc, material .json, .ktx2/.dds/sidecar, RGL .bsdf, MERL "
                 ".binary, Zemax/LightTools/CSV table) or a library material name ('brdf "
                 "materials' lists them; a file of the same name wins)")
      ->required();
  app.add_option("--compare", compare,
                 "Second source drawn over the first (e.g. a fit over its measurement)");
  app.add_option("--mode", mode_name, "What to show")
      ->check(CLI::IsMember({"lobe", "slices", "preview"}))
      ->capture_default_str();
  app.add_option("--theta-in", theta_in_deg,
                 "Light polar angle in degrees; between measured slices the lobe is the LUT's "
                 "interpolation")
      ->check(CLI::Range(0.0, 89.0))
      ->capture_default_str();
  app.add_option("--screenshot", screenshot,
                 "Render once to this PNG and exit (no window; uses xvfb-run when there is no "
                 "X display). Also writes FILE.png.json with the camera");
  app.add_option("--size", size_text, "Window or picture size in pixels, WIDTHxHEIGHT")
      ->check(CLI::Validator(
          [](std::string& text) {
            int w = 0, h = 0;
            return ParseSize(text, &w, &h);
          },
          "WxH"))
      ->capture_default_str();
  std::string channel = "luminance";
  bool log_scale = false, cosine_weighted = false, all_slices = false;
  app.add_option("--channel", channel, "Channel the lobe and heat maps show")
      ->check(CLI::IsMember({"R", "G", "B", "luminance"}))
      ->capture_default_str();
  app.add_flag("--log", log_scale, "Log scale for the lobe radius and the colours");
  app.add_flag("--cos", cosine_weighted, "Lobe radius f_r·cosθo instead of f_r");
  app.add_flag("--all-slices", all_slices, "Every measured slice at once");
  bool force = false;
  app.add_flag("--force", force,
               "With --screenshot: overwrite FILE.png and FILE.png.json if they already exist");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    // One line, like every other error (CLI11's own message may hold newlines).
    std::string what = e.what();
    for (char& c : what)
      if (c == '\n') c = ' ';
    std::fprintf(stderr, "brdf-view: %s (see 'brdf-view --help')\n", what.c_str());
    return 2;
  }

  brdf::viewer::ViewerOptions options;
  ParseSize(size_text, &options.width, &options.height);
  options.mode = brdf::viewer::ModeFromName(mode_name);
  options.theta_in_deg = theta_in_deg;
  options.screenshot_path = screenshot;
  options.channel = channel == "R" ? 0 : channel == "G" ? 1 : channel == "B" ? 2 : 3;
  options.log_scale = log_scale;
  options.cosine_weighted = cosine_weighted;
  options.all_slices = all_slices;
  if (timing) options.on_milestone = brdf::view_tool::PrintMilestone;
  // A screenshot is one small frame: Mesa's CPU rasteriser (llvmpipe, e.g. under Xvfb) then
  // spends more time handing it to its worker threads and waiting for them to be scheduled
  // than drawing it, most of all on a busy machine (docs/benchmarks.md, viewer start-up).
  // LP_NUM_THREADS=0 (a documented Mesa variable) draws on the calling thread; the user's own
  // setting wins, and other OpenGL drivers ignore it.
  if (!screenshot.empty()) setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);

  if (!screenshot.empty()) {
    // The picture is written as PNG, so only a .png name is taken (a .jpg name got PNG bytes).
    const std::string ext = std::filesystem::path(screenshot).extension().string();
    if (ext != ".png" && ext != ".PNG") {
      std::fprintf(stderr, "brdf-view: error: --screenshot: expected a .png file name, got '%s'\n",
                   screenshot.c_str());
      return Finish(1);
    }
    // The overwrite rule of every writing command (brdf/core/file_util.h), before any work: it
    // also refuses a missing or unwritable folder, a name beyond NAME_MAX and a target that is
    // not a regular file (`--screenshot /dev/null` would have written /dev/null.json).
    try {
      brdf::CheckWritableOutputs({screenshot, screenshot + ".json"}, force);
    } catch (const brdf::Error& e) {
      std::fprintf(stderr, "brdf-view: error: %s%s\n", e.what(),
                   brdf::view_tool::RemedyText(e.remedy()).c_str());
      return Finish(1);
    }
  }

  const std::string display_problem = brdf::viewer::DisplayProblem();
  if (!display_problem.empty()) {
    if (screenshot.empty()) {
      std::fprintf(stderr,
                   "brdf-view: %s; the window needs an X display (use --screenshot FILE.png to "
                   "render a picture without one)\n",
                   display_problem.c_str());
      return 1;
    }
    if (std::getenv(kXvfbGuard) != nullptr) return Finish(kDisplayRetry);
    const std::string xvfb_run = FindOnPath("xvfb-run");
    if (!xvfb_run.empty()) {
      int code = -1;
      for (int attempt = 0; attempt < kXvfbAttempts; ++attempt) {
        code = RunUnderXvfb(xvfb_run, argc, argv, options.width, options.height);
        if (code != kDisplayRetry) break;
      }
      if (code >= 0 && code != kDisplayRetry) return code;
    }
    if (xvfb_run.empty()) {
      std::fprintf(stderr,
                   "brdf-view: %s and xvfb-run is not installed: install the Debian packages "
                   "xvfb and xauth (tools/install-deps.sh) or run inside an X session\n",
                   display_problem.c_str());
    } else {
      std::fprintf(stderr,
                   "brdf-view: no usable X display even under xvfb-run (%s), tried %d times\n",
                   xvfb_run.c_str(), kXvfbAttempts);
    }
    return 1;
  }

  try {
    // Both sources open on threads of their own while the window is being created.
    bool compare_failed = false;
    brdf::viewer::SourceOpener open_compare;
    if (!compare.empty()) {
      open_compare = [&compare, &compare_failed] {
        brdf::viewer::LoadedSource second = brdf::view_tool::OpenViewSource(compare);
        if (!second.error.empty()) {
          compare_failed = true;
          std::fprintf(stderr, "brdf-view: error: --compare: %s\n", second.error.c_str());
        }
        return second;
      };
    }
    const brdf::viewer::ViewerResult result = brdf::viewer::RunViewer(
        options, [&source] { return brdf::view_tool::OpenViewSource(source); }, open_compare);
    if (!result.ok) {
      if (result.display_failed && std::getenv(kXvfbGuard) != nullptr) {
        return Finish(kDisplayRetry);  // the parent starts another Xvfb
      }
      if (!result.message.empty()) std::fprintf(stderr, "brdf-view: %s\n", result.message.c_str());
      return Finish(1);
    }
    return Finish(compare_failed && !screenshot.empty() ? 1 : 0);
  } catch (const brdf::Error& e) {
    std::fprintf(stderr, "brdf-view: error: %s\n", e.what());
    return Finish(1);
  }
}
