// brdf::engines: engine selection, IEEE half conversion against published bit patterns, the
// files each engine folder receives, and manifests whose probe texels are the texture's own
// texels (decoded here from EXT_texture_shared_exponent, not with the exporter's decoder).
#include "brdf/engines/engine_export.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "brdf/core/error.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;
using engines::EngineSet;
using engines::ParseEngines;

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::uint32_t U32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}

// c = c_s · 2^(exp − 15 − 9) (EXT_texture_shared_exponent).
std::array<double, 3> Decode(std::uint32_t w) {
  const double scale = std::ldexp(1.0, static_cast<int>(w >> 27) - 24);
  return {(w & 511) * scale, ((w >> 9) & 511) * scale, ((w >> 18) & 511) * scale};
}

class EngineExport : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "brdf_engine_export_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  static Lut Pattern(std::vector<double> theta_in_deg) {
    Lut lut;
    lut.Resize(theta_in_deg.size());
    lut.theta_in_deg = std::move(theta_in_deg);
    for (std::size_t i = 0; i < lut.texels.size(); ++i)
      lut.texels[i] = static_cast<float>(0.001 * (1 + (i * 7919) % 4001));
    return lut;
  }
  fs::path dir_;
};

TEST(ParseEngines, AcceptsEachEngineAllAndNone) {
  const EngineSet all = ParseEngines("all");
  EXPECT_TRUE(all.unity && all.unreal && all.godot && all.web);
  const EngineSet two = ParseEngines("web,unity");
  EXPECT_TRUE(two.unity && two.web && !two.unreal && !two.godot);
  EXPECT_FALSE(ParseEngines("").Any());
  EXPECT_FALSE(ParseEngines("none").Any());
  try {
    ParseEngines("unity,unrael");
    FAIL() << "accepted a misspelt engine";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "unknown engine 'unrael' (known: unity, unreal, godot, web, all)");
  }
}

// Bit patterns from IEEE 754-2008 binary16 (e.g. the table in its Wikipedia article).
TEST(FloatToHalf, MatchesPublishedBitPatterns) {
  EXPECT_EQ(engines::FloatToHalf(1.0f), 0x3c00);
  EXPECT_EQ(engines::FloatToHalf(-2.0f), 0xc000);
  EXPECT_EQ(engines::FloatToHalf(65504.0f), 0x7bff);               // largest finite
  EXPECT_EQ(engines::FloatToHalf(65520.0f), 0x7c00);               // rounds to infinity
  EXPECT_EQ(engines::FloatToHalf(std::ldexp(1.0f, -14)), 0x0400);  // smallest normal
  EXPECT_EQ(engines::FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);  // smallest subnormal
  EXPECT_EQ(engines::FloatToHalf(std::ldexp(1.0f, -25)), 0x0000);  // ties to even: 0
  EXPECT_EQ(engines::FloatToHalf(0.333333343f), 0x3555);
  EXPECT_EQ(engines::FloatToHalf(0.1f), 0x2e66);
  EXPECT_EQ(engines::FloatToHalf(65408.0f), 0x7bfc);  // the largest RGB9E5 value, exact
}

TEST_F(EngineExport, WritesEveryEngineFolderWithTheContainersAsBytes) {
  const Lut lut = Pattern({0, 20, 40, 60});
  exporter::TextureMetadata meta;
  meta.name = "felt";
  meta.source = "felt.bpc";
  const auto r = engines::ExportLutWithEngines(dir_.string(), lut, meta, {}, ParseEngines("all"));
  for (const char* f : {"unity/felt.brdf3d",
                        "unity/Editor/MeasuredBrdfImporter.cs",
                        "unity/MeasuredBrdf.hlsl",
                        "unity/felt.manifest.json",
                        "unreal/felt.dds",
                        "unreal/felt_tiles.exr",
                        "unreal/MeasuredBrdf.ush",
                        "unreal/import_measured_brdf.py",
                        "unreal/felt.manifest.json",
                        "godot/felt.dds",
                        "godot/felt_slices.exr",
                        "godot/felt_slices.exr.import",
                        "godot/measured_brdf.gdshader",
                        "godot/felt.manifest.json",
                        "web/felt.ktx2",
                        "web/measured_brdf.js",
                        "web/index.html",
                        "web/package.json",
                        "web/felt.manifest.json",
                        "web/MeasuredBrdf.es300.glsl",
                        "web/MeasuredBrdf.450.glsl"})
    EXPECT_TRUE(fs::is_regular_file(dir_ / f)) << f;
  EXPECT_EQ(r.written.size(), 21u);
  const std::string ktx2 = Read(dir_ / "felt.ktx2");
  EXPECT_EQ(Read(dir_ / "unity/felt.brdf3d"), ktx2);
  EXPECT_EQ(Read(dir_ / "web/felt.ktx2"), ktx2);
  EXPECT_EQ(Read(dir_ / "godot/felt.dds"), Read(dir_ / "felt.dds"));
  // The paths a failed conversion must remove are the per-material ones.
  const auto paths = engines::EngineOutputPaths(dir_.string(), "felt", ParseEngines("all"));
  EXPECT_EQ(paths.size(), 11u);
  for (const std::string& p : paths) EXPECT_TRUE(fs::is_regular_file(p)) << p;
}

