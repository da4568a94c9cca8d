#include "brdf/exporter/atlas.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/lut_compression.h"
#include "brdf/exporter/rgb9e5.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

// Five distinct materials sharing θin {0, 20, 40, 60}.
struct Five {
  std::vector<Lut> luts;
  std::vector<AtlasMaterial> materials;
  Five() {
    const std::vector<double> theta = {0, 20, 40, 60};
    luts.push_back(test::AnalyticLut(test::Ggx03(), theta));
    luts.push_back(test::AnalyticLut(test::Lafortune20(), theta));
    luts.push_back(test::AnalyticLut(test::Lambert(0.9), theta));
    luts.push_back(test::PatternLut(theta, 41));
    luts.push_back(test::PatternLut(theta, 42));
    const char* names[] = {"ggx", "lafortune", "lambert", "pattern41", "pattern42"};
    for (int m = 0; m < 5; ++m)
      materials.push_back({names[m], &luts[m], std::string("src/") + names[m]});
  }
};

TEST(Atlas, LayoutFollowsDesignSection5) {
  const AtlasLayout l = ComputeAtlasLayout(5, 4);
  EXPECT_EQ(l.cells.columns, 3);  // ceil(√5)
  EXPECT_EQ(l.cells.rows, 2);     // ceil(5/3)
  EXPECT_EQ(l.TextureWidth(), 3 * 361);
  EXPECT_EQ(l.TextureHeight(), 2 * 181);
  EXPECT_EQ(l.composite.columns, 2);
  EXPECT_EQ(l.composite.rows, 2);
  EXPECT_EQ(l.ImageWidth(), 2 * 3 * 361);
  EXPECT_EQ(l.ImageHeight(), 2 * 2 * 181);
  const AtlasLayout one = ComputeAtlasLayout(1, 4);
  EXPECT_EQ(one.TextureWidth(), 361);
  EXPECT_EQ(one.ImageWidth(), 722);
  EXPECT_EQ(one.ImageHeight(), 362);
}

TEST(Atlas, EachCellOfEveryContainerEqualsItsOwnLut) {
  const Five five;
  const std::string dir = test::TestDir("atlas_cells");
  const std::vector<std::string> written = WriteAtlas(dir + "/five", five.materials);
  EXPECT_EQ(written.size(), 4u);
  // The list a caller's overwrite check covers is exactly what was written.
  EXPECT_EQ(AtlasOutputPaths(dir + "/five"), written);
  const LoadedTexture ktx2 = ReadKtx2(dir + "/five.ktx2");
  const LoadedTexture dds = ReadTextureFile(dir + "/five.dds");
  const ExrFile exr = ReadExr(dir + "/five.exr");
  ASSERT_EQ(ktx2.volume.width, 3 * 361);
  ASSERT_EQ(ktx2.volume.height, 2 * 181);
  ASSERT_EQ(ktx2.volume.depth, 4);
  EXPECT_FALSE(ktx2.IsSingleLut());
  EXPECT_TRUE(ktx2.theta_in_from_metadata);
  EXPECT_TRUE(dds.theta_in_from_metadata);  // from the manifest beside it
  EXPECT_EQ(dds.volume.words, ktx2.volume.words);
  ASSERT_EQ(exr.image.width, 2 * 3 * 361);
  ASSERT_EQ(exr.image.height, 2 * 2 * 181);
  const int width = 3 * 361, height = 2 * 181;
  for (int m = 0; m < 5; ++m) {
    const Lut& lut = five.luts[m];
    const int x0 = (m % 3) * 361, y0 = (m / 3) * 181;  // column m mod Cm, row m div Cm
    for (int k = 0; k < 4; ++k) {
      const int ex = (k % 2) * width, ey = (k / 2) * height;  // slice grid k in the EXR
      for (int j = 0; j < 181; ++j)
        for (int i = 0; i < 361; ++i) {
          const float* t = lut.Texel(k, j, i);
          const std::size_t at = (static_cast<std::size_t>(k) * height + y0 + j) * width + x0 + i;
          ASSERT_EQ(ktx2.volume.words[at], EncodeRgb9e5(t[0], t[1], t[2]))
              << "material " << m << " texel " << i << "," << j << "," << k;
          const float* e = exr.image.Pixel(ex + x0 + i, ey + y0 + j);
          for (int c = 0; c < 3; ++c) {
            if (std::isnan(t[c])) {
              ASSERT_TRUE(std::isnan(e[c]));
            } else {
              ASSERT_EQ(e[c], t[c]) << "material " << m << " EXR " << i << "," << j << "," << k;
            }
          }
        }
    }
    // The library's own cell extraction agrees with the layout above.
    const Lut cell = ExtractAtlasCell(ktx2.volume, ComputeAtlasLayout(5, 4), m, lut.theta_in_deg);
    EXPECT_EQ(cell.texels, UnpackLut(PackLut(lut), lut.theta_in_deg).texels) << m;
  }
}

