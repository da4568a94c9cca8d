#include "brdf/exporter/sidecar.h"

#include <gtest/gtest.h>

#include <functional>

#include <regex>

#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/ktx2.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

TextureMetadata FullMeta() {
  TextureMetadata m;
  m.name = "felt";
  m.source = "captures/felt.bpc";
  m.extrapolation = ExtrapolationInfo{0.2, 0.3, 75.0};
  m.fitted_models_json = {R"({"model": "lambert", "rho": [0.5, 0.4, 0.3]})"};
  m.companion_files = {"felt.ktx2", "felt.dds", "felt.exr", "felt.png"};
  return m;
}

TEST(Sidecar, BitwiseReferenceCrcHasTheStandardCheckValue) {
  // The CRC-32 check value of "123456789" is 0xCBF43926 (IEEE 802.3 / zlib).
  const std::string s = "123456789";
  EXPECT_EQ(test::BitwiseCrc32(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()),
            0xCBF43926u);
}

TEST(Sidecar, HoldsEveryFieldDesignSection7Names) {
  const Lut lut = test::AnalyticLut(test::Lambert(0.5), {0, 20, 40, 60});
  const auto j = nlohmann::json::parse(SidecarJson(PackLut(lut), lut.theta_in_deg, FullMeta()));
  EXPECT_EQ(j["source"], "captures/felt.bpc");
  EXPECT_EQ(j["theta_in_deg"], nlohmann::json::array({0, 20, 40, 60}));
  EXPECT_EQ(j["grid"]["width"], 361);
  EXPECT_EQ(j["grid"]["height"], 181);
  EXPECT_EQ(j["grid"]["slices"], 4);
  EXPECT_EQ(j["grid"]["delta_in_deg"], 20.0);
  const std::string centre = j["texel_convention"]["centre_exact"];
  const std::string published = j["texel_convention"]["published"];
  EXPECT_NE(centre.find("u = (phi_d/1deg + 0.5)/361"), std::string::npos) << centre;
  EXPECT_NE(centre.find("v = (theta_d/1deg + 0.5)/181"), std::string::npos) << centre;
  EXPECT_NE(published.find("u = phi_d/(2 pi)"), std::string::npos) << published;
  EXPECT_NE(published.find("v = theta_d/pi"), std::string::npos) << published;
  const std::string glsl = j["texel_convention"]["glsl"];
  // The generated lookup (compiled by glslangValidator in tests/engines/shader_compile_test).
  EXPECT_NE(glsl.find("MEASURED_BRDF_DELTA_IN_DEG = 20.0;"), std::string::npos) << glsl;
  EXPECT_NE(glsl.find("MEASURED_BRDF_SLICES = 4.0;"), std::string::npos) << glsl;
  EXPECT_NE(glsl.find("MEASURED_BRDF_TEXELS_U = 361.0;"), std::string::npos) << glsl;
  EXPECT_NE(glsl.find("precision highp sampler3D;"), std::string::npos) << glsl;
  EXPECT_NE(glsl.find("phi_d/360, theta_d/180"), std::string::npos)
      << glsl;  // the published form is quoted
  EXPECT_EQ(j["extrapolation"]["p"], 0.2);
  EXPECT_EQ(j["extrapolation"]["l"], 0.3);
  EXPECT_EQ(j["extrapolation"]["theta_b_deg"], 75.0);
  EXPECT_EQ(j["fitted_models"][0]["model"], "lambert");
  EXPECT_TRUE(
      std::regex_match(j["tool"]["version"].get<std::string>(), std::regex(R"(\d+\.\d+\.\d+)")));
  EXPECT_EQ(j["payload"]["bytes"], 361u * 181u * 4u * 4u);
  EXPECT_EQ(j["payload"]["checksum"]["algorithm"], "crc32");
  EXPECT_EQ(j["files"].size(), 4u);
}

TEST(Sidecar, ChecksumIsTheCrc32OfTheKtx2LevelImage) {
  const std::string dir = test::TestDir("sidecar_crc");
  const Lut lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  WriteKtx2(dir + "/g.ktx2", lut, FullMeta());
  WriteSidecar(dir + "/g.json", PackLut(lut), lut.theta_in_deg, FullMeta());
  const auto ktx2 = test::ReadAll(dir + "/g.ktx2");
  const std::uint64_t offset = test::Le64(ktx2, 80), length = test::Le64(ktx2, 88);
  const std::uint32_t crc = test::BitwiseCrc32(ktx2.data() + offset, length);
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%08x", crc);
  const auto j = nlohmann::json::parse(ReadFileText(dir + "/g.json", 1 << 20));
  EXPECT_EQ(j["payload"]["checksum"]["value"], hex);
  EXPECT_EQ(j["payload"]["bytes"], length);
  EXPECT_EQ(ReadSidecar(dir + "/g.json").payload_crc32, crc);
}

