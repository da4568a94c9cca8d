// `brdf convert`, `brdf eval` and `brdf info` on exported LUTs, run as a user runs them: the
// built tool on material files this test writes. Expected values come from the analytic
// formulas, the specular frame and the RGB9E5 layout written out in tool_test_util.h, and the
// container layouts read here from their specifications.
#include <zlib.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <random>

#include "brdf/exporter/exr.h"
#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

using Json = nlohmann::json;

// 361 × 181 texels × K = 4 slices × 4 bytes = 1,045,456 (docs/design.md §5).
constexpr std::size_t kPayloadBytesK4 = 361u * 181u * 4u * 4u;

const std::vector<double> kThetaIn = {0, 20, 40, 60};

struct Named {
  std::string name;
  Analytic material;
};
std::vector<Named> Materials() {
  return {{"lambert", Lambertian()}, {"ggx", Ggx03()}, {"lafortune", Lafortune20()}};
}

// The three materials converted once for the whole suite (the conversion is the slow part).
class ConvertedMaterials : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(brdf::test::ScopedTempDir::MakeTempDir("convert"));
    fs::create_directories(*root_ / "in");
    for (const Named& m : Materials())
      WriteText(*root_ / "in" / (m.name + ".json"), m.material.Json());
    // --beyond clamp: this suite checks the containers, the texel quantisation and the §6
    // band of the measured slices; the default blind-spot fill (more slices, a model-filled
    // band) is checked by the atlas test and tests/python/beyond_oracle.py.
    run_ = new ToolRun(RunTool("convert " + Quote(*root_ / "in") + " --out " +
                                   Quote(*root_ / "out") + " --jobs 2 --beyond clamp",
                               *root_));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
    delete run_;
  }
  static fs::path Out(const std::string& file) { return *root_ / "out" / file; }
  static fs::path* root_;
  static ToolRun* run_;
};
fs::path* ConvertedMaterials::root_ = nullptr;
ToolRun* ConvertedMaterials::run_ = nullptr;

