// Through the built tool and the brdf::sources library: one evaluation path for
// captures and LUTs, one rule beyond the measured θin range, `brdf repair` followed by
// `brdf capture --resume`, and `brdf info` reporting every problem `convert` and `eval` refuse.
// Expected values come from the analytic formulas of tool_test_util.h (written from
// docs/design.md §9, not the library's models), from the simulator run uninterrupted, and from
// byte layouts of docs/formats/bpc.md patched here (CRCs recomputed with zlib).
#include <zlib.h>

#include <algorithm>
#include <limits>

#include "brdf/core/error.h"
#include "brdf/processing/resample.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/open.h"
#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

class SourcesCli : public ToolTest {
 protected:
  fs::path WriteCapture(const std::string& name, const Measurement& m) {
    const fs::path p = dir_ / (name + ".bpc");
    WriteBpc(p.string(), m);
    return p;
  }
  std::array<double, 3> Eval(const fs::path& file, const std::string& in, const std::string& out,
                             std::string* err = nullptr, const std::string& options = {}) {
    const ToolRun r =
        RunTool("eval " + Quote(file) + " --in " + in + " --out " + out + options, dir_);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    if (err) *err = r.err;
    return ParseTriple(r.out);
  }
};

std::uint32_t ZlibCrc(const std::string& b, std::size_t at, std::size_t n) {
  return static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(b.data() + at), static_cast<uInt>(n)));
}
void StoreU32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
// Rewrites the payload and header CRC-32s of the chunk at `at` (docs/formats/bpc.md).
void FixChunkCrcs(std::string& b, std::size_t at) {
  const std::uint64_t n = LoadU64(b, at + 8);
  StoreU32(b, at + 16, ZlibCrc(b, at + 24, n));
  StoreU32(b, at + 20, ZlibCrc(b, at, 20));
}

// Gold at θin = 30°, mirror direction, once gave 2.62 from the capture against 4.80 from the
// LUT. Between measured θin both now interpolate linearly at the same specular-frame
// coordinates: in the mirror direction θd = 0 in both neighbouring slices, so the value is the
// mean of the two slices' mirror values, f(20°→20°) and f(40°→40°), exactly (texel centres on
// capture nodes; 1e-6 covers the float32 storage). --beyond clamp: the measured slices alone
// (the default fill inserts a 30° slice; the capture-against-texture half below uses it).
TEST_F(SourcesCli, CaptureBetweenSlicesInterpolatesInTheSpecularFrameLikeTheLut) {
  const Analytic m = Ggx03();
  const fs::path bpc = WriteCapture("ggx", CaptureOf(m, {0, 20, 40, 60}));
  const auto got = Eval(bpc, "30,0", "30,180", nullptr, " --beyond clamp");
  const auto f20 = m.FAngles(20, 20, 180), f40 = m.FAngles(40, 40, 180);
  for (int c = 0; c < 3; ++c) {
    const double mid = 0.5 * (f20[c] + f40[c]);
    EXPECT_NEAR(got[c], mid, 1e-6 * mid) << c;
  }
  // The exported texture of the same capture: the same path, up to RGB9E5 rounding of the
  // texels (at most half a step of the largest channel each).
  const ToolRun conv = RunTool(
      "convert " + Quote(bpc) + " --out " + Quote(dir_ / "luts") + " --formats ktx2,json --quiet",
      dir_);
  ASSERT_EQ(conv.exit_code, 0) << conv.err;
  const fs::path ktx2 = dir_ / "luts" / "ggx.ktx2";
  for (const auto& [in, out] : std::vector<std::pair<std::string, std::string>>{
           {"30,0", "30,180"}, {"10,0", "33,171"}, {"47,20", "12,250"}, {"55,0", "80,90"}}) {
    const auto a = Eval(bpc, in, out), b = Eval(ktx2, in, out);
    const double step = Rgb9e5Step(2 * std::max({a[0], a[1], a[2]}));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], step) << in << " " << out << " " << c;
  }
}

