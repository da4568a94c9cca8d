// What every test program may need from its surroundings: the third-party data folder and a
// private temporary folder.
//
// Third-party data (real measured files that are never copied into the repository) is found
// through the environment variable BRDF_DATA_DIR, read when a test runs; without it, the
// folder configured at build time (CMake cache variable BRDF_DATA_DIR, by default
// <repository>/../shared/brdf-data). A test that needs the data and cannot find it fails with
// one line naming BRDF_DATA_DIR; it never skips.
//
// Every test writes below its own folder made by mkdtemp(3) in $TMPDIR (or /tmp), so two test
// runs on one machine, or two tests of one run, never share a file name.
#pragma once

#include <stdlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace brdf::test {

// The third-party data folder: $BRDF_DATA_DIR if set and non-empty, else the build's default.
// Throws std::runtime_error (which fails the calling test) when the folder does not exist.
inline std::string DataDir() {
  const char* env = std::getenv("BRDF_DATA_DIR");
  const std::string dir =
      (env != nullptr && *env != '\0') ? std::string(env) : std::string(BRDF_DATA_DIR_DEFAULT);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw std::runtime_error("third-party data folder '" + dir +
                             "' not found: set BRDF_DATA_DIR to the brdf-data folder "
                             "(see README.md, 'Test data')");
  return dir;
}

// DataDir()/relative; throws std::runtime_error naming BRDF_DATA_DIR when it is missing.
inline std::string DataPath(std::string_view relative) {
  const std::string path = DataDir() + "/" + std::string(relative);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw std::runtime_error("third-party data file '" + path +
                             "' not found: BRDF_DATA_DIR must point to the brdf-data folder "
                             "(see README.md, 'Test data')");
  return path;
}

// A new, empty, private folder "<tmp>/brdf-<tag>-XXXXXX"; removed with its content by the
// destructor (kept when BRDF_KEEP_TEST_OUTPUT is set, for looking at after a failure).
class ScopedTempDir {
 public:
  explicit ScopedTempDir(std::string_view tag = "test") : path_(MakeTempDir(tag)) {}
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;
  ~ScopedTempDir() {
    if (std::getenv("BRDF_KEEP_TEST_OUTPUT") != nullptr) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& p) const { return path_ / p; }

  // Creates the folder; throws std::runtime_error if mkdtemp fails.
  static std::filesystem::path MakeTempDir(std::string_view tag) {
    std::string pattern =
        (std::filesystem::temp_directory_path() / ("brdf-" + std::string(tag) + "-XXXXXX"))
            .string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("cannot create a temporary folder from " + pattern + ": " +
                               std::strerror(errno));
    return pattern;
  }

 private:
  std::filesystem::path path_;
};

// A new private folder like ScopedTempDir, removed when the test program exits: for helpers
// that hand out paths (a folder per call, never reused).
inline std::filesystem::path NewTempDir(std::string_view tag) {
  static std::vector<std::unique_ptr<ScopedTempDir>> dirs;
  dirs.push_back(std::make_unique<ScopedTempDir>(tag));
  return dirs.back()->path();
}

// Runs `command` through /bin/sh and returns its stdout and its exit status (pclose: 0 on
// success; -1 if the command could not be started). For the numpy oracles of tests/python/.
struct CommandOutput {
  int status = -1;
  std::string out;
};
inline CommandOutput RunCommand(const std::string& command) {
  CommandOutput r;
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  r.status = ::pclose(pipe);
  return r;
}

}  // namespace brdf::test
