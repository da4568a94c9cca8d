// Outputs checked before any work, and option values refused in one line in the user's terms:
// a preview into a missing folder fails at once naming the folder (not after rendering, naming
// its temporary file), a conversion whose derived names exceed NAME_MAX fails before writing
// anything, and every numeric option states its range in plain numbers ("1 to 8192", never
// CLI11's 309-digit limits or "%f" figures); NaN and infinities are refused.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <regex>
#include <string>
#include <vector>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

class OutputsAndOptions : public ToolTest {
 protected:
  void SetUp() override {
    ToolTest::SetUp();
    WriteText(dir_ / "white.json", R"({"model": "lambert", "rho": 1.0})");
  }
};

TEST_F(OutputsAndOptions, APreviewIntoAMissingFolderFailsAtOnceNamingTheFolder) {
  const auto t0 = std::chrono::steady_clock::now();
  const ToolRun r = Run("preview " + Quote(dir_ / "white.json") + " --size 512 --out " +
                        Quote(dir_ / "missing" / "p.exr"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_EQ(r.err, "brdf: error: " + (dir_ / "missing" / "p.exr").string() +
                       ": cannot write into the folder " + (dir_ / "missing").string() +
                       ": No such file or directory\n");
  EXPECT_LT(seconds, 2.0) << "checked before rendering";
  // A path through a regular file is not a folder either.
  WriteText(dir_ / "file", "x");
  const ToolRun f = Run("preview " + Quote(dir_ / "white.json") + " --size 16 --out " +
                        Quote(dir_ / "file" / "p.exr"));
  EXPECT_EQ(f.exit_code, 1);
  ASSERT_EQ(f.ErrLines().size(), 1u) << f.err;
  EXPECT_EQ(f.err, "brdf: error: " + (dir_ / "file" / "p.exr").string() + ": " +
                       (dir_ / "file").string() + " is not a folder\n");
}

// The longest name `convert --engine all` derives is Godot's NAME_slices.exr.import, 18 bytes
// more than the material's name: 237 bytes work, 238 are refused before any file is written
// (before: the run worked for seconds, failed at the last rename and left shared engine files).
TEST_F(OutputsAndOptions, ConvertRefusesDerivedNamesBeyondNameMaxBeforeWritingAnything) {
  for (const std::size_t length : {237u, 238u}) {
    const std::string name(length, 'k');
    WriteText(dir_ / (name + ".json"), R"({"model": "lambert", "rho": 0.5})");
    const fs::path out = dir_ / ("out" + std::to_string(length));
    const ToolRun r = Run("convert " + Quote(dir_ / (name + ".json")) +
                          " --engine all --quiet --out " + Quote(out));
    fs::remove(dir_ / (name + ".json"));
    std::size_t files = 0, longest = 0;
    for (const auto& e : fs::recursive_directory_iterator(out))
      if (e.is_regular_file()) {
        ++files;
        longest = std::max(longest, e.path().filename().string().size());
      }
    if (length == 237) {
      EXPECT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(longest, 255u);
      continue;
    }
    EXPECT_EQ(r.exit_code, 1);
    ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
    EXPECT_NE(r.err.find("/godot/" + name +
                         "_slices.exr.import: the file name is 256 bytes long; "
                         "a file name may have at most 255 bytes (NAME_MAX)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(files, 0u) << "nothing written";
  }
}

struct OptionCase {
  std::string args, message;
};

TEST_F(OutputsAndOptions, NumericOptionsStateTheirRangeInPlainNumbers) {
  const std::string white = Quote(dir_ / "white.json");
  const std::string preview = "preview " + white + " --out " + Quote(dir_ / "x.exr") + " ";
  const std::vector<OptionCase> cases = {
      {preview + "--jobs 0", "brdf: preview: --jobs: expected a whole number >= 1, got '0'"},
      {preview + "--size 0",
       "brdf: preview: --size: expected a whole number from 1 to 8192, got '0'"},
      {preview + "--size 8193",
       "brdf: preview: --size: expected a whole number from 1 to 8192, got '8193'"},
      {preview + "--spp 0",
       "brdf: preview: --spp: expected a whole number from 1 to 1048576, got '0'"},
      {preview + "--subdivisions 17",
       "brdf: preview: --subdivisions: expected a whole number from 1 to 16, got '17'"},
      {preview + "--sample-pixels 0",
       "brdf: preview: --sample-pixels: expected a whole number from 1 to 67108864, got '0'"},
      {preview + "--rms 2", "brdf: preview: --rms: expected a number in [1e-06, 1], got '2'"},
      {preview + "--fov -5",
       "brdf: preview: --fov: expected a number in (0, 170) degrees, got '-5'"},
      {preview + "--fov 0", "brdf: preview: --fov: expected a number in (0, 170) degrees, got '0'"},
      {preview + "--fov nan",
       "brdf: preview: --fov: expected a number in (0, 170) degrees, got 'nan'"},
      {preview + "--fov 179.9",
       "brdf: preview: --fov: expected a number in (0, 170) degrees, got '179.9'"},
      {preview + "--exposure nan",
       "brdf: preview: --exposure: expected a finite number of stops, got 'nan'"},
      {preview + "--env-rotate inf",
       "brdf: preview: --env-rotate: expected a finite number of degrees, got 'inf'"},
      {"eval " + white + " --in 0,0 --out 0,0 --beyond-subdivide 0",
       "brdf: eval: --beyond-subdivide: expected a whole number from 1 to 20, got '0'"},
      {"convert " + white + " --out " + Quote(dir_ / "c") + " --beyond-subdivide 21",
       "brdf: convert: --beyond-subdivide: expected a whole number from 1 to 20, got '21'"},
      {"convert " + white + " --out " + Quote(dir_ / "c") + " --engine ''",
       "brdf: convert: --engine: expected unity, unreal, godot, web or all (comma separated), "
       "got ''"},
      {"atlas " + white + " --out " + Quote(dir_ / "a") + " --engine ''",
       "brdf: atlas: --engine: expected unity, unreal, godot, web or all (comma separated), "
       "got ''"},
      {"capture --device sim --material gold --sample s --out " + Quote(dir_ / "c.bpc") +
           " --noise nan",
       "brdf: capture: --noise: expected a finite number, got 'nan'"},
      {"capture --device sim --material gold --sample s --out " + Quote(dir_ / "c.bpc") +
           " --theta-out-step inf",
       "brdf: capture: --theta-out-step: expected a finite number of degrees, got 'inf'"},
  };
  const std::regex long_number("[0-9]{30,}");
  for (const OptionCase& c : cases) {
    const ToolRun r = Run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
    EXPECT_EQ(r.ErrLines().size(), 1u) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind(c.message, 0), 0u) << c.args << "\n" << r.err;
    EXPECT_FALSE(std::regex_search(r.err, long_number)) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "c"));
  EXPECT_FALSE(fs::exists(dir_ / "c.bpc"));
}

// A fixed exposure outside the instrument's range is refused when the instrument has said its
// range (before the references are measured), in plain numbers: the simulated MD2 takes 1 to
// 2000 ms (before: the firmware's refusal with "5000.000000" figures and a second line).
TEST_F(OutputsAndOptions, AFixedExposureOutsideTheInstrumentsRangeIsRefusedInOneLine) {
  const ToolRun r =
      Run("capture --device sim --material gold --sample s --quiet --exposure 5000 "
          "--out " +
          Quote(dir_ / "e.bpc"));
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_EQ(r.err,
            "brdf: error: exposure: expected a fixed time from 1 to 2000 ms (the range of "
            "BRDF-SIM MD2), got 5000 ms\n");
  EXPECT_FALSE(fs::exists(dir_ / "e.bpc"));
}

// The extrapolation member names the parameter, what it must be and its value once (before:
// "expected p >= 0 and l in [0, 1], got extrapolation parameter p must be ...").
TEST_F(OutputsAndOptions, ABadExtrapolationMemberNamesTheParameterOnce) {
  WriteText(dir_ / "bad.json",
            R"({"model": "lambert", "rho": 0.5, "extrapolate": {"p": -1, "l": 0.5}})");
  WriteText(dir_ / "badl.json",
            R"({"model": "lambert", "rho": 0.5, "extrapolate": {"p": 1, "l": 2}})");
  ToolRun r = Run("convert " + Quote(dir_ / "bad.json") + " --quiet --out " + Quote(dir_ / "o"));
  EXPECT_NE(r.err.find((dir_ / "bad.json").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("member 'extrapolate.p': expected a finite number >= 0 (docs/design.md "
                       "§6), got -1"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("got extrapolation parameter"), std::string::npos) << r.err;
  r = Run("convert " + Quote(dir_ / "badl.json") + " --quiet --out " + Quote(dir_ / "o"));
  EXPECT_NE(r.err.find(": member 'extrapolate.l': expected a number in [0, 1] (docs/design.md "
                       "§6), got 2"),
            std::string::npos)
      << r.err;
}

// An RGL file whose field says rank 0 (its dimensions then read as the next field's header)
// is reported at the byte where the next name turns into control characters, whole, on one line
// (before: "expected field '" and the line cut at the NUL).
TEST_F(OutputsAndOptions, AnRglFieldOfRankZeroIsReportedOnOneWholeLine) {
  const std::string rgl = test::DataPath("rgl/aurora_white_rgb.bsdf");
  std::string data = ReadAll(rgl);
  ASSERT_GT(data.size(), 100u);
  // tensor_file: 12-byte magic, 2-byte version, u32 field count, then per field: u16 name
  // length, name, u16 rank, u8 dtype, u64 offset, u64 per dimension.
  auto u16 = [&](std::size_t at) {
    return static_cast<std::size_t>(static_cast<unsigned char>(data[at]) |
                                    static_cast<unsigned char>(data[at + 1]) << 8);
  };
  std::size_t pos = 18, rank_at = 0;
  const std::size_t name_len = u16(pos);
  ASSERT_GT(name_len, 0u);
  rank_at = pos + 2 + name_len;
  ASSERT_GT(u16(rank_at), 0u);
  data[rank_at] = data[rank_at + 1] = 0;
  WriteText(dir_ / "rank0.bsdf", data);
  const ToolRun r = Run("info " + Quote(dir_ / "rank0.bsdf"));
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_NE(r.err.find((dir_ / "rank0.bsdf").string() + ": byte "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expected a field name of printable characters (field 1 of "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("got the control character 0x"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\0'), std::string::npos);
}

// A fit result under --engine-fits that does not parse is named with its line and column; it
// fails that input (the manifest would otherwise silently lack the fallback asked for), and no
// file of the input is left behind.
TEST_F(OutputsAndOptions, ABrokenEngineFitIsNamedWithLineAndColumn) {
  fs::create_directories(dir_ / "fits");
  WriteText(dir_ / "fits" / "white.ggx.json",
            "{\"model\": \"ggx\",\n  \"kd\": [0.1, 0.1, 0.1],, }");
  const ToolRun r = Run("convert " + Quote(dir_ / "white.json") + " --engine unity --engine-fits " +
                        Quote(dir_ / "fits") + " --quiet --out " + Quote(dir_ / "o"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((dir_ / "fits" / "white.ggx.json").string() +
                       ": line 2, column 25: expected valid JSON, got ', }'"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o" / "white.ktx2"));
}

// A KTX2 level offset near 2^64 is said as stored (length and offset), not as a range whose end
// wrapped past 2^64 ("bytes 18446744073709551600..1045440").
TEST_F(OutputsAndOptions, AKtx2LevelOffsetNear2To64IsPrintedAsStored) {
  ToolRun r = Run("convert " + Quote(dir_ / "white.json") + " --formats ktx2 --quiet --out " +
                  Quote(dir_ / "k"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string data = ReadAll(dir_ / "k" / "white.ktx2");
  // KTX2: 48-byte header, 32-byte index, then level 0's byteOffset (u64) at byte 80.
  ASSERT_GT(data.size(), 104u);
  std::uint64_t length = 0;
  for (int b = 7; b >= 0; --b) length = length << 8 | static_cast<unsigned char>(data[88 + b]);
  const std::uint64_t offset = ~std::uint64_t{0} - 15;  // 2^64 − 16, aligned
  for (int b = 0; b < 8; ++b) data[80 + b] = static_cast<char>(offset >> (8 * b));
  WriteText(dir_ / "bad.ktx2", data);
  r = Run("info " + Quote(dir_ / "bad.ktx2"));
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_NE(r.err.find(": byte 80: expected the level 0 image inside the file (" +
                       std::to_string(data.size()) + " bytes), got " + std::to_string(length) +
                       " bytes from offset 18446744073709551600"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace brdf::tooltest
