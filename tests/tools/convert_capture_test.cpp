// `brdf convert` and `brdf eval` on captures (.bpc): intact, corrupt, truncated and unfinished
// files this test writes from the analytic formulas in tool_test_util.h. Damage offsets are
// found here by walking the chunk layout of docs/formats/bpc.md.
#include <algorithm>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

const std::vector<double> kThetaIn = {0, 20, 40, 60};

class CaptureInputs : public ToolTest {
 protected:
  fs::path WriteCapture(const std::string& name, const Analytic& m,
                        const std::vector<double>& theta_in = kThetaIn) {
    fs::create_directories(dir_ / "in");
    const fs::path p = dir_ / "in" / (name + ".bpc");
    WriteBpc(p.string(), CaptureOf(m, theta_in));
    return p;
  }
  static void CutFile(const fs::path& p, std::uint64_t size) { fs::resize_file(p, size); }
  static ChunkSpan Chunk(const fs::path& p, const std::string& tag, int nth = 0) {
    for (const ChunkSpan& c : BpcChunks(p))
      if (c.tag == tag && nth-- == 0) return c;
    ADD_FAILURE() << "no chunk " << tag << " in " << p;
    return {};
  }
};

TEST_F(CaptureInputs, EvalOfCaptureMatchesAnalytic) {
  const Analytic m = Ggx03();
  const fs::path bpc = WriteCapture("ggx", m);
  // `brdf eval` of a capture samples the float LUT `brdf convert` builds from it (one
  // evaluation path). Where the query is a texel centre of that LUT and the texel's direction a
  // capture node (the plane of incidence at whole degrees of θd) it is the capture's own
  // (float) value; elsewhere the LUT's bilinear interpolation over 1° texels, within 1e-3 of the
  // formula for this GGX α = 0.3 (second differences of f over one texel stay below 1 % of f
  // here, and the bilinear error is at most 1/8 of them); between slices (θin 30°, mirror
  // direction: θd = 0 in both neighbouring slices) the mean of the two slices' mirror values;
  // beyond θb = 75° the value at 75° (defaults: clamping).
  WriteText(dir_ / "pairs.txt",
            "20 0 30 180\n"
            "40 0 12 33\n"
            "0 0 0 0\n"
            "60 0 60 180\n"
            "40 0 33.5 171.25\n"
            "30 0 30 180\n"
            "20 0 85 10\n"
            "20 90 30 270\n");
  // --beyond clamp: the measured slices, the θin interpolation between them and the §6 band
  // (the default fill inserts a 30° slice and replaces the band; tests/python/beyond_oracle.py).
  const ToolRun r =
      RunTool("eval " + Quote(bpc) + " --beyond clamp --pairs " + Quote(dir_ / "pairs.txt"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::vector<std::array<double, 3>> got;
  while (std::getline(lines, line)) got.push_back(ParseTriple(line));
  ASSERT_EQ(got.size(), 8u);
  const auto near = [](const std::array<double, 3>& a, const std::array<double, 3>& b,
                       double rel = 2e-7) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], rel * std::fabs(b[c]) + 1e-12) << c;
  };
  near(got[0], m.FAngles(20, 30, 180));
  near(got[1], m.FAngles(40, 12, 33), 1e-3);
  near(got[2], m.FAngles(0, 0, 0));
  near(got[3], m.FAngles(60, 60, 180));
  for (int c = 0; c < 3; ++c) {
    double lo = 1e300, hi = -1e300;
    for (double t : {33.0, 34.0})
      for (double p : {171.0, 172.0}) {
        lo = std::min(lo, m.FAngles(40, t, p)[c]);
        hi = std::max(hi, m.FAngles(40, t, p)[c]);
      }
    EXPECT_GE(got[4][c], lo * (1 - 1e-3));
    EXPECT_LE(got[4][c], hi * (1 + 1e-3));
    const double mid = 0.5 * (m.FAngles(20, 20, 180)[c] + m.FAngles(40, 40, 180)[c]);
    EXPECT_NEAR(got[5][c], mid, 1e-6 * mid);
  }
  near(got[6], m.FAngles(20, 75, 10), 1e-3);
  near(got[7], got[0]);  // isotropic: only φout − φin matters

  // With --extrapolate 0.2,0.3: f(75°)·((1 − α) + α·0.2), α = b((85 − 75)/15, 0.3).
  const ToolRun x = RunTool(
      "eval " + Quote(bpc) + " --in 20,0 --out 85,10 --extrapolate 0.2,0.3 --beyond clamp", dir_);
  ASSERT_EQ(x.exit_code, 0) << x.err;
  const double alpha = BezierByBisection(10.0 / 15.0, 0.3);
  const auto f75 = m.FAngles(20, 75, 10);
  const auto gx = ParseTriple(x.out);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(gx[c], f75[c] * ((1 - alpha) + alpha * 0.2), 1e-3 * f75[c]);
}