// Every command that reads a source takes a library material name (README "Library names"):
// `eval gold` is gold.json's GGX formula (its own numbers: kd 0, f0 (0.962585, 0.786916,
// 0.40822), α 0.15); info, convert and import answer about that file; a file named `gold` in the
// current folder wins; an unknown bare name is one line listing the library.
TEST_F(SourcesCli, EveryCommandThatReadsASourceAcceptsALibraryName) {
  const Analytic gold{"ggx", {0, 0, 0}, {0.962585, 0.786916, 0.40822}, 0.15};
  const auto got = Eval("gold", "30,0", "30,180");
  const auto want = gold.FAngles(30, 30, 180);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-7 * want[c]) << c;
  const std::string library_file =
      (fs::path(BRDF_SOURCE_DIR) / "data-samples" / "materials" / "gold.json").string();
  const ToolRun info = Run("info gold");
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find(library_file), std::string::npos) << info.out;
  const ToolRun convert = Run("convert gold --formats ktx2 --quiet --out " + Quote(dir_ / "luts"));
  EXPECT_EQ(convert.exit_code, 0) << convert.err;
  EXPECT_TRUE(fs::exists(dir_ / "luts" / "gold.ktx2"));
  const ToolRun import = Run("import gold --out " + Quote(dir_ / "g.bpc"));
  EXPECT_EQ(import.exit_code, 1);
  EXPECT_NE(import.err.find(library_file + ": file content: expected a third-party measurement"),
            std::string::npos)
      << import.err;
  // ./gold, a Lambertian material, is read instead of the library's gold: ρ/π.
  WriteText(dir_ / "gold", Lambertian().Json());
  const std::string here_out = (dir_ / "here.txt").string();
  ASSERT_EQ(std::system(("cd " + Quote(dir_) + " && " + BRDF_TOOL +
                         " eval gold --in 30,0 --out 30,180 >'" + here_out + "'")
                            .c_str()),
            0);
  const auto here = ParseTriple(ReadAll(here_out));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(here[c], Lambertian().kd[c] / kPi, 1e-8) << c;
  const ToolRun unknown = Run("eval velvet --in 30,0 --out 30,180");
  EXPECT_EQ(unknown.exit_code, 1);
  ASSERT_EQ(unknown.ErrLines().size(), 1u) << unknown.err;
  EXPECT_NE(unknown.err.find("velvet: no such file, and no library material of that name"),
            std::string::npos)
      << unknown.err;
  EXPECT_NE(unknown.err.find("gold, paper_white"), std::string::npos) << unknown.err;
}

// The library form of the same guarantee: OpenBrdf of a capture and the float LUT that
// BuildLut makes of it with the commands' options (what `brdf convert` encodes, the default
// blind-spot fill included: 9 slices 0–80°) agree to the last bit, filled region included.
TEST_F(SourcesCli, OpenBrdfOfACaptureIsTheFloatLutSampledAsAGpuDoes) {
  const fs::path bpc = WriteCapture("laf", CaptureOf(Lafortune20(), {0, 20, 40, 60}, 75, 5, 5));
  const sources::OpenedSource s = sources::OpenBrdf(bpc.string());
  EXPECT_EQ(s.evaluation, sources::Evaluation::kResampledLut);
  const Lut lut =
      processing::BuildLut(LoadBpc(bpc.string()), {}, sources::DefaultResampleOptions());
  EXPECT_EQ(lut.slices(), 9);
  for (double ti : {0.0, 13.0, 20.0, 31.5, 59.0, 67.0, 80.0})
    for (double to : {0.0, 17.0, 44.0, 74.0, 88.0})
      for (double po : {0.0, 91.0, 180.0, 333.0}) {
        const Rgb f = s.brdf->Eval(SphericalDirectionDeg(ti, 0), SphericalDirectionDeg(to, po));
        const std::array<float, 3> g = lut.SampleAngles(ti, to, po);
        for (int c = 0; c < 3; ++c)
          EXPECT_EQ(static_cast<float>(f[c]), g[c]) << ti << " " << to << " " << po;
      }
}

