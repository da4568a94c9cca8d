// brdf::engines: engine selection, IEEE half conversion against published bit patterns and
// against numpy's float16 (Debian /usr/bin/python3, run by the test), the files each engine
// folder receives, and manifests whose probe texels are the texture's own
// texels (decoded here from EXT_texture_shared_exponent, not with the exporter's decoder).
#include "brdf/engines/engine_export.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/exporter/packed_volume.h"

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

// numpy's float32 → float16 conversion (round to nearest even, subnormals, overflow to inf) of
// `values`, run in Debian's python: an implementation independent of the code under test.
std::vector<std::uint16_t> NumpyHalves(const std::vector<float>& values, const fs::path& dir) {
  const fs::path in = dir / "floats.bin", out = dir / "halves.bin";
  std::ofstream(in, std::ios::binary)
      .write(reinterpret_cast<const char*>(values.data()),
             static_cast<std::streamsize>(values.size() * sizeof(float)));
  const std::string cmd = std::string(BRDF_PYTHON3) +
                          " -c \"import numpy as np, sys; np.fromfile(sys.argv[1], '<f4')"
                          ".astype('<f2').tofile(sys.argv[2])\" '" +
                          in.string() + "' '" + out.string() + "'";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd << ": Debian python3 with numpy is required";
  const std::string bytes = Read(out);
  std::vector<std::uint16_t> halves(bytes.size() / 2);
  for (std::size_t i = 0; i < halves.size(); ++i)
    halves[i] = static_cast<std::uint16_t>(static_cast<unsigned char>(bytes[2 * i]) |
                                           (static_cast<unsigned char>(bytes[2 * i + 1]) << 8));
  EXPECT_EQ(halves.size(), values.size());
  return halves;
}

// Every value an RGB9E5 channel can hold (32 exponents × 512 mantissas, subnormal halves
// included), converted by the table the Unreal DDS uses, equals numpy's float16 of the same
// value; and Rgba16fBytes puts those halves, with alpha 1.0, where each channel belongs.
TEST_F(EngineExport, Rgb9e5ChannelHalvesEqualNumpyForEveryChannelValue) {
  std::vector<float> values;
  std::vector<std::uint16_t> ours;
  for (std::uint32_t e = 0; e < 32; ++e)
    for (std::uint32_t m = 0; m < 512; ++m) {
      values.push_back(static_cast<float>(std::ldexp(static_cast<double>(m), int(e) - 24)));
      ours.push_back(engines::Rgb9e5ChannelToHalf(m, e));
    }
  const std::vector<std::uint16_t> numpy = NumpyHalves(values, dir_);
  ASSERT_EQ(numpy.size(), ours.size());
  int differing = 0;
  for (std::size_t i = 0; i < ours.size(); ++i)
    if (ours[i] != numpy[i] && ++differing <= 5)
      ADD_FAILURE() << "m " << i % 512 << " e " << i / 512 << " (" << values[i] << "): 0x"
                    << std::hex << ours[i] << ", numpy 0x" << numpy[i];
  EXPECT_EQ(differing, 0);

  exporter::PackedVolume vol;  // every (e, m) once in each channel, mantissas rotated
  vol.width = 512;
  vol.height = 32;
  vol.depth = 1;
  for (std::uint32_t e = 0; e < 32; ++e)
    for (std::uint32_t m = 0; m < 512; ++m)
      vol.words.push_back((e << 27) | m | (((m + 171) % 512) << 9) | (((m + 342) % 512) << 18));
  const std::string bytes = engines::Rgba16fBytes(vol);
  ASSERT_EQ(bytes.size(), vol.words.size() * 8);
  const auto half_at = [&](std::size_t t, int c) {
    return static_cast<std::uint16_t>(static_cast<unsigned char>(bytes[8 * t + 2 * c]) |
                                      (static_cast<unsigned char>(bytes[8 * t + 2 * c + 1]) << 8));
  };
  for (std::size_t t = 0; t < vol.words.size(); ++t) {
    const std::size_t e = t / 512, m = t % 512;
    ASSERT_EQ(half_at(t, 0), numpy[e * 512 + m]) << t;
    ASSERT_EQ(half_at(t, 1), numpy[e * 512 + (m + 171) % 512]) << t;
    ASSERT_EQ(half_at(t, 2), numpy[e * 512 + (m + 342) % 512]) << t;
    ASSERT_EQ(half_at(t, 3), 0x3c00) << t;
  }
}

