#include "brdf/exporter/lut_export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "brdf/core/error.h"
#include "brdf/exporter/sidecar.h"
#include "brdf/exporter/texture_file.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

std::vector<std::string> Listing(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(ExportLut, WritesEveryFormatUnderItsFinalNameOnly) {
  const std::string dir = test::TestDir("export_all");
  const Lut lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  TextureMetadata meta;
  meta.name = "ggx";
  meta.source = "analytic";
  const LutExportResult r = ExportLut(dir, lut, meta);
  EXPECT_EQ(r.written.size(), 5u);
  EXPECT_EQ(Listing(dir),
            (std::vector<std::string>{"ggx.dds", "ggx.exr", "ggx.json", "ggx.ktx2", "ggx.png"}));
  EXPECT_EQ(r.payload_bytes, 361u * 181u * 4u * 4u);
  const SidecarInfo info = ReadSidecar(dir + "/ggx.json");
  EXPECT_EQ(info.files, (std::vector<std::string>{"ggx.ktx2", "ggx.dds", "ggx.exr", "ggx.png"}));
  EXPECT_EQ(info.payload_crc32, r.payload_crc32);
  // Both containers hold the same payload, and it is the one the sidecar describes.
  const LoadedTexture ktx2 = ReadTextureFile(dir + "/ggx.ktx2");
  const LoadedTexture dds = ReadTextureFile(dir + "/ggx.dds");
  EXPECT_EQ(ktx2.volume.words, dds.volume.words);
  EXPECT_TRUE(dds.theta_in_from_metadata);
  const std::vector<std::uint8_t> dds_bytes = test::ReadAll(dir + "/ggx.dds");
  EXPECT_EQ(test::BitwiseCrc32(dds_bytes.data() + 148, dds_bytes.size() - 148), info.payload_crc32);
}

TEST(ExportLut, WritesOnlyTheSelectedFormats) {
  const std::string dir = test::TestDir("export_some");
  const Lut lut = test::PatternLut({0, 20}, 9);
  TextureMetadata meta;
  meta.name = "p";
  ExportLut(dir, lut, meta, {ParseExportFormats("dds,json"), {ExrPixelType::kHalf}});
  EXPECT_EQ(Listing(dir), (std::vector<std::string>{"p.dds", "p.json"}));
  EXPECT_EQ(ReadSidecar(dir + "/p.json").files, std::vector<std::string>{"p.dds"});
}

// The list a caller's overwrite check covers is exactly what ExportLut writes, in its order.
TEST(ExportLut, ListsTheFilesItWillWriteBeforeWritingThem) {
  const Lut lut = test::PatternLut({0, 20}, 9);
  for (const char* formats : {"ktx2,dds,exr,png,json", "dds,json", "png", "json,ktx2"}) {
    const std::string dir = test::TestDir(std::string("export_list_") + formats[0] + formats[1]);
    TextureMetadata meta;
    meta.name = "p";
    const LutExportFormats f = ParseExportFormats(formats);
    const std::vector<std::string> planned = LutExportPaths(dir, "p", f);
    EXPECT_TRUE(Listing(dir).empty());
    const LutExportResult r = ExportLut(dir, lut, meta, {f, {}});
    EXPECT_EQ(planned, r.written) << formats;
    std::vector<std::string> names;
    for (const std::string& p : planned) names.push_back(std::filesystem::path(p).filename());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, Listing(dir)) << formats;
  }
}

TEST(ExportLut, ParsesFormatListsAndNamesUnknownOnes) {
  const LutExportFormats f = ParseExportFormats("ktx2,png");
  EXPECT_TRUE(f.ktx2);
  EXPECT_TRUE(f.png);
  EXPECT_FALSE(f.dds || f.exr || f.json);
  try {
    ParseExportFormats("ktx2,tiff");
    FAIL() << "accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("'tiff'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseExportFormats(""), InvalidArgument);
  EXPECT_THROW(ParseExportFormats("ktx2,"), InvalidArgument);
}

TEST(ExportLut, RefusesNamesThatAreNotPlainFileNames) {
  const std::string dir = test::TestDir("export_names");
  const Lut lut = test::PatternLut({0}, 1);
  for (const char* bad : {"", "..", "a/b", "x\\y"}) {
    TextureMetadata meta;
    meta.name = bad;
    EXPECT_THROW(ExportLut(dir, lut, meta), InvalidArgument) << bad;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(ExportLut, FailureInAMissingFolderLeavesNoPartialFile) {
  const std::string dir = test::TestDir("export_missing");
  const Lut lut = test::PatternLut({0, 20}, 2);
  TextureMetadata meta;
  meta.name = "m";
  EXPECT_THROW(ExportLut(dir + "/nope", lut, meta), IoError);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace brdf::exporter
