// The one overwrite rule of every writing command (convert, atlas, capture, import, export-csv,
// preview, repair, fit; brdf::CheckWritableOutputs, README "Writing files"): an existing output
// is refused before any work with one line naming it and --force, nothing is changed, and
// --force replaces it; an output path that is a folder is refused even with --force. The
// expected bytes come from the first run's files, compared before and after.
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

// A capture whose end chunk is cut: every slice intact, so `brdf repair` rewrites it.
fs::path WriteUnfinishedCapture(const fs::path& dir) {
  const fs::path cut = dir / "cut.bpc";
  std::string b = ReadAll(kGoldCapture);
  const std::vector<ChunkSpan> chunks = BpcChunks(kGoldCapture);
  b.resize(chunks.back().offset + 3);
  WriteText(cut, b);
  return cut;
}

TEST_F(Overwrite, RepairRefusesAnExistingFileWithoutForce) {
  const fs::path cut = WriteUnfinishedCapture(dir_);
  ExpectRefusedThenForced("repair " + Quote(cut) + " --out " + Quote(dir_ / "fixed.bpc"),
                          dir_ / "fixed.bpc");
}

TEST_F(Overwrite, FitRefusesAnExistingResultWithoutForce) {
  ExpectRefusedThenForced("fit gold --model lambert --quiet --out " + Quote(dir_ / "gold.fit.json"),
                          dir_ / "gold.fit.json");
}

