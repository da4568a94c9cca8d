// Inputs that are not regular files (FIFOs, folders, devices) are refused at once with one line
// naming the file and what it is, and never block; a huge sparse file with a small capture at
// its start costs memory for the capture, not for the file's size (peak RSS of the child
// process from wait4, compared with a bound far below the file size).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

const std::string kGoldCapture = std::string(BRDF_SOURCE_DIR) + "/data-samples/captures/gold.bpc";

// Runs `brdf <args>` (stdout and stderr to files in `dir`) and returns the exit code and the
// child's peak resident set size in KiB.
std::pair<int, long> RunMeasured(const std::string& args, const fs::path& dir) {
  const std::string cmd = "exec " + std::string(BRDF_TOOL) + " " + args + " >'" +
                          (dir / "m.out").string() + "' 2>'" + (dir / "m.err").string() + "'";
  const pid_t child = ::fork();
  if (child == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  struct rusage usage {};
  ::wait4(child, &status, 0, &usage);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, usage.ru_maxrss};
}

class SpecialFiles : public ToolTest {};

TEST_F(SpecialFiles, FifosAreRefusedAtOnceByEveryReadingCommand) {
  for (const std::string name :
       {"cap.bpc", "mat.json", "lut.ktx2", "lut.dds", "t.bsdf", "p.csv", "m.binary"}) {
    const fs::path fifo = dir_ / name;
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << fifo;
    // `timeout` turns a hang into exit code 124 instead of a stuck test.
    // (info and eval classify through tools/brdf/sources.cpp, which is to call
    // brdf::CheckRegularFile; their cases join this list when it does.)
    for (const std::string& args :
         {"convert " + Quote(fifo) + " --quiet --out " + Quote(dir_ / "o"),
          "import " + Quote(fifo) + " --out " + Quote(dir_ / "i.bpc")}) {
      SCOPED_TRACE(args);
      const std::string timed = "timeout 20 " + std::string(BRDF_TOOL) + " " + args;
      const int status =
          std::system((timed + " >/dev/null 2>'" + (dir_ / "e.txt").string() + "'").c_str());
      ASSERT_TRUE(WIFEXITED(status));
      EXPECT_NE(WEXITSTATUS(status), 124) << "blocked on the FIFO";
      EXPECT_NE(WEXITSTATUS(status), 0);
      const std::string err = ReadAll(dir_ / "e.txt");
      EXPECT_NE(err.find(fifo.string()), std::string::npos) << err;
      EXPECT_NE(err.find("FIFO"), std::string::npos) << err;
      EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    }
  }
}

TEST_F(SpecialFiles, FoldersAndDevicesAreRefusedWithWhatTheyAre) {
  const std::string folder = (dir_ / "folder.bpc").string();
  fs::create_directories(folder);
  struct Case {
    std::string args, path, kind;
  };
  for (const Case& c :
       {Case{"import " + Quote(folder) + " --out " + Quote(dir_ / "i.bpc"), folder, "a folder"},
        Case{"import /dev/zero --out " + Quote(dir_ / "i.bpc"), "/dev/zero", "a device"},
        Case{"convert /dev/zero --quiet --out " + Quote(dir_ / "o"), "/dev/zero", "a device"}}) {
    SCOPED_TRACE(c.args);
    const std::string timed = "timeout 20 " + std::string(BRDF_TOOL) + " " + c.args;
    const int status =
        std::system((timed + " >/dev/null 2>'" + (dir_ / "e.txt").string() + "'").c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 124);
    EXPECT_NE(WEXITSTATUS(status), 0);
    const std::string err = ReadAll(dir_ / "e.txt");
    EXPECT_NE(err.find(c.path), std::string::npos) << err;
    EXPECT_NE(err.find("is " + c.kind + ", not a file"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
}

TEST_F(SpecialFiles, ASparseThreeGigabyteFileWithASmallCaptureCostsTheCaptureNotTheFile) {
  const fs::path sparse = dir_ / "sparse.bpc";
  fs::copy_file(kGoldCapture, sparse);
  const std::uintmax_t capture_bytes = fs::file_size(sparse);
  {
    const int fd = ::open(sparse.c_str(), O_WRONLY);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, 3ll << 30), 0);
    ::close(fd);
  }
  ASSERT_EQ(fs::file_size(sparse), 3ull << 30);
  ASSERT_LT(capture_bytes, 16u << 20);
  // The tool itself (libraries, a capture of ~5 MB and its LUT) stays far below this; reading
  // the file into memory would cost 3 GiB.
  constexpr long kBoundKib = 768 * 1024;
  for (const std::string& args :
       {"info " + Quote(sparse), "eval " + Quote(sparse) + " --in 20,0 --out 20,180",
        "convert " + Quote(sparse) + " --quiet --formats ktx2 --out " + Quote(dir_ / "o")}) {
    SCOPED_TRACE(args);
    const auto [code, peak_kib] = RunMeasured(args, dir_);
    EXPECT_TRUE(code == 0 || code == 1) << code << ": " << ReadAll(dir_ / "m.err");
    EXPECT_LT(peak_kib, kBoundKib) << ReadAll(dir_ / "m.err");
  }
}

}  // namespace
}  // namespace brdf::tooltest