TEST_F(EngineExport, ManifestProbesAreTheTexturesOwnTexels) {
  const Lut lut = Pattern({0, 20, 40, 60});
  exporter::TextureMetadata meta;
  meta.name = "p";
  engines::ExportLutWithEngines(dir_.string(), lut, meta, {}, ParseEngines("unity,godot"));
  const std::string ktx2 = Read(dir_ / "p.ktx2");
  const std::size_t level = static_cast<std::size_t>(U32(ktx2, 80));  // level 0 byteOffset
  for (const char* engine : {"unity", "godot"}) {
    const auto j = nlohmann::json::parse(Read(dir_ / engine / "p.manifest.json"));
    EXPECT_EQ(j["engines"][engine]["folder"], engine);
    EXPECT_EQ(j["engines"].size(), 2u);
    EXPECT_EQ(j["texture"]["width"], 361);
    EXPECT_EQ(j["texture"]["depth"], 4);
    EXPECT_EQ(j["axes"]["w"]["range_deg"], nlohmann::json::array({0.0, 60.0}));
    EXPECT_EQ(j["axes"]["u"]["range_deg"], nlohmann::json::array({0, 360}));
    EXPECT_TRUE(j["fallback_material"].is_null());
    ASSERT_GE(j["probe_texels"].size(), 4u * 7u);
    for (const auto& p : j["probe_texels"]) {
      const int x = p["index"][0], y = p["index"][1], z = p["index"][2];
      const auto expect =
          Decode(U32(ktx2, level + 4 * ((static_cast<std::size_t>(z) * 181 + y) * 361 + x)));
      for (int c = 0; c < 3; ++c) EXPECT_EQ(p["rgb"][c].get<double>(), expect[c]) << p.dump();
      EXPECT_DOUBLE_EQ(p["uvw"][0].get<double>(), (x + 0.5) / 361);
      EXPECT_DOUBLE_EQ(p["theta_in_deg"].get<double>(), 20.0 * z);
    }
  }
}

TEST_F(EngineExport, FittedModelsBecomeTheFallbackMaterial) {
  exporter::TextureMetadata meta;
  meta.name = "f";
  meta.fitted_models_json = {R"({"model": "ggx", "kd": [0.1, 0.1, 0.1], "f0": [0.04, 0.04, 0.04],
                                 "alpha": 0.3, "fit": {"rmse": 0.01}})"};
  engines::ExportLutWithEngines(dir_.string(), Pattern({0, 20, 40, 60}), meta, {},
                                ParseEngines("web"));
  const auto j = nlohmann::json::parse(Read(dir_ / "web/f.manifest.json"));
  EXPECT_EQ(j["fallback_material"]["models"][0]["model"], "ggx");
  EXPECT_EQ(j["fallback_material"]["models"][0]["fit"]["rmse"], 0.01);
}

TEST_F(EngineExport, LayoutsOtherThanTheReferenceGetTheirOwnShaderFiles) {
  exporter::TextureMetadata a, b;
  a.name = "a";
  b.name = "b";
  engines::ExportLutWithEngines(dir_.string(), Pattern({0, 20, 40, 60}), a, {},
                                ParseEngines("unity"));
  engines::ExportLutWithEngines(dir_.string(), Pattern({10, 25, 40}), b, {}, ParseEngines("unity"));
  const std::string ref = Read(dir_ / "unity/MeasuredBrdf.hlsl");
  const std::string other = Read(dir_ / "unity/MeasuredBrdf_3x15from10.hlsl");
  EXPECT_NE(ref.find("MEASURED_BRDF_DELTA_IN_DEG = 20.0;"), std::string::npos);
  EXPECT_NE(other.find("MEASURED_BRDF_DELTA_IN_DEG = 15.0;"), std::string::npos);
  EXPECT_NE(other.find("MEASURED_BRDF_THETA_IN0_DEG = 10.0;"), std::string::npos);
  const auto j = nlohmann::json::parse(Read(dir_ / "unity/b.manifest.json"));
  EXPECT_EQ(j["engines"]["unity"]["files"]["shader"], "MeasuredBrdf_3x15from10.hlsl");
}

TEST_F(EngineExport, AtlasFoldersAddressEachMaterialsCell) {
  const Lut l0 = Pattern({0, 20, 40, 60}), l1 = Pattern({0, 20, 40, 60}),
            l2 = Pattern({0, 20, 40, 60});
  const std::vector<exporter::AtlasMaterial> materials = {
      {"m0", &l0, "m0.json"}, {"m1", &l1, "m1.json"}, {"m2", &l2, "m2.json"}};
  const std::string prefix = (dir_ / "set").string();
  const auto written =
      engines::WriteAtlasWithEngines(prefix, materials, {}, ParseEngines("godot,web"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "godot/set.dds"));
  EXPECT_EQ(Read(dir_ / "godot/set.dds"), Read(dir_ / "set.dds"));
  EXPECT_EQ(Read(dir_ / "web/set.ktx2"), Read(dir_ / "set.ktx2"));
  const auto j = nlohmann::json::parse(Read(dir_ / "web/set.manifest.json"));
  EXPECT_TRUE(j["atlas"].get<bool>());
  ASSERT_EQ(j["cells"].size(), 3u);  // 2 × 2 cells: m2 at column 0, row 1
  EXPECT_EQ(j["cells"][1]["x0"], 361);
  EXPECT_EQ(j["cells"][2]["y0"], 181);
  EXPECT_EQ(j["texture"]["width"], 722);
  const std::string shader =
      Read(dir_ / "web" / j["engines"]["web"]["files"]["shader"].get<std::string>());
  EXPECT_NE(shader.find("MEASURED_BRDF_TEXELS_U = 722.0;"), std::string::npos);
  EXPECT_NE(shader.find("MEASURED_BRDF_TEXELS_V = 362.0;"), std::string::npos);
}

}  // namespace
}  // namespace brdf