// One rule beyond the last slice for captures and LUTs: the nearest slice's value at the same
// specular-frame angles (the GPU's clamp-to-edge along w), with a warning. In the mirror
// direction of θin = 70° that is the 60° slice's mirror value f(60°→60°). (--beyond clamp:
// the rule for the LUT's last slice; the default fill moves that slice to 80°.)
TEST_F(SourcesCli, BeyondTheLastSliceClampsWithAWarning) {
  const Analytic m = Ggx03();
  const fs::path bpc = WriteCapture("ggx", CaptureOf(m, {0, 20, 40, 60}));
  std::string err;
  const auto got = Eval(bpc, "70,0", "70,180", &err, " --beyond clamp");
  const auto f60 = m.FAngles(60, 60, 180);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], f60[c], 1e-6 * f60[c]) << c;
  EXPECT_NE(err.find("θin 70° is outside the measured range 0°–60°"), std::string::npos) << err;
  ASSERT_EQ(RunTool("convert " + Quote(bpc) + " --out " + Quote(dir_ / "luts") +
                        " --formats ktx2,json --quiet --beyond clamp",
                    dir_)
                .exit_code,
            0);
  const auto lut = Eval(dir_ / "luts" / "ggx.ktx2", "70,0", "70,180", &err);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(lut[c], f60[c], Rgb9e5Step(2 * f60[0])) << c;
  EXPECT_NE(err.find("outside the measured range"), std::string::npos) << err;
  // Inside the range: no warning.
  Eval(bpc, "60,0", "10,10", &err, " --beyond clamp");
  EXPECT_EQ(err.find("outside"), std::string::npos) << err;
}

// Light beyond the last slice, view inside the measured range: reciprocity (docs/design.md §5)
// answers from measured slices, the same for the capture and its exported texture, without a
// warning. The expected value is the material's own for the pair, which the capture holds in
// its 40° slice at θout = 70° (measured, θout ≤ 75°), within the resampling error.
// (--beyond clamp: the exchange rule at the LUT's last slice; the default fill builds its
// slices past 60° by the same reciprocity, tests/python/beyond_oracle.py.)
TEST_F(SourcesCli, BeyondTheLastSliceWithTheViewInsideUsesReciprocity) {
  const Analytic m = Ggx03();
  const fs::path bpc = WriteCapture("ggx", CaptureOf(m, {0, 20, 40, 60}));
  std::string err;
  const std::string clamp = " --beyond clamp";
  const auto got = Eval(bpc, "70,0", "40,180", &err, clamp);
  EXPECT_EQ(err.find("outside"), std::string::npos) << err;
  const auto exchanged = Eval(bpc, "40,180", "70,0", &err, clamp);
  const auto truth = m.FAngles(70, 40, 180);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(got[c], exchanged[c], 1e-7 * exchanged[c]) << c;
    EXPECT_NEAR(got[c], truth[c], 0.02 * truth[c]) << c;
  }
  ASSERT_EQ(RunTool("convert " + Quote(bpc) + " --out " + Quote(dir_ / "luts") +
                        " --formats ktx2,json --quiet --beyond clamp",
                    dir_)
                .exit_code,
            0);
  const auto lut = Eval(dir_ / "luts" / "ggx.ktx2", "70,0", "40,180", &err);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(lut[c], got[c], Rgb9e5Step(2 * got[0])) << c;
  EXPECT_EQ(err.find("outside"), std::string::npos) << err;
}