TEST(Sidecar, ParsesBackWhatItWrote) {
  const Lut lut = test::PatternLut({0, 20, 40}, 4);
  const PackedVolume packed = PackLut(lut);
  const SidecarInfo info = ParseSidecarJson(SidecarJson(packed, lut.theta_in_deg, FullMeta()));
  EXPECT_EQ(info.name, "felt");
  EXPECT_EQ(info.source, "captures/felt.bpc");
  EXPECT_EQ(info.theta_in_deg, lut.theta_in_deg);
  EXPECT_EQ(info.width, 361);
  EXPECT_EQ(info.height, 181);
  EXPECT_EQ(info.slices, 3);
  EXPECT_EQ(info.payload_bytes, packed.ByteSize());
  ASSERT_TRUE(info.extrapolation.has_value());
  EXPECT_EQ(info.extrapolation->l, 0.3);
  ASSERT_EQ(info.fitted_models_json.size(), 1u);
  EXPECT_EQ(nlohmann::json::parse(info.fitted_models_json[0])["rho"][2], 0.3);
  EXPECT_EQ(info.files.front(), "felt.ktx2");
}

TEST(Sidecar, WithoutExtrapolationRecordsNull) {
  const Lut lut = test::PatternLut({0}, 4);
  TextureMetadata m;
  m.name = "plain";
  const auto j = nlohmann::json::parse(SidecarJson(PackLut(lut), lut.theta_in_deg, m));
  EXPECT_TRUE(j["extrapolation"].is_null());
  EXPECT_FALSE(ParseSidecarJson(j.dump()).extrapolation.has_value());
}

TEST(Sidecar, ParserNamesTheBadMember) {
  const Lut lut = test::PatternLut({0, 20}, 4);
  auto j = nlohmann::json::parse(SidecarJson(PackLut(lut), lut.theta_in_deg, FullMeta()));
  j.erase("theta_in_deg");
  try {
    ParseSidecarJson(j.dump(), "felt.json");
    FAIL() << "accepted";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("felt.json: member 'theta_in_deg'"), std::string::npos)
        << e.what();
  }
  try {
    ParseSidecarJson("{\"kind\": ", "broken.json");
    FAIL() << "accepted";
  } catch (const FormatError& e) {
    // The text ends after its 9th character: the parser stops at column 10.
    EXPECT_NE(std::string(e.what()).find("broken.json: line 1, column 10"), std::string::npos)
        << e.what();
  }
}

// A sidecar whose θin list is not k·Δin, disagrees with its grid, or whose payload size is not
// 361·181·K·4 bytes is refused with one line naming the member (docs/design.md §5, §7).
TEST(Sidecar, RefusesThetaInListsAndSizesThatDisagreeWithTheTexture) {
  const Lut lut = test::PatternLut({0, 20, 40}, 4);
  const auto good = nlohmann::json::parse(SidecarJson(PackLut(lut), lut.theta_in_deg, FullMeta()));
  struct Case {
    std::function<void(nlohmann::json&)> edit;
    std::string member, got;
  };
  const std::vector<Case> cases = {
      {[](auto& j) {
         j["theta_in_deg"] = {0, 20, 45};
       },
       "member 'theta_in_deg'", "[0, 20, 45]"},
      {[](auto& j) {
         j["theta_in_deg"] = {10, 30, 50};
       },
       "member 'theta_in_deg'", "[10, 30, 50]"},
      {[](auto& j) {
         j["theta_in_deg"] = {0, 20};
       },
       "member 'grid.slices'", "got 3"},
      {[](auto& j) { j["grid"]["delta_in_deg"] = 30; }, "member 'theta_in_deg'", "[0, 20, 40]"},
      {[](auto& j) { j["payload"]["bytes"] = 1045456; }, "member 'payload.bytes'", "got 1045456"},
      {[](auto& j) { j["grid"]["width"] = 360; }, "member 'payload.bytes'", "360 * 181 * 3 * 4"},
  };
  for (const Case& c : cases) {
    auto j = good;
    c.edit(j);
    try {
      ParseSidecarJson(j.dump(), "felt.json");
      ADD_FAILURE() << "accepted " << j.dump();
    } catch (const FormatError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("felt.json: " + c.member, 0), 0u) << what;
      EXPECT_NE(what.find(c.got), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(Sidecar, RefusesAFittedModelThatIsNotJson) {
  const Lut lut = test::PatternLut({0}, 4);
  TextureMetadata m;
  m.fitted_models_json = {"{model: lambert"};
  EXPECT_THROW(SidecarJson(PackLut(lut), lut.theta_in_deg, m), InvalidArgument);
}

}  // namespace
}  // namespace brdf::exporter