// FloatToHalf against numpy where rounding matters: every half value, every midpoint between
// neighbouring halves (the ties, which go to the even neighbour) and the floats one ulp either
// side of it, the subnormal range, overflow near 65520, and 300 000 random floats of every
// exponent from 2^-30 to 2^17, both signs. NaNs are compared as NaN.
TEST_F(EngineExport, FloatToHalfEqualsNumpyIncludingTiesAndSubnormals) {
  std::vector<float> values;
  const auto half_value = [](std::uint32_t h) {  // decoded from the bit pattern (IEEE 754)
    const std::uint32_t exp = (h >> 10) & 31, frac = h & 1023;
    const double mag =
        exp == 0 ? std::ldexp(double(frac), -24) : std::ldexp(1.0 + frac / 1024.0, int(exp) - 15);
    return (h & 0x8000) ? -mag : mag;
  };
  for (std::uint32_t h = 0; h < 0x7c00; ++h) {
    for (std::uint32_t sign : {0u, 0x8000u}) {
      const double v = half_value(h | sign);
      values.push_back(static_cast<float>(v));
      const double next = h + 1 < 0x7c00 ? half_value((h + 1) | sign) : (sign ? -65536.0 : 65536.0);
      const float tie = static_cast<float>((v + next) / 2);  // exact in float
      values.push_back(tie);
      values.push_back(std::nextafter(tie, 0.0f));
      values.push_back(std::nextafter(tie, tie * 2));
    }
  }
  for (float v :
       {65504.0f, 65519.0f, 65520.0f, 1e6f, std::ldexp(1.0f, -25), std::ldexp(1.0f, -26),
        std::ldexp(1.5f, -25), std::ldexp(1.0f, -40), 0.0f, -0.0f,
        std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
        std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::denorm_min()})
    values.push_back(v);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> exponent(-30, 17);
  std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
  for (int i = 0; i < 300000; ++i)
    values.push_back((i % 2 ? -1.0f : 1.0f) * std::ldexp(mantissa(rng), exponent(rng)));
  const std::vector<std::uint16_t> numpy = NumpyHalves(values, dir_);
  ASSERT_EQ(numpy.size(), values.size());
  int differing = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::uint16_t ours = engines::FloatToHalf(values[i]);
    const bool both_nan = (ours & 0x7fff) > 0x7c00 && (numpy[i] & 0x7fff) > 0x7c00;
    if (ours != numpy[i] && !both_nan && ++differing <= 5)
      ADD_FAILURE() << values[i] << ": 0x" << std::hex << ours << ", numpy 0x" << numpy[i];
  }
  EXPECT_EQ(differing, 0) << "of " << values.size();
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
                        "web/MeasuredBrdf.450.glsl",
                        "web/MeasuredBrdf.compact.es300.glsl"})
    EXPECT_TRUE(fs::is_regular_file(dir_ / f)) << f;
  for (const char* e : {"unity", "unreal", "godot", "web"})
    EXPECT_TRUE(fs::is_regular_file(dir_ / e / "felt_ibl.dds")) << e;
  EXPECT_EQ(r.written.size(), 26u);
  const std::string ktx2 = Read(dir_ / "felt.ktx2");
  EXPECT_EQ(Read(dir_ / "unity/felt.brdf3d"), ktx2);
  EXPECT_EQ(Read(dir_ / "web/felt.ktx2"), ktx2);
  EXPECT_EQ(Read(dir_ / "godot/felt.dds"), Read(dir_ / "felt.dds"));
  // The DDS streamed in 64 KiB chunks (the last one partial) holds the whole-volume encoding.
  EXPECT_EQ(Read(dir_ / "unreal/felt.dds"), engines::EncodeRgba16fDds(exporter::PackLut(lut)));
  // The paths a failed conversion must remove are the per-material ones.
  const auto paths = engines::EngineOutputPaths(dir_.string(), "felt", ParseEngines("all"));
  EXPECT_EQ(paths.size(), 15u);
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
      // docs/design.md §5: u = (φd/1° + 0.5)/361, v = (θd/1° + 0.5)/181, w = (θin/Δin + 0.5)/K,
      // texel (i, j) at (φd, θd) = (i°, j°) (one material: the cell starts at texel 0).
      EXPECT_DOUBLE_EQ(p["uvw"][0].get<double>(), (x + 0.5) / 361);
      EXPECT_DOUBLE_EQ(p["uvw"][1].get<double>(), (y + 0.5) / 181);
      EXPECT_DOUBLE_EQ(p["uvw"][2].get<double>(), (z + 0.5) / 4);
      EXPECT_EQ(p["phi_d_deg"].get<int>(), x);
      EXPECT_EQ(p["theta_d_deg"].get<int>(), y);
      EXPECT_DOUBLE_EQ(p["theta_in_deg"].get<double>(), 20.0 * z);
    }
    // Each slice's probes include its peak: the texel of largest Rec.709 luminance.
    const auto luminance = [](const std::array<double, 3>& c) {
      return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    };
    for (int z = 0; z < 4; ++z) {
      double peak = 0, probed = 0;
      for (std::size_t t = 0; t < 361u * 181u; ++t)
        peak = std::max(peak, luminance(Decode(U32(ktx2, level + 4 * (z * 361u * 181u + t)))));
      for (const auto& p : j["probe_texels"])
        if (p["index"][2] == z)
          probed = std::max(probed, luminance({p["rgb"][0], p["rgb"][1], p["rgb"][2]}));
      EXPECT_NEAR(probed, peak, 1e-12 * peak) << "slice " << z;
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

// `brdf fit` results (written here in its output form: NAME.MODEL.json with "model" and "fit")
// become the fallback material; other materials' fits and other files are not picked up.
TEST_F(EngineExport, FitResultsOfTheMaterialBecomeTheFallbackWithGltfValues) {
  const fs::path fits = dir_ / "fits";
  fs::create_directories(fits);
  std::ofstream(fits / "f.unreal-defaultlit.json")
      << R"({"name": "f", "model": "unreal-defaultlit", "base_color": [0.8, 0.5, 0.2],
             "metallic": 0.25, "specular": 0.6, "roughness": 0.4,
             "fit": {"status": "converged", "rmse": 0.03}})";
  std::ofstream(fits / "f.unity-urp-lit.json")
      << R"({"model": "unity-urp-lit", "base_color": [0.7, 0.4, 0.2], "metallic": 0.2,
             "smoothness": 0.6, "fit": {"status": "converged", "rmse": 0.05}})";
  std::ofstream(fits / "g.ggx.json") << R"({"model": "ggx", "fit": {"rmse": 1}})";
  std::ofstream(fits / "f.json") << R"({"model": "ggx"})";
  std::ofstream(fits / "f.ggx.extra.json") << R"({"model": "ggx"})";
  const std::vector<FittedMaterial> read = engines::ReadFitResults(fits.string(), "f");
  ASSERT_EQ(read.size(), 2u);
  exporter::TextureMetadata meta;
  meta.name = "f";
  fs::create_directories(dir_ / "out");
  engines::ExportLutWithEngines((dir_ / "out").string(), Pattern({0, 20, 40, 60}), meta, {},
                                ParseEngines("unreal,web"), read);
  const auto j = nlohmann::json::parse(Read(dir_ / "out/unreal/f.manifest.json"));
  const auto& fallback = j["fallback_material"];
  ASSERT_EQ(fallback["models"].size(), 2u);
  EXPECT_EQ(fallback["models"][0]["model"], "unity-urp-lit");  // file-name order
  EXPECT_EQ(fallback["models"][1]["fit"]["rmse"], 0.03);
  // glTF 2.0 + KHR_materials_specular, checked by the extensions' own formulas: dielectric
  // F0 = min(0.04 · specularColorFactor, 1) · specularFactor, F0 = mix(dielectric, baseColor,
  // metallic); Unreal: F0 = lerp(0.08 · Specular, BaseColor, Metallic) (ShadingModels.ush).
  const auto& g = fallback["gltf"]["material"];
  const auto& pbr = g["pbrMetallicRoughness"];
  const auto& spec = g["extensions"]["KHR_materials_specular"];
  const double metallic = pbr["metallicFactor"];
  EXPECT_DOUBLE_EQ(metallic, 0.25);
  EXPECT_DOUBLE_EQ(pbr["roughnessFactor"].get<double>(), 0.4);
  EXPECT_EQ(pbr["baseColorFactor"][3], 1.0);
  const double base[3] = {0.8, 0.5, 0.2};
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(pbr["baseColorFactor"][c].get<double>(), base[c]);
    const double dielectric = std::min(0.04 * spec["specularColorFactor"][c].get<double>(), 1.0) *
                              spec["specularFactor"].get<double>();
    const double gltf_f0 = dielectric * (1 - metallic) + base[c] * metallic;
    const double unreal_f0 = 0.08 * 0.6 * (1 - metallic) + base[c] * metallic;
    EXPECT_NEAR(gltf_f0, unreal_f0, 1e-15) << c;
  }
  EXPECT_EQ(fallback["gltf"]["rmse"], 0.03);
  EXPECT_EQ(Read(dir_ / "out/web/f.manifest.json"), Read(dir_ / "out/unreal/f.manifest.json"));

  std::ofstream(fits / "f.ward.json") << R"({"model": "ward", "fit": 3})";
  try {
    engines::ReadFitResults(fits.string(), "f");
    FAIL() << "accepted a fit without a fit report";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("f.ward.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a number"), std::string::npos) << e.what();
  }
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

// One web folder, two layouts: the viewer imports the module each material's manifest names
// (web_browser renders through it), so the second layout leaves index.html as it was.
TEST_F(EngineExport, OneViewerServesEveryLayoutOfTheWebFolder) {
  exporter::TextureMetadata a, b;
  a.name = "a";
  b.name = "b";
  engines::ExportLutWithEngines(dir_.string(), Pattern({0, 20, 40, 60}), a, {},
                                ParseEngines("web"));
  const std::string viewer = Read(dir_ / "web/index.html");
  engines::ExportLutWithEngines(dir_.string(), Pattern({10, 25, 40}), b, {}, ParseEngines("web"));
  EXPECT_EQ(Read(dir_ / "web/index.html"), viewer);
  EXPECT_EQ(viewer.find("measured_brdf"), std::string::npos) << "the viewer names a module";
  EXPECT_NE(viewer.find("manifest.engines.web.files.shader"), std::string::npos);
  for (const char* m : {"a", "b"}) {
    const auto j = nlohmann::json::parse(Read(dir_ / "web" / (std::string(m) + ".manifest.json")));
    const std::string module = j["engines"]["web"]["files"]["shader"];
    EXPECT_TRUE(fs::is_regular_file(dir_ / "web" / module)) << module;
  }
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