TEST_F(ConvertedMaterials, WritesEveryFormatForEachMaterial) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  EXPECT_NE(run_->out.find("converted 3 of 3"), std::string::npos) << run_->out;
  for (const Named& m : Materials()) {
    SCOPED_TRACE(m.name);
    for (const char* ext : {".ktx2", ".dds", ".exr", ".png", ".json"})
      EXPECT_TRUE(fs::is_regular_file(Out(m.name + ext))) << m.name << ext;

    const Texture3d ktx2 = ReadKtx2Layout(Out(m.name + ".ktx2"));
    EXPECT_EQ(ktx2.format, 123u);  // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
    EXPECT_EQ(ktx2.width, 361u);
    EXPECT_EQ(ktx2.height, 181u);
    EXPECT_EQ(ktx2.depth, 4u);
    EXPECT_EQ(ktx2.payload.size(), kPayloadBytesK4);

    const Texture3d dds = ReadDdsLayout(Out(m.name + ".dds"));
    EXPECT_EQ(dds.format, 67u);  // DXGI_FORMAT_R9G9B9E5_SHAREDEXP
    EXPECT_EQ(dds.width, 361u);
    EXPECT_EQ(dds.height, 181u);
    EXPECT_EQ(dds.depth, 4u);
    EXPECT_TRUE(dds.payload == ktx2.payload) << "DDS and KTX2 payloads differ";

    const Json sidecar = Json::parse(ReadAll(Out(m.name + ".json")));
    EXPECT_EQ(sidecar["kind"], "brdf-lut-sidecar");
    EXPECT_EQ(sidecar["theta_in_deg"].get<std::vector<double>>(), kThetaIn);
    EXPECT_EQ(sidecar["payload"]["bytes"].get<std::size_t>(), kPayloadBytesK4);
    char crc[16];
    std::snprintf(crc, sizeof crc, "0x%08lx",
                  ::crc32(0L, reinterpret_cast<const Bytef*>(ktx2.payload.data()),
                          static_cast<uInt>(ktx2.payload.size())));
    EXPECT_EQ(sidecar["payload"]["checksum"]["value"], crc);
    EXPECT_EQ(sidecar["extrapolation"]["p"], 1.0);
    EXPECT_EQ(sidecar["extrapolation"]["l"], 0.5);
    EXPECT_EQ(sidecar["extrapolation"]["theta_b_deg"], 75.0);

    // PNG: signature, then the IHDR chunk's big-endian width and height (the 2 × 2 composite).
    const std::string png = ReadAll(Out(m.name + ".png"));
    ASSERT_GE(png.size(), 24u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    const auto be32 = [&](std::size_t at) {
      return (static_cast<std::uint32_t>(static_cast<unsigned char>(png[at])) << 24) |
             (static_cast<std::uint32_t>(static_cast<unsigned char>(png[at + 1])) << 16) |
             (static_cast<std::uint32_t>(static_cast<unsigned char>(png[at + 2])) << 8) |
             static_cast<unsigned char>(png[at + 3]);
    };
    EXPECT_EQ(be32(16), 722u);
    EXPECT_EQ(be32(20), 362u);

    // EXR composite (2 × 2 slices, top-left first): each float pixel quantises to the KTX2 texel.
    const exporter::ExrFile exr = exporter::ReadExr(Out(m.name + ".exr").string());
    ASSERT_EQ(exr.image.width, 722);
    ASSERT_EQ(exr.image.height, 362);
    double worst = 0;
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 181; j += 4)
        for (int i = 0; i < 361; i += 4) {
          const float* px = exr.image.Pixel((k % 2) * 361 + i, (k / 2) * 181 + j);
          const auto q = DecodeRgb9e5Word(ktx2.Word(i, j, k));
          const double step = Rgb9e5Step(std::max({px[0], px[1], px[2], 1e-30f}));
          for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(px[c] - q[c]) / step);
        }
    EXPECT_LE(worst, 0.5 + 1e-6) << "EXR value and KTX2 texel differ by more than half a step";
  }
  EXPECT_TRUE(FilesStartingWith(*root_ / "out", ".").empty()) << "temporary files left behind";
}

// The LUT value at a texel whose direction is inside the measured range is the bilinear
// interpolation of the capture's 1° lattice, so it lies between the analytic values at the
// four surrounding lattice nodes; in the extrapolated band (defaults p = 1: clamping) between
// the values at θb = 75° of the two neighbouring φ nodes. RGB9E5 then moves it by at most half
// a quantisation step of its largest channel.
struct Bound {
  std::array<double, 3> lo, hi;
};
Bound LatticeBound(const Analytic& m, double theta_in, double theta_out, double phi_out) {
  Bound b;
  b.lo.fill(1e300);
  b.hi.fill(-1e300);
  const double t = std::min(theta_out, 75.0);
  const double t0 = std::floor(t), t1 = std::min(75.0, std::ceil(t));
  const double p0 = std::floor(phi_out), p1 = std::ceil(phi_out);
  for (double tt : {t0, t1})
    for (double pp : {p0, p1}) {
      const auto f = m.FAngles(theta_in, tt, std::fmod(pp, 360.0));
      for (int c = 0; c < 3; ++c) {
        b.lo[c] = std::min(b.lo[c], f[c]);
        b.hi[c] = std::max(b.hi[c], f[c]);
      }
    }
  return b;
}

