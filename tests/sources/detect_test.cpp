// brdf::sources::DetectFileKind in-process: a file is what its bytes say, whatever its name
// (brdf/sources/detect.h). The expected kinds come from the files' own bytes: the magic numbers
// and JSON members the format documents name (docs/formats/bpc.md, the RGL and MERL layouts).
#include "brdf/sources/detect.h"

#include <gtest/gtest.h>

#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/merl.h"
#include "brdf/core/models.h"
#include "test_support.h"
#include "tools/tool_test_util.h"

namespace brdf::sources {
namespace {

namespace fs = std::filesystem;

using tooltest::CaptureOf;
using tooltest::Lambertian;
using tooltest::ReadAll;
using tooltest::WriteText;

class Detect : public tooltest::ToolTest {};

TEST_F(Detect, ACaptureIsRecognisedByItsMagicUnderAnyName) {
  const fs::path file = dir_ / "measured.dat";
  WriteBpc(file.string(), CaptureOf(Lambertian(), {0}, 30, 15, 90));
  // The magic of docs/formats/bpc.md, read from the file itself.
  ASSERT_EQ(ReadAll(file).substr(0, 8), std::string("\x89"
                                                    "BPC\r\n\x1a\n",
                                                    8));
  EXPECT_EQ(DetectFileKind(file.string()), FileKind::kCapture);
}

TEST_F(Detect, JsonFilesAreToldApartByTheirMembers) {
  WriteText(dir_ / "shiny.txt", tooltest::Ggx03().Json());
  EXPECT_EQ(DetectFileKind((dir_ / "shiny.txt").string()), FileKind::kMaterial);
  WriteText(dir_ / "lut.json", R"({"kind": "brdf-lut-sidecar", "width": 361})");
  EXPECT_EQ(DetectFileKind((dir_ / "lut.json").string()), FileKind::kSidecar);
  WriteText(dir_ / "lib.json", R"({"kind": "brdf-atlas-manifest"})");
  EXPECT_EQ(DetectFileKind((dir_ / "lib.json").string()), FileKind::kAtlasManifest);
  WriteText(dir_ / "gold.extrapolate.json", R"({"p": 0.2, "l": 0.3})");
  EXPECT_EQ(DetectFileKind((dir_ / "gold.extrapolate.json").string()), FileKind::kExtrapolation);
  WriteText(dir_ / "other.json", R"({"colour": "red"})");
  EXPECT_EQ(DetectFileKind((dir_ / "other.json").string()), FileKind::kOtherJson);
  WriteText(dir_ / "broken.json", R"({"model": )");
  EXPECT_THROW(DetectFileKind((dir_ / "broken.json").string()), FormatError);
}

TEST_F(Detect, MeasuredDatabasesAreRecognisedByContent) {
  // An RGL file starts with "tensor_file\0"; copied under a name without an extension.
  const std::string rgl = ReadAll(test::DataPath("rgl/chm_orange_rgb.bsdf"));
  ASSERT_EQ(rgl.substr(0, 12), std::string("tensor_file\0", 12));
  WriteText(dir_ / "orange", rgl);
  EXPECT_EQ(DetectFileKind((dir_ / "orange").string()), FileKind::kRgl);
  // A MERL file: the header 90, 90, 180 and exactly the size that header implies.
  const fs::path merl = dir_ / "grey.bin";
  WriteMerlBinary(merl.string(), AnalyticBrdf(ParseMaterialJson(Lambertian().Json())));
  EXPECT_EQ(fs::file_size(merl), 12u + 8u * 3u * 90u * 90u * 180u);
  EXPECT_EQ(DetectFileKind(merl.string()), FileKind::kMerl);
  // One byte more is not a MERL file any more.
  WriteText(dir_ / "grey_plus_one.bin", ReadAll(merl) + "x");
  EXPECT_NE(DetectFileKind((dir_ / "grey_plus_one.bin").string()), FileKind::kMerl);
}

TEST_F(Detect, ABinaryExtensionWithoutItsMagicClaimsItsKindSoTheReaderNamesTheDamage) {
  WriteText(dir_ / "cut.bpc", "not a capture");
  EXPECT_EQ(DetectFileKind((dir_ / "cut.bpc").string()), FileKind::kCapture);
  WriteText(dir_ / "notes", "hello, world\n");
  EXPECT_EQ(DetectFileKind((dir_ / "notes").string()), FileKind::kUnknown);
}

TEST_F(Detect, OnlyRegularFilesAreClassified) {
  fs::create_directories(dir_ / "folder.bpc");
  try {
    DetectFileKind((dir_ / "folder.bpc").string());
    ADD_FAILURE() << "a folder was classified";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("folder"), std::string::npos) << e.what();
  }
  try {
    DetectFileKind((dir_ / "missing.bpc").string());
    ADD_FAILURE() << "a missing file was classified";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "missing.bpc").string() + ": no such file");
  }
}

}  // namespace
}  // namespace brdf::sources