// --compress bc6h for an atlas: the KTX2 and DDS hold the same blocks, the manifest describes
// them and every material's certified error is the error of its own cell (recomputed here with
// MeasureCompressionError on the cell cut out of the decoded texture).
TEST(Atlas, Bc6hAtlasRecordsEachCellsError) {
  const Five five;
  const std::string dir = test::TestDir("atlas_bc6h");
  WriteAtlas(dir + "/five", five.materials, {}, LutCompression::kBc6h, 2);
  const LoadedTexture ktx2 = ReadKtx2(dir + "/five.ktx2");
  const LoadedTexture dds = ReadTextureFile(dir + "/five.dds");
  ASSERT_EQ(ktx2.format, TexelFormat::kBc6hUfloat);
  ASSERT_EQ(dds.format, TexelFormat::kBc6hUfloat);
  EXPECT_EQ(ktx2.bc6h.bytes, dds.bc6h.bytes);
  EXPECT_EQ(ktx2.bc6h.ByteSize(), std::size_t{(3 * 361 + 3) / 4} * ((2 * 181 + 3) / 4) * 4 * 16);
  const AtlasManifest m = ParseAtlasManifest(ktx2.atlas_manifest_json);
  EXPECT_EQ(m.payload_format, "bc6h_ufloat");
  const std::vector<float> decoded = DecodeBc6hVolume(ktx2.bc6h);
  const int width = 3 * 361, height = 2 * 181;
  for (int n = 0; n < 5; ++n) {
    ASSERT_TRUE(m.materials[n].certified_error) << n;
    const int x0 = (n % 3) * 361, y0 = (n / 3) * 181;
    std::vector<float> cell;
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 181; ++j)
        for (int i = 0; i < 361 * 3; ++i)
          cell.push_back(
              decoded[((static_cast<std::size_t>(k) * height + y0 + j) * width + x0) * 3 + i]);
    const CertifiedError want = MeasureCompressionError(five.luts[n], cell, 90.0);
    const CertifiedError& got = *m.materials[n].certified_error;
    EXPECT_EQ(got.measured.texels + got.filled.texels, 361u * 181u * 4u);
    EXPECT_FLOAT_EQ(got.measured.max, want.measured.max) << n;
    EXPECT_FLOAT_EQ(got.measured.p99, want.measured.p99) << n;
    EXPECT_FLOAT_EQ(got.measured.median, want.measured.median) << n;
  }
}