TEST_F(ConvertedMaterials, EvalOfKtx2AtTexelCentresEqualsQuantisedAnalytic) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  std::mt19937 rng(7);
  for (const Named& m : Materials()) {
    SCOPED_TRACE(m.name);
    // Texels above the horizon: the poles (mirror direction), then random ones.
    struct Texel {
      int i, j, k;
      double theta_out, phi_out;
    };
    std::vector<Texel> texels;
    for (int k = 0; k < 4; ++k)
      for (int n = 0; n < 100; ++n) {
        const int i = n == 0 ? 0 : static_cast<int>(rng() % 361);
        const int j = n == 0 ? 0 : static_cast<int>(rng() % 181);
        const auto d = TexelDirection(kThetaIn[k], i, j);
        if (d[0] <= 89.9) texels.push_back({i, j, k, d[0], d[1]});
      }
    std::string pairs;
    for (const Texel& t : texels)
      pairs += Angles(kThetaIn[t.k], 0) + " " + Angles(t.theta_out, t.phi_out) + "\n";
    WriteText(*root_ / "pairs.txt", pairs);
    const ToolRun r = RunTool(
        "eval " + Quote(Out(m.name + ".ktx2")) + " --pairs " + Quote(*root_ / "pairs.txt"), *root_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream lines(r.out);
    std::string line;
    std::size_t checked = 0, in_band = 0;
    for (const Texel& t : texels) {
      ASSERT_TRUE(std::getline(lines, line));
      const auto got = ParseTriple(line);
      const Bound b = LatticeBound(m.material, kThetaIn[t.k], t.theta_out, t.phi_out);
      const double step = Rgb9e5Step(std::max({b.hi[0], b.hi[1], b.hi[2]}));
      for (int c = 0; c < 3; ++c) {
        const double tol = 0.5 * step + 1e-6 * b.hi[c];
        EXPECT_GE(got[c], b.lo[c] - tol)
            << "texel " << t.i << "," << t.j << "," << t.k << " c" << c;
        EXPECT_LE(got[c], b.hi[c] + tol)
            << "texel " << t.i << "," << t.j << "," << t.k << " c" << c;
      }
      ++checked;
      if (t.theta_out > 75) ++in_band;
    }
    EXPECT_GT(checked, 150u);
    EXPECT_GT(in_band, 5u) << "no texel of the extrapolated band was checked";
  }
}

TEST_F(ConvertedMaterials, LambertianLutHoldsExactlyTheQuantisedAlbedo) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  // Every texel, extrapolated and below-horizon ones included, is RGB9E5(ρ/π).
  const Texture3d ktx2 = ReadKtx2Layout(Out("lambert.ktx2"));
  const Analytic m = Lambertian();
  const double step = Rgb9e5Step(m.kd[0] / kPi);
  const std::uint32_t first = ktx2.Word(0, 0, 0);
  const auto q = DecodeRgb9e5Word(first);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(q[c], m.kd[c] / kPi, 0.5 * step);
    EXPECT_DOUBLE_EQ(std::round(q[c] / step), q[c] / step) << "not on the RGB9E5 grid";
  }
  std::size_t differing = 0;
  for (std::size_t w = 0; w < ktx2.payload.size() / 4; ++w)
    differing += LoadU32(ktx2.payload, w * 4) != first;
  EXPECT_EQ(differing, 0u);
}

TEST_F(ConvertedMaterials, EvalOfSidecarAndDdsEqualsEvalOfKtx2) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  WriteText(*root_ / "few.txt", "0 0 10 30\n20 0 30 180\n40 90 50 270\n60 0 80 170\n30 0 45 181\n");
  for (const Named& m : Materials()) {
    const auto eval = [&](const std::string& ext) {
      const ToolRun r = RunTool(
          "eval " + Quote(Out(m.name + ext)) + " --pairs " + Quote(*root_ / "few.txt"), *root_);
      EXPECT_EQ(r.exit_code, 0) << r.err;
      return r.out;
    };
    const std::string ktx2 = eval(".ktx2");
    EXPECT_EQ(std::count(ktx2.begin(), ktx2.end(), '\n'), 5);
    EXPECT_EQ(eval(".json"), ktx2) << m.name;
    EXPECT_EQ(eval(".dds"), ktx2) << m.name;
  }
}