// `brdf repair` then `brdf capture --resume` gives, slice for slice and value for value, the
// capture an uninterrupted run with the same seed makes.
class Repair : public SourcesCli {
 protected:
  std::string CaptureArgs(const fs::path& out) const {
    return "capture --device sim --material gold --sample 'gold R1' --seed 7 --quiet "
           "--theta-out-step 5 --phi-out-step 10 --out " +
           Quote(out);
  }
  void ExpectSameSlices(const Measurement& a, const Measurement& b) {
    ASSERT_EQ(a.slices.size(), b.slices.size());
    for (const Slice& s : a.slices) {
      const auto it = std::find_if(b.slices.begin(), b.slices.end(), [&](const Slice& t) {
        return t.theta_in_deg == s.theta_in_deg;
      });
      ASSERT_NE(it, b.slices.end()) << "θin " << s.theta_in_deg;
      ASSERT_EQ(s.samples.size(), it->samples.size());
      std::size_t differing = 0;
      for (std::size_t n = 0; n < s.samples.size(); ++n) {
        const Sample &x = s.samples[n], &y = it->samples[n];
        const std::array<float, 10> fx = {
            x.theta_in_deg, x.phi_in_deg, x.theta_out_deg, x.phi_out_deg, x.rgb[0],
            x.rgb[1],       x.rgb[2],     x.sigma[0],      x.sigma[1],    x.sigma[2]};
        const std::array<float, 10> fy = {
            y.theta_in_deg, y.phi_in_deg, y.theta_out_deg, y.phi_out_deg, y.rgb[0],
            y.rgb[1],       y.rgb[2],     y.sigma[0],      y.sigma[1],    y.sigma[2]};
        differing += std::memcmp(fx.data(), fy.data(), sizeof fx) != 0 || x.flags != y.flags;
      }
      EXPECT_EQ(differing, 0u) << "θin " << s.theta_in_deg;
    }
  }
};