// --max-error for an atlas: one texel format for the whole texture. Three materials in 2 × 2
// cells (one unused). A bound BC6H meets on every cell keeps BC6H; a bound below BC6H's error
// falls back to RGB9E5, and each cell's recorded error is then that of its RGB9E5 words, the same
// as the material's LUT packed on its own (PackLut), whatever the unused cell holds.
TEST(Atlas, MaxErrorPicksBc6hOnlyWhenEveryCellMeetsIt) {
  const Five five;
  const std::vector<AtlasMaterial> three(five.materials.begin(), five.materials.begin() + 3);
  Atlas bc6h = BuildAtlas(three);
  CompressAtlasBc6h(bc6h, three, 2);
  double worst = 0;
  for (const CertifiedError& e : bc6h.certified_error) worst = std::max(worst, e.measured.max);
  ASSERT_GT(worst, 1e-4);  // BC6H is lossy on these LUTs

  Atlas loose = BuildAtlas(three);
  EXPECT_EQ(ChooseAtlasCompression(loose, three, std::min(0.99, 2 * worst), 2),
            LutCompression::kBc6h);
  ASSERT_TRUE(loose.bc6h);
  ASSERT_EQ(loose.certified_error.size(), 3u);
  for (const CertifiedError& e : loose.certified_error) {
    EXPECT_EQ(e.format, "bc6h_ufloat");
    EXPECT_TRUE(e.max_error_met);
  }

  Atlas tight = BuildAtlas(three);
  EXPECT_EQ(ChooseAtlasCompression(tight, three, worst / 2, 2), LutCompression::kNone);
  EXPECT_FALSE(tight.bc6h);
  ASSERT_EQ(tight.certified_error.size(), 3u);
  for (int m = 0; m < 3; ++m) {
    const Lut& lut = five.luts[m];
    const CertifiedError want =
        MeasureCompressionError(lut, UnpackLut(PackLut(lut), lut.theta_in_deg).texels, 90.0);
    const CertifiedError& got = tight.certified_error[m];
    EXPECT_EQ(got.format, "rgb9e5");
    EXPECT_EQ(got.measured.max, want.measured.max) << m;
    EXPECT_EQ(got.filled.p99, want.filled.p99) << m;
    EXPECT_EQ(got.max_error_bound, worst / 2);
    EXPECT_EQ(got.max_error_met, want.measured.max <= worst / 2) << m;
  }
  // The manifest records the RGB9E5 figures for every material.
  const AtlasManifest parsed = ParseAtlasManifest(AtlasManifestJson(tight, {}));
  EXPECT_EQ(parsed.payload_format, "rgb9e5");
  for (const AtlasManifestEntry& e : parsed.materials) {
    ASSERT_TRUE(e.certified_error) << e.name;
    EXPECT_EQ(e.certified_error->format, "rgb9e5");
    EXPECT_EQ(e.certified_error->max_error_bound, worst / 2);
  }
  Atlas bad = BuildAtlas(three);
  EXPECT_THROW(ChooseAtlasCompression(bad, three, 0.0), InvalidArgument);
  EXPECT_THROW(ChooseAtlasCompression(bad, three, 1.0), InvalidArgument);
}

TEST(Atlas, UnusedCellsAreZero) {
  const Five five;
  const Atlas atlas = BuildAtlas(five.materials);
  // Cell 5 (column 2, row 1) is empty in a 3 × 2 grid of five materials.
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 181; ++j)
      for (int i = 0; i < 361; ++i)
        ASSERT_EQ(atlas.volume.words[atlas.volume.Index(2 * 361 + i, 181 + j, k)], 0u);
}

