// The one overwrite rule of every writing command (brdf::CheckWritableOutputs; README "Writing
// files"): an existing output is refused with one line naming it and --force, nothing is
// changed, and --force replaces it; an output path that is a folder is refused even with
// --force. The expected bytes come from the first run's files, compared before and after.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

const std::string kGoldCapture = std::string(BRDF_SOURCE_DIR) + "/data-samples/captures/gold.bpc";

class Overwrite : public ToolTest {
 protected:
  // Runs `args` twice: the second run must be refused with one line naming `out` and --force,
  // and leave `out` as the first run wrote it; a third run with --force must succeed.
  void ExpectRefusedThenForced(const std::string& args, const fs::path& out) {
    const ToolRun first = Run(args);
    ASSERT_EQ(first.exit_code, 0) << args << "\n" << first.err;
    ASSERT_TRUE(fs::exists(out)) << out;
    const std::string before = ReadAll(out);
    fs::last_write_time(out, fs::file_time_type::clock::now() - std::chrono::hours(1));
    const auto stamp = fs::last_write_time(out);

    const ToolRun second = Run(args);
    EXPECT_EQ(second.exit_code, 1) << args << "\n" << second.err;
    const std::vector<std::string> lines = second.ErrLines();
    ASSERT_EQ(lines.size(), 1u) << second.err;
    EXPECT_NE(lines[0].find(out.filename().string()), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("already exists"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("--force"), std::string::npos) << lines[0];
    EXPECT_EQ(ReadAll(out), before);
    EXPECT_EQ(fs::last_write_time(out), stamp) << "the refused run touched " << out;

    const ToolRun forced = Run(args + " --force");
    EXPECT_EQ(forced.exit_code, 0) << forced.err;
    EXPECT_NE(fs::last_write_time(out), stamp) << "--force did not rewrite " << out;
  }
};

TEST_F(Overwrite, ConvertRefusesExistingOutputsWithoutForce) {
  ExpectRefusedThenForced("convert " + Quote(kGoldCapture) + " --quiet --formats ktx2,json --out " +
                              Quote(dir_ / "luts"),
                          dir_ / "luts" / "gold.ktx2");
}

TEST_F(Overwrite, AtlasRefusesExistingOutputsWithoutForce) {
  ExpectRefusedThenForced("atlas " + Quote(kGoldCapture) + " --quiet --out " + Quote(dir_ / "lib"),
                          dir_ / "lib.ktx2");
}

TEST_F(Overwrite, ExportCsvRefusesAnExistingFileWithoutForce) {
  ExpectRefusedThenForced("export-csv " + Quote(kGoldCapture) + " --out " + Quote(dir_ / "g.csv"),
                          dir_ / "g.csv");
}

TEST_F(Overwrite, PreviewRefusesAnExistingImageWithoutForce) {
  ExpectRefusedThenForced(
      "preview " + Quote(std::string(BRDF_SOURCE_DIR) + "/data-samples/materials/gold.json") +
          " --size 16 --spp 1 --quiet --out " + Quote(dir_ / "p.png"),
      dir_ / "p.png");
}

TEST_F(Overwrite, ImportRefusesAnExistingFileWithoutForce) {
  const fs::path csv = dir_ / "in.csv";
  WriteText(csv, "theta_in,phi_in,theta_out,phi_out,r,g,b\n20,0,30,180,0.1,0.2,0.3\n");
  ExpectRefusedThenForced("import " + Quote(csv) + " --out " + Quote(dir_ / "in.bpc"),
                          dir_ / "in.bpc");
}

// A coarse geometry (one θin, 15° × 30° steps) so the simulated capture takes milliseconds.
const std::string kSmallCapture =
    "capture --device sim --material gold --sample s --theta-in 0 --theta-out-step 15 "
    "--phi-out-step 30 --quiet";

TEST_F(Overwrite, CaptureRefusesAnExistingFileWithoutForce) {
  ExpectRefusedThenForced(kSmallCapture + " --out " + Quote(dir_ / "c.bpc"), dir_ / "c.bpc");
  // The same line, word for word, as another writing command's (only the path differs).
  const ToolRun capture = Run(kSmallCapture + " --out " + Quote(dir_ / "c.bpc"));
  ASSERT_EQ(Run("export-csv " + Quote(kGoldCapture) + " --out " + Quote(dir_ / "c.csv")).exit_code,
            0);
  const ToolRun csv = Run("export-csv " + Quote(kGoldCapture) + " --out " + Quote(dir_ / "c.csv"));
  ASSERT_EQ(capture.ErrLines().size(), 1u) << capture.err;
  ASSERT_EQ(csv.ErrLines().size(), 1u) << csv.err;
  std::string expected = csv.ErrLines()[0];
  expected.replace(expected.find("c.csv"), 5, "c.bpc");
  EXPECT_EQ(capture.ErrLines()[0], expected);
}

TEST_F(Overwrite, AnOutputThatIsAFolderIsRefusedEvenWithForce) {
  fs::create_directories(dir_ / "luts" / "gold.ktx2");
  fs::create_directories(dir_ / "lib.json");
  fs::create_directories(dir_ / "c.bpc");
  for (const std::string& args :
       {"convert " + Quote(kGoldCapture) + " --quiet --force --out " + Quote(dir_ / "luts"),
        "atlas " + Quote(kGoldCapture) + " --quiet --force --out " + Quote(dir_ / "lib"),
        kSmallCapture + " --force --out " + Quote(dir_ / "c.bpc"),
        kSmallCapture + " --resume --out " + Quote(dir_ / "c.bpc")}) {
    const ToolRun r = Run(args);
    EXPECT_EQ(r.exit_code, 1) << args;
    const std::vector<std::string> lines = r.ErrLines();
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_NE(lines[0].find("is a folder, not a file"), std::string::npos) << lines[0];
  }
  EXPECT_TRUE(fs::is_directory(dir_ / "luts" / "gold.ktx2"));
  EXPECT_FALSE(fs::exists(dir_ / "luts" / "gold.dds")) << "nothing may be written";
}

// A run killed before renaming its outputs leaves ".brdf-<pid>-<n>.tmp" files; the next run into
// that folder removes them and says so in one note.
TEST_F(Overwrite, ConvertRemovesAndReportsTemporariesOfAKilledRun) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // `child` now names no running process
  fs::create_directories(dir_ / "luts");
  const fs::path stale = dir_ / "luts" / (".brdf-" + std::to_string(child) + "-0.tmp");
  WriteText(stale, "half a texture");
  const ToolRun r = Run("convert " + Quote(kGoldCapture) + " --quiet --formats ktx2 --out " +
                        Quote(dir_ / "luts"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(stale));
  const std::vector<std::string> lines = r.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_NE(lines[0].find("removed 1 temporary file left by an interrupted run: " + stale.string()),
            std::string::npos)
      << lines[0];
}

}  // namespace
}  // namespace brdf::tooltest