TEST_F(Repair, RepairedAndResumedCaptureEqualsTheUninterruptedOne) {
  const fs::path ref = dir_ / "ref.bpc";
  ASSERT_EQ(RunTool(CaptureArgs(ref), dir_).exit_code, 0);
  const Measurement want = LoadBpc(ref.string());
  const std::string bytes = ReadAll(ref);
  const std::vector<ChunkSpan> chunks = BpcChunks(ref);
  ASSERT_EQ(chunks.size(), 6u);  // HEAD, 4 × SLCE, END
  struct Damage {
    std::string name;
    std::size_t cut = 0;   // 0: no cut
    std::size_t flip = 0;  // 0: no flipped byte
    bool expect_dropped = true;
  };
  const std::vector<Damage> damages = {
      {"cut inside slice 2", chunks[3].offset + chunks[3].size / 2, 0},
      {"cut inside slice 0's header", chunks[1].offset + 10, 0},
      {"cut after slice 3", chunks[5].offset, 0, false},
      {"cut inside the end chunk", chunks[5].offset + 30, 0},
      {"flipped byte in slice 1's samples", 0, chunks[2].offset + 24 + 32 + 500},
      {"flipped byte in slice 3's chunk header", 0, chunks[4].offset + 9},
      {"flipped byte in slice 0's samples and a cut in slice 3", chunks[4].offset + 100,
       chunks[1].offset + 24 + 40},
  };
  for (const Damage& d : damages) {
    SCOPED_TRACE(d.name);
    std::string b = bytes;
    if (d.flip) b[d.flip] = static_cast<char>(b[d.flip] ^ 0x10);
    if (d.cut) b.resize(d.cut);
    const fs::path damaged = dir_ / "damaged.bpc", fixed = dir_ / "fixed.bpc";
    fs::remove(fixed);
    WriteText(damaged, b);
    const ToolRun r = RunTool("repair " + Quote(damaged) + " --out " + Quote(fixed), dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::size_t damage_at = d.flip ? std::min(d.flip, d.cut ? d.cut : d.flip) : d.cut;
    if (d.expect_dropped) {
      EXPECT_NE(r.out.find("dropped"), std::string::npos) << r.out;
      // The first dropped part starts at the chunk that holds the damage.
      std::size_t chunk_start = 0;
      for (const ChunkSpan& c : chunks)
        if (c.offset <= damage_at) chunk_start = c.offset;
      EXPECT_NE(r.out.find("at byte " + std::to_string(chunk_start)), std::string::npos) << r.out;
    }
    // The repaired file is an unfinished capture holding only intact slices.
    const BpcReadResult fixed_read = ReadBpc(fixed.string());
    EXPECT_FALSE(fixed_read.finished);
    EXPECT_TRUE(fixed_read.problems.empty());
    const ToolRun resume = RunTool(CaptureArgs(fixed) + " --resume", dir_);
    ASSERT_EQ(resume.exit_code, 0) << resume.err;
    const BpcReadResult done = ReadBpc(fixed.string());
    EXPECT_TRUE(done.finished);
    EXPECT_TRUE(done.problems.empty());
    ExpectSameSlices(want, done.measurement);
    // And convert accepts it.
    EXPECT_EQ(RunTool("info " + Quote(fixed), dir_).exit_code, 0);
  }
}

TEST_F(Repair, RefusesToOverwriteAndRefusesAnIntactCapture) {
  const fs::path ref = dir_ / "ref.bpc";
  ASSERT_EQ(RunTool(CaptureArgs(ref), dir_).exit_code, 0);
  ToolRun r = RunTool("repair " + Quote(ref) + " --out " + Quote(dir_ / "x.bpc"), dir_);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("nothing to repair"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.bpc"));
  std::string b = ReadAll(ref);
  b.resize(b.size() - 5);
  WriteText(dir_ / "cut.bpc", b);
  WriteText(dir_ / "taken.bpc", "x");
  r = RunTool("repair " + Quote(dir_ / "cut.bpc") + " --out " + Quote(dir_ / "taken.bpc"), dir_);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(ReadAll(dir_ / "taken.bpc"), "x");
}

// Every message that used to say "rewrite its intact slices" names the repair command.
TEST_F(Repair, DamageFollowedByIntactSlicesNamesTheRepairCommand) {
  const fs::path ref = dir_ / "ref.bpc";
  ASSERT_EQ(RunTool(CaptureArgs(ref), dir_).exit_code, 0);
  const std::vector<ChunkSpan> chunks = BpcChunks(ref);
  std::string b = ReadAll(ref);
  b[chunks[2].offset + 24 + 100] ^= 0x01;
  WriteText(dir_ / "flip.bpc", b);
  for (const char* name : {"info", "eval", "convert"}) {
    const std::string cmd = name;
    std::string args = cmd + " " + Quote(dir_ / "flip.bpc");
    if (cmd == "eval") args += " --in 0,0 --out 10,10";
    if (cmd == "convert") args += " --out " + Quote(dir_ / "luts") + " --quiet";
    const ToolRun r = RunTool(args, dir_);
    EXPECT_NE(r.exit_code, 0) << cmd;
    EXPECT_NE((r.out + r.err).find("brdf repair " + (dir_ / "flip.bpc").string() + " --out"),
              std::string::npos)
        << cmd << ": " << r.out << r.err;
  }
}

// `brdf info` exits 1 and lists each problem that makes `convert` and `eval` refuse a capture;
// those two refuse it naming the same problem. No message shows code identifiers.
TEST_F(SourcesCli, InfoReportsWhatConvertAndEvalRefuse) {
  const Analytic m = Lambertian();
  struct Case {
    std::string name, needle;
    std::string bytes;
  };
  std::vector<Case> cases;
  {
    Measurement x = CaptureOf(m, {0, 20}, 75, 5, 10);
    x.slices[1].samples[17].rgb[0] = std::numeric_limits<float>::quiet_NaN();
    WriteBpc((dir_ / "tmp.bpc").string(), x);
    cases.push_back(
        {"nan", "red value not a finite number (first: sample 17", ReadAll(dir_ / "tmp.bpc")});
  }
  {
    Measurement x = CaptureOf(m, {0, 20}, 75, 5, 10);
    x.slices[0].samples[3].theta_out_deg = 95.0f;
    WriteBpc((dir_ / "tmp.bpc").string(), x);
    cases.push_back({"theta", "θout outside [−90°, 90°] (first: sample 3, θout 95°",
                     ReadAll(dir_ / "tmp.bpc")});
  }
  {
    Measurement x = CaptureOf(m, {0, 20}, 0, 5, 10);  // θout max 0: only the pole
    WriteBpc((dir_ / "tmp.bpc").string(), x);
    cases.push_back({"degenerate", "measured range θout 0°–0°", ReadAll(dir_ / "tmp.bpc")});
  }
  {
    WriteBpc((dir_ / "tmp.bpc").string(), CaptureOf(m, {0, 20}, 75, 5, 10));
    std::string b = ReadAll(dir_ / "tmp.bpc");
    const std::vector<ChunkSpan> c = BpcChunks(dir_ / "tmp.bpc");
    StoreU32(b, c[2].offset + 4, 0);  // slice 1 claims to be slice 0
    FixChunkCrcs(b, c[2].offset);
    cases.push_back({"duplicate index", "slice index 0 a second time", b});
    std::string far = ReadAll(dir_ / "tmp.bpc");
    StoreU32(far, c[2].offset + 4, 7);
    FixChunkCrcs(far, c[2].offset);
    cases.push_back({"index out of range", "got slice index 7", far});
    std::string lie = ReadAll(dir_ / "tmp.bpc");
    const std::string key = "\"slice_count\": 2";
    const std::size_t at = lie.find(key, c[3].offset);
    ASSERT_NE(at, std::string::npos) << lie.substr(c[3].offset);
    lie[at + key.size() - 1] = '3';
    FixChunkCrcs(lie, c[3].offset);
    cases.push_back({"lying end count", "got slice_count 3", lie});
  }
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    const fs::path p = dir_ / "case.bpc";
    WriteText(p, k.bytes);
    const ToolRun info = RunTool("info " + Quote(p), dir_);
    EXPECT_EQ(info.exit_code, 1) << info.out << info.err;
    EXPECT_NE(info.out.find(k.needle), std::string::npos) << info.out;
    EXPECT_NE(info.err.find("refuse"), std::string::npos) << info.err;
    const ToolRun eval = RunTool("eval " + Quote(p) + " --in 0,0 --out 10,10", dir_);
    EXPECT_EQ(eval.exit_code, 1);
    EXPECT_NE(eval.err.find(k.needle), std::string::npos) << eval.err;
    EXPECT_EQ(std::count(eval.err.begin(), eval.err.end(), '\n'), 1) << eval.err;
    const ToolRun conv =
        RunTool("convert " + Quote(p) + " --out " + Quote(dir_ / "luts") + " --quiet", dir_);
    EXPECT_EQ(conv.exit_code, 1);
    EXPECT_NE((conv.out + conv.err).find(k.needle), std::string::npos) << conv.out << conv.err;
    for (const std::string& text : {info.out + info.err, eval.err, conv.out + conv.err})
      for (const char* bad : {"kFlag", "brdf::", "json.exception", "channel 0", "value 0 "})
        EXPECT_EQ(text.find(bad), std::string::npos) << bad << " in: " << text;
  }
}

// One detection rule: a capture, a KTX2 texture and a material file are recognised by content
// whatever their names, by info and eval alike.
TEST_F(SourcesCli, FilesAreRecognisedByContentNotName) {
  const fs::path bpc = WriteCapture("a", CaptureOf(Lambertian(), {0, 20}, 75, 5, 10));
  fs::copy_file(bpc, dir_ / "capture.dat");
  WriteText(dir_ / "material.txt", Lambertian().Json());
  EXPECT_EQ(sources::DetectFileKind((dir_ / "capture.dat").string()), sources::FileKind::kCapture);
  EXPECT_EQ(sources::DetectFileKind((dir_ / "material.txt").string()),
            sources::FileKind::kMaterial);
  const ToolRun info = RunTool("info " + Quote(dir_ / "capture.dat"), dir_);
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find(".bpc capture"), std::string::npos) << info.out;
  const auto f = Eval(dir_ / "material.txt", "10,0", "20,90");
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], Lambertian().kd[c] / kPi, 1e-9);
  // Special files are refused without blocking.
  EXPECT_THROW(sources::DetectFileKind(dir_.string()), IoError);
}

}  // namespace
}  // namespace brdf::tooltest