TEST_F(ConvertedMaterials, InfoReportsDimensionsPayloadChecksumAndRanges) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const Texture3d ktx2 = ReadKtx2Layout(Out("ggx.ktx2"));
  for (const char* ext : {".ktx2", ".dds", ".json"}) {
    SCOPED_TRACE(ext);
    const ToolRun r = RunTool("info --json " + Quote(Out(std::string("ggx") + ext)), *root_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Json j = Json::parse(r.out);
    EXPECT_EQ(j["width"], 361);
    EXPECT_EQ(j["height"], 181);
    EXPECT_EQ(j["slices"], 4);
    EXPECT_EQ(j["theta_in_deg"].get<std::vector<double>>(), kThetaIn);
    EXPECT_EQ(j["payload_bytes"].get<std::size_t>(), kPayloadBytesK4);
    EXPECT_NE(j["checksum"].get<std::string>().find("verified against"), std::string::npos);
    EXPECT_EQ(j["extrapolation"]["p"], 1.0);
    EXPECT_EQ(j["extrapolation"]["theta_b_deg"], 75.0);
    for (int k = 0; k < 4; ++k) {
      std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
      for (int y = 0; y < 181; ++y)
        for (int x = 0; x < 361; ++x) {
          const auto v = DecodeRgb9e5Word(ktx2.Word(x, y, k));
          for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], v[c]), hi[c] = std::max(hi[c], v[c]);
        }
      const Json& range = j["value_ranges"][k];
      for (int c = 0; c < 3; ++c) {
        EXPECT_DOUBLE_EQ(range["rgb_min"][c].get<double>(), lo[c]);
        EXPECT_DOUBLE_EQ(range["rgb_max"][c].get<double>(), hi[c]);
      }
    }
  }
}

TEST_F(ConvertedMaterials, InfoAndEvalRefuseATextureWithAChangedTexel) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const fs::path bad = *root_ / "tampered.ktx2";
  std::string bytes = ReadAll(Out("ggx.ktx2"));
  bytes[bytes.size() - 1000] ^= 0x10;  // inside the level 0 image
  WriteText(bad, bytes);
  for (const std::string cmd : {"info ", "eval --in 0,0 --out 10,0 "}) {
    const ToolRun r = RunTool(cmd + Quote(bad), *root_);
    EXPECT_EQ(r.exit_code, 1) << cmd;
    EXPECT_NE(r.err.find("tampered.ktx2"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("CRC-32"), std::string::npos) << r.err;
  }
}

class ConvertOptions : public ToolTest {};

