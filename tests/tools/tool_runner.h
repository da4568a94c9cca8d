// Runs the built `brdf` tool (BRDF_TOOL) as a user runs it and captures what it prints, and a
// fixture giving each test its own scratch folder.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/file_util.h"

namespace brdf::testing {

struct ToolRun {
  int exit_code = -1;
  std::string out, err;

  // stderr split into lines (without the newlines).
  std::vector<std::string> ErrLines() const {
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (start < err.size()) {
      const std::size_t end = err.find('\n', start);
      lines.push_back(err.substr(start, end == std::string::npos ? end : end - start));
      if (end == std::string::npos) break;
      start = end + 1;
    }
    return lines;
  }
};

// `args` is passed to the shell as is: quote paths with '...'.
inline ToolRun RunTool(const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path err_file = dir / "stderr.txt";
  const std::string cmd = std::string(BRDF_TOOL) + " " + args + " 2>'" + err_file.string() + "'";
  ToolRun r;
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = ReadFileText(err_file.string(), 1 << 20);
  return r;
}

inline std::string Quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

class ToolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("brdf_tool_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name() + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  ToolRun Run(const std::string& args) const { return RunTool(args, dir_); }
  std::filesystem::path dir_;
};

}  // namespace brdf::testing