// Several results into a folder: one of them existing stops the whole run before any fit, so
// the result that did not exist is not written either.
TEST_F(Overwrite, FitChecksEveryResultBeforeAnyFit) {
  const std::string args = "fit gold paper_white --model lambert --quiet --out " + Quote(dir_);
  const ToolRun first = Run(args);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const fs::path gold = dir_ / "gold.lambert.json", paper = dir_ / "paper_white.lambert.json";
  ASSERT_TRUE(fs::exists(gold) && fs::exists(paper));
  fs::remove(paper);
  const std::string before = ReadAll(gold);
  const ToolRun second = Run(args);
  EXPECT_EQ(second.exit_code, 1) << second.err;
  const std::vector<std::string> lines = second.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << second.err;
  EXPECT_EQ(lines[0],
            "brdf: error: " + gold.string() + ": already exists; use --force to overwrite it");
  EXPECT_FALSE(fs::exists(paper)) << "a fit ran before the check";
  EXPECT_EQ(ReadAll(gold), before);
  const ToolRun forced = Run(args + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_TRUE(fs::exists(paper));
}

TEST_F(Overwrite, AnOutputThatIsAFolderIsRefusedEvenWithForce) {
  fs::create_directories(dir_ / "luts" / "gold.ktx2");
  fs::create_directories(dir_ / "lib.json");
  fs::create_directories(dir_ / "c.bpc");
  fs::create_directories(dir_ / "f.json");
  fs::create_directories(dir_ / "folder_out" / "gold.lambert.json");
  fs::create_directories(dir_ / "g.csv");
  fs::create_directories(dir_ / "p.png");
  const fs::path cut = WriteUnfinishedCapture(dir_);
  const fs::path csv = dir_ / "in.csv";
  WriteText(csv, "theta_in,phi_in,theta_out,phi_out,r,g,b\n20,0,30,180,0.1,0.2,0.3\n");
  for (const std::string& args :
       {"convert " + Quote(kGoldCapture) + " --quiet --force --out " + Quote(dir_ / "luts"),
        "atlas " + Quote(kGoldCapture) + " --quiet --force --out " + Quote(dir_ / "lib"),
        kSmallCapture + " --force --out " + Quote(dir_ / "c.bpc"),
        kSmallCapture + " --resume --out " + Quote(dir_ / "c.bpc"),
        "repair " + Quote(cut) + " --force --out " + Quote(dir_ / "c.bpc"),
        "import " + Quote(csv) + " --force --out " + Quote(dir_ / "c.bpc"),
        "export-csv " + Quote(kGoldCapture) + " --force --out " + Quote(dir_ / "g.csv"),
        "preview gold --size 16 --spp 1 --quiet --force --out " + Quote(dir_ / "p.png"),
        "fit gold --model lambert --quiet --force --out " + Quote(dir_ / "f.json"),
        "fit gold paper_white --model lambert --quiet --force --out " +
            Quote(dir_ / "folder_out")}) {
    const ToolRun r = Run(args);
    EXPECT_EQ(r.exit_code, 1) << args;
    const std::vector<std::string> lines = r.ErrLines();
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_NE(lines[0].find("is a folder, not a file"), std::string::npos) << args << lines[0];
  }
  for (const char* folder : {"c.bpc", "f.json", "g.csv", "p.png"})
    EXPECT_TRUE(fs::is_directory(dir_ / folder)) << folder;
  EXPECT_FALSE(fs::exists(dir_ / "folder_out" / "paper_white.lambert.json"))
      << "a fit ran before the check";
  EXPECT_TRUE(fs::is_directory(dir_ / "luts" / "gold.ktx2"));
  EXPECT_FALSE(fs::exists(dir_ / "luts" / "gold.dds")) << "nothing may be written";
}

// `--engine` outputs follow the same rule: a run whose regular outputs are all new but
// whose engine files exist is refused before it writes anything, with one line naming the engine
// file and --force; --force rewrites it. The expected state is the first run's files.
TEST_F(Overwrite, ConvertRefusesExistingEngineOutputsWithoutForce) {
  const fs::path out = dir_ / "luts";
  const ToolRun first = Run("convert " + Quote(kGoldCapture) +
                            " --quiet --formats ktx2 --engine unreal --out " + Quote(out));
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const fs::path dds = out / "unreal" / "gold.dds";
  const std::string before = ReadAll(dds);
  fs::last_write_time(dds, fs::file_time_type::clock::now() - std::chrono::hours(1));
  const auto stamp = fs::last_write_time(dds);

  // gold.json does not exist yet: only the engine files stand in the way.
  const std::string second_args = "convert " + Quote(kGoldCapture) +
                                  " --quiet --formats json --engine unreal --out " + Quote(out);
  const ToolRun second = Run(second_args);
  EXPECT_EQ(second.exit_code, 1) << second.err;
  const std::vector<std::string> lines = second.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << second.err;
  EXPECT_NE(lines[0].find((fs::path("unreal") / "gold.dds").string() + ": already exists"),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[0].find("--force"), std::string::npos) << lines[0];
  EXPECT_FALSE(fs::exists(out / "gold.json")) << "the refused run wrote a regular output";
  EXPECT_EQ(ReadAll(dds), before);
  EXPECT_EQ(fs::last_write_time(dds), stamp) << "the refused run touched " << dds;

  const ToolRun forced = Run(second_args + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(fs::last_write_time(dds), stamp) << "--force did not rewrite " << dds;
  EXPECT_TRUE(fs::exists(out / "gold.json"));
}

// The files every material of a folder shares (viewer, shaders, importer) are the tool's own
// when it wrote them: a second material converted into the same folder later needs no --force.
// A file of that name the tool did not write is the user's and is refused like any output.
TEST_F(Overwrite, EngineSharedFilesAreReplacedOnlyWhenTheToolWroteThem) {
  const fs::path out = dir_ / "luts";
  const std::string wood =
      Quote(std::string(BRDF_SOURCE_DIR) + "/data-samples/materials/wood_oak.json");
  const ToolRun gold =
      Run("convert " + Quote(kGoldCapture) + " --quiet --engine all --out " + Quote(out));
  ASSERT_EQ(gold.exit_code, 0) << gold.err;
  const ToolRun oak = Run("convert " + wood + " --quiet --engine all --out " + Quote(out));
  EXPECT_EQ(oak.exit_code, 0) << "a managed shared file was refused: " << oak.err;
  EXPECT_TRUE(fs::exists(out / "web" / "wood_oak.manifest.json"));

  const fs::path mine = dir_ / "mine";
  fs::create_directories(mine / "web");
  WriteText(mine / "web" / "index.html", "<p>my own page</p>\n");
  const std::string args =
      "convert " + Quote(kGoldCapture) + " --quiet --engine web --out " + Quote(mine);
  const ToolRun refused = Run(args);
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  const std::vector<std::string> lines = refused.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << refused.err;
  EXPECT_NE(lines[0].find((fs::path("web") / "index.html").string() + ": already exists"),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[0].find("--force"), std::string::npos) << lines[0];
  EXPECT_EQ(ReadAll(mine / "web" / "index.html"), "<p>my own page</p>\n");
  EXPECT_FALSE(fs::exists(mine / "gold.ktx2")) << "the refused run wrote a regular output";
  EXPECT_FALSE(fs::exists(mine / "web" / "gold.ktx2")) << "the refused run wrote an engine file";

  const ToolRun forced = Run(args + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(ReadAll(mine / "web" / "index.html").find("<!DOCTYPE html>"), std::string::npos);
}

TEST_F(Overwrite, AtlasRefusesExistingEngineOutputsWithoutForce) {
  const std::string args =
      "atlas " + Quote(kGoldCapture) + " --quiet --engine godot --out " + Quote(dir_ / "lib");
  const ToolRun first = Run(args);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  for (const char* ext : {".ktx2", ".dds", ".exr", ".json"})
    fs::remove(dir_ / (std::string("lib") + ext));  // only the engine files remain
  const fs::path dds = dir_ / "godot" / "lib.dds";
  fs::last_write_time(dds, fs::file_time_type::clock::now() - std::chrono::hours(1));
  const auto stamp = fs::last_write_time(dds);
  const ToolRun second = Run(args);
  EXPECT_EQ(second.exit_code, 1) << second.err;
  const std::vector<std::string> lines = second.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << second.err;
  EXPECT_NE(lines[0].find((fs::path("godot") / "lib.dds").string() + ": already exists"),
            std::string::npos)
      << lines[0];
  EXPECT_FALSE(fs::exists(dir_ / "lib.ktx2")) << "the refused atlas wrote its texture";
  EXPECT_EQ(fs::last_write_time(dds), stamp);
  const ToolRun forced = Run(args + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(fs::last_write_time(dds), stamp);
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