TEST_F(ConvertOptions, ExtrapolationComesFromTheMostSpecificSource) {
  fs::create_directories(dir_ / "in");
  // ggx: its own "extrapolate" member; lafortune: a file beside it (overriding p only);
  // lambert: nothing of its own, so the command line.
  WriteText(dir_ / "in" / "ggx.json", Ggx03().Json(", \"extrapolate\": {\"p\": 0.2, \"l\": 0.3}"));
  WriteText(dir_ / "in" / "lafortune.json", Lafortune20().Json());
  WriteText(dir_ / "in" / "lafortune.extrapolate.json", "{\"extrapolate\": {\"p\": 0.4}}");
  WriteText(dir_ / "in" / "lambert.json", Lambertian().Json());
  // --beyond clamp: the §6 band as the parameters give it (the fill's model replaces it).
  const ToolRun r = RunTool("convert " + Quote(dir_ / "in") + " --out " + Quote(dir_ / "out") +
                                " --extrapolate 0.5,0.7 --formats ktx2,json --quiet --beyond clamp",
                            dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("converted 3 of 3"), std::string::npos) << r.out;
  const auto params = [&](const std::string& name) {
    const Json j = Json::parse(ReadAll(dir_ / "out" / (name + ".json")));
    return std::array<double, 2>{j["extrapolation"]["p"].get<double>(),
                                 j["extrapolation"]["l"].get<double>()};
  };
  EXPECT_EQ(params("ggx"), (std::array<double, 2>{0.2, 0.3}));
  EXPECT_EQ(params("lafortune"), (std::array<double, 2>{0.4, 0.5}));
  EXPECT_EQ(params("lambert"), (std::array<double, 2>{0.5, 0.7}));
  // --formats: only the KTX2 and the sidecar.
  EXPECT_EQ(FilesStartingWith(dir_ / "out", "ggx").size(), 2u);
  EXPECT_FALSE(fs::exists(dir_ / "out" / "ggx.exr"));

  // The GGX LUT in the band beyond θb = 75°: f(75°, φ)·((1 − α) + α·p) with
  // α = b(min((θ − 75°)/15°, 1), l), p = 0.2, l = 0.3 (docs/design.md §6), at texel centres.
  const Analytic m = Ggx03();
  std::string pairs;
  std::vector<std::array<double, 3>> dirs;  // θin, θout, φout
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j <= 180; j += 3)
      for (int i = 0; i <= 360; i += 7) {
        const auto d = TexelDirection(kThetaIn[k], i, j);
        if (d[0] <= 75.5 || d[0] > 89.5) continue;
        dirs.push_back({kThetaIn[k], d[0], d[1]});
        pairs += Angles(kThetaIn[k], 0) + " " + Angles(d[0], d[1]) + "\n";
      }
  ASSERT_GT(dirs.size(), 50u);
  WriteText(dir_ / "pairs.txt", pairs);
  const ToolRun e = RunTool(
      "eval " + Quote(dir_ / "out" / "ggx.ktx2") + " --pairs " + Quote(dir_ / "pairs.txt"), dir_);
  ASSERT_EQ(e.exit_code, 0) << e.err;
  std::istringstream lines(e.out);
  std::string line;
  for (const auto& d : dirs) {
    ASSERT_TRUE(std::getline(lines, line));
    const auto got = ParseTriple(line);
    const double alpha = BezierByBisection(std::min((d[1] - 75.0) / 15.0, 1.0), 0.3);
    const double factor = (1 - alpha) + alpha * 0.2;
    const Bound b = LatticeBound(m, d[0], 75.0, d[2]);
    const double step = Rgb9e5Step(factor * std::max({b.hi[0], b.hi[1], b.hi[2]}));
    for (int c = 0; c < 3; ++c) {
      const double tol = 0.5 * step + 1e-6 * b.hi[c];
      EXPECT_GE(got[c], factor * b.lo[c] - tol) << d[0] << " " << d[1] << " " << d[2];
      EXPECT_LE(got[c], factor * b.hi[c] + tol) << d[0] << " " << d[1] << " " << d[2];
    }
  }
}

TEST_F(ConvertOptions, RefusesToOverwriteItsInput) {
  // Converting a material folder into itself would replace gold.json by gold's sidecar.
  const std::string material = Lambertian().Json();
  WriteText(dir_ / "gold.json", material);
  const ToolRun r = RunTool("convert " + Quote(dir_) + " --out " + Quote(dir_) + " --quiet", dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("converted 0 of 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("would overwrite an input"), std::string::npos) << r.out;
  EXPECT_EQ(ReadAll(dir_ / "gold.json"), material);
  EXPECT_FALSE(fs::exists(dir_ / "gold.ktx2"));
}

TEST_F(ConvertOptions, ReportsMissingAndUnknownInputsAndConvertsTheRest) {
  WriteText(dir_ / "gold.json", Lambertian().Json());
  WriteText(dir_ / "notes.txt", "not a material");
  WriteText(dir_ / "config.json", "{\"colour\": \"red\"}");
  const ToolRun r =
      RunTool("convert " + Quote(dir_ / "gold.json") + " " + Quote(dir_ / "nope.bpc") + " " +
                  Quote(dir_ / "notes.txt") + " " + Quote(dir_ / "config.json") + " --out " +
                  Quote(dir_ / "out") + " --formats ktx2 --quiet",
              dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("converted 1 of 4"), std::string::npos) << r.out;
  for (const char* name : {"nope.bpc", "notes.txt", "config.json"})
    EXPECT_NE(r.out.find(name), std::string::npos) << name << " not reported: " << r.out;
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / "gold.ktx2"));
}

}  // namespace
}  // namespace brdf::tooltest