TEST(Atlas, ManifestNamesEveryMaterialItsCellAndTheConventions) {
  const Five five;
  const std::string dir = test::TestDir("atlas_manifest");
  WriteAtlas(dir + "/five", five.materials);
  const auto j = nlohmann::json::parse(ReadFileText(dir + "/five.json", 1 << 20));
  EXPECT_EQ(j["kind"], "brdf-atlas-manifest");
  EXPECT_EQ(j["theta_in_deg"], nlohmann::json::array({0, 20, 40, 60}));
  ASSERT_EQ(j["materials"].size(), 5u);
  for (int m = 0; m < 5; ++m) {
    const auto& e = j["materials"][m];
    EXPECT_EQ(e["name"], five.materials[m].name);
    EXPECT_EQ(e["source"], five.materials[m].source);
    EXPECT_EQ(e["cell"]["column"], m % 3);
    EXPECT_EQ(e["cell"]["row"], m / 3);
    EXPECT_EQ(e["cell"]["x0"], (m % 3) * 361);
    EXPECT_EQ(e["cell"]["y0"], (m / 3) * 181);
  }
  EXPECT_EQ(j["grid"]["cell_columns"], 3);
  EXPECT_EQ(j["grid"]["cell_rows"], 2);
  EXPECT_EQ(j["grid"]["texture_width"], 1083);
  EXPECT_EQ(j["grid"]["texture_height"], 362);
  EXPECT_EQ(j["grid"]["texture_depth"], 4);
  EXPECT_FALSE(j["texel_convention"]["centre_exact"].get<std::string>().empty());
  EXPECT_FALSE(j["texel_convention"]["published"].get<std::string>().empty());
  EXPECT_FALSE(j["texel_convention"]["atlas_cell"].get<std::string>().empty());
  EXPECT_EQ(j["payload"]["bytes"], 1083u * 362u * 4u * 4u);
  const AtlasManifest parsed = ParseAtlasManifest(j.dump(), "five.json");
  EXPECT_EQ(parsed.materials[4].name, "pattern42");
  EXPECT_EQ(parsed.materials[4].x0, 361);
  EXPECT_EQ(parsed.layout.cells.columns, 3);
}

// The extrapolation a material's cell was filled with and its fitted models (--extrapolate
// auto's record) are written per material and read back; materials without them have none.
TEST(Atlas, ManifestRecordsEachMaterialsExtrapolationAndFits) {
  Five five;
  five.materials[1].extrapolation = ExtrapolationInfo{0.25, 0.8, 75};
  five.materials[1].fitted_models_json = {R"({"kind":"extrapolation-auto","p":0.25,"l":0.8})"};
  const AtlasManifest parsed =
      ParseAtlasManifest(AtlasManifestJson(BuildAtlas(five.materials), {}));
  ASSERT_TRUE(parsed.materials[1].extrapolation.has_value());
  EXPECT_EQ(parsed.materials[1].extrapolation->p, 0.25);
  EXPECT_EQ(parsed.materials[1].extrapolation->l, 0.8);
  EXPECT_EQ(parsed.materials[1].extrapolation->theta_b_deg, 75);
  ASSERT_EQ(parsed.materials[1].fitted_models_json.size(), 1u);
  EXPECT_EQ(nlohmann::json::parse(parsed.materials[1].fitted_models_json[0])["l"], 0.8);
  EXPECT_FALSE(parsed.materials[0].extrapolation.has_value());
  EXPECT_TRUE(parsed.materials[0].fitted_models_json.empty());
}

TEST(Atlas, RefusesMaterialsWithDifferentThetaSetsNamingThem) {
  const Lut a = test::AnalyticLut(test::Lambert(0.5), {0, 20, 40, 60});
  const Lut b = test::AnalyticLut(test::Lambert(0.5), {0, 30, 60});
  const std::string dir = test::TestDir("atlas_theta");
  try {
    WriteAtlas(dir + "/mixed", {{"paper", &a, ""}, {"velvet", &b, ""}});
    FAIL() << "accepted";
  } catch (const InvalidArgument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'paper'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'velvet'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("0, 30, 60"), std::string::npos) << msg;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));  // nothing written
}

TEST(Atlas, RefusesDuplicateNamesAndEmptyLists) {
  const Lut a = test::PatternLut({0, 20}, 1);
  EXPECT_THROW(BuildAtlas({{"x", &a, ""}, {"x", &a, ""}}), InvalidArgument);
  EXPECT_THROW(BuildAtlas({}), InvalidArgument);
}

TEST(Atlas, SingleMaterialAtlasIsThatLut) {
  const Lut a = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  const Atlas atlas = BuildAtlas({{"only", &a, ""}});
  EXPECT_EQ(atlas.volume.words, PackLut(a).words);
}

}  // namespace
}  // namespace brdf::exporter