TEST_F(CaptureInputs, BatchWithCorruptAndTruncatedCapturesConvertsTheRest) {
  WriteCapture("good_lambert", Lambertian());
  WriteCapture("good_lafortune", Lafortune20());
  WriteText(dir_ / "in" / "good_ggx.json", Ggx03().Json());
  // A flipped byte in the middle of slice 1's samples.
  const fs::path corrupt = WriteCapture("corrupt", Ggx03());
  const ChunkSpan slice1 = Chunk(corrupt, "SLCE", 1);
  {
    std::string b = ReadAll(corrupt);
    b[slice1.offset + slice1.size / 2] ^= 0x01;
    WriteText(corrupt, b);
  }
  // Cut in the middle of slice 2 (an interrupted capture).
  const fs::path truncated = WriteCapture("truncated", Lafortune20());
  const ChunkSpan slice2 = Chunk(truncated, "SLCE", 2);
  CutFile(truncated, slice2.offset + slice2.size / 2);

  const ToolRun r = RunTool(
      "convert " + Quote(dir_ / "in") + " --out " + Quote(dir_ / "out") + " --jobs 2", dir_);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("converted 3 of 5"), std::string::npos) << r.out;
  // Both named, with the damage offset (the damaged chunk's start) and slice.
  const auto reason = [&](const std::string& name) {
    const auto at = r.out.find(name + ".bpc (");
    EXPECT_NE(at, std::string::npos) << name << " not reported: " << r.out;
    return at == std::string::npos ? std::string() : r.out.substr(at);
  };
  const std::string corrupt_reason = reason("corrupt");
  EXPECT_NE(corrupt_reason.find("byte " + std::to_string(slice1.offset) + " (slice 1)"),
            std::string::npos)
      << corrupt_reason;
  const std::string truncated_reason = reason("truncated");
  EXPECT_NE(truncated_reason.find("byte " + std::to_string(slice2.offset) + " (slice 2)"),
            std::string::npos)
      << truncated_reason;
  EXPECT_NE(truncated_reason.find("--resume"), std::string::npos) << truncated_reason;
  EXPECT_NE(r.err.find("corrupt.bpc: FAILED"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truncated.bpc: FAILED"), std::string::npos) << r.err;

  for (const char* good : {"good_lambert", "good_lafortune", "good_ggx"})
    for (const char* ext : {".ktx2", ".dds", ".exr", ".png", ".json"})
      EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / (std::string(good) + ext))) << good << ext;
  EXPECT_TRUE(FilesStartingWith(dir_ / "out", "corrupt").empty());
  EXPECT_TRUE(FilesStartingWith(dir_ / "out", "truncated").empty());
  EXPECT_TRUE(FilesStartingWith(dir_ / "out", ".").empty()) << "temporary files left behind";
}

TEST_F(CaptureInputs, UnfinishedCaptureWithEverySliceIsConvertedWithAWarning) {
  // No end chunk at all (never finalised), and an end chunk cut in half.
  const fs::path a = WriteCapture("no_end", Lambertian());
  CutFile(a, Chunk(a, "END ").offset);
  const fs::path b = WriteCapture("cut_end", Lambertian());
  const ChunkSpan end = Chunk(b, "END ");
  CutFile(b, end.offset + end.size / 2);
  const ToolRun r = RunTool(
      "convert " + Quote(dir_ / "in") + " --out " + Quote(dir_ / "out") + " --formats ktx2 --quiet",
      dir_);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("converted 2 of 2"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("no_end.bpc: warning: no intact end chunk"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cut_end.bpc: warning: no intact end chunk"), std::string::npos) << r.err;
  // The default fill: θin 0, 10, …, 80° (Δin/2 up to 80°, docs/design.md §5), 9 slices.
  EXPECT_EQ(ReadKtx2Layout(dir_ / "out" / "no_end.ktx2").depth, 9u);
}

TEST_F(CaptureInputs, UnfinishedCaptureMissingSlicesIsRefused) {
  // Cut cleanly after slice 2: every chunk present is intact, but θin 60° was never captured.
  const fs::path p = WriteCapture("three_of_four", Lambertian());
  const ChunkSpan slice3 = Chunk(p, "SLCE", 3);
  CutFile(p, slice3.offset);
  const ToolRun r =
      RunTool("convert " + Quote(p) + " --out " + Quote(dir_ / "out") + " --quiet", dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("converted 0 of 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("missing 60"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("byte " + std::to_string(slice3.offset)), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--resume"), std::string::npos) << r.out;
  EXPECT_TRUE(!fs::exists(dir_ / "out") || fs::is_empty(dir_ / "out"));
}

TEST_F(CaptureInputs, CaptureWithOtherThetaInStepsConverts) {
  // θin 0/30/60 on a 5° lattice: K = 3, Δin = 30°. The default fill halves the step and
  // extrapolates up to 80° (docs/design.md §5): θin 0, 15, …, 75°, 6 slices; --beyond clamp
  // keeps the 3 measured ones.
  const fs::path p = dir_ / "tilted.bpc";
  WriteBpc(p.string(), CaptureOf(Lafortune20(), {0, 30, 60}, 75, 5, 5));
  const ToolRun r = RunTool(
      "convert " + Quote(p) + " --out " + Quote(dir_ / "out") + " --formats ktx2 --quiet", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const Texture3d t = ReadKtx2Layout(dir_ / "out" / "tilted.ktx2");
  EXPECT_EQ(t.depth, 6u);
  EXPECT_EQ(t.payload.size(), 361u * 181u * 6u * 4u);
  const ToolRun c = RunTool("convert " + Quote(p) + " --out " + Quote(dir_ / "clamped") +
                                " --formats ktx2 --quiet --beyond clamp",
                            dir_);
  ASSERT_EQ(c.exit_code, 0) << c.out << c.err;
  const Texture3d u = ReadKtx2Layout(dir_ / "clamped" / "tilted.ktx2");
  EXPECT_EQ(u.depth, 3u);
  EXPECT_EQ(u.payload.size(), 361u * 181u * 3u * 4u);
}

}  // namespace
}  // namespace brdf::tooltest
