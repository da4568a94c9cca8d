#include "brdf/core/importers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/csv.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/lighttools.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

std::string Zemax() {
  return brdf::test::DataPath("zemax-imaging-sphere/test_13_planesymmetric_btdf_zemax.bsdf");
}
std::string Gonio() { return brdf::test::DataPath("goniometer-csv/test_brdf_viewer_2D_data.csv"); }

fs::path TempDir() { return brdf::test::NewTempDir("importers"); }

TEST(ImportFormat, NamesRoundTrip) {
  for (ImportFormat f :
       {ImportFormat::kAuto, ImportFormat::kRgl, ImportFormat::kZemax, ImportFormat::kLightTools,
        ImportFormat::kMerl, ImportFormat::kCsv, ImportFormat::kGonio}) {
    EXPECT_EQ(ImportFormatFromName(ImportFormatName(f)), f);
  }
  EXPECT_EQ(ImportFormatName(ImportFormat::kLightTools), "lighttools");
  EXPECT_THROW(ImportFormatFromName("ies"), InvalidArgument);
}

TEST(DetectImportFormat, RecognisesEachFormatByContent) {
  const fs::path dir = TempDir();
  EXPECT_EQ(DetectImportFormat(Zemax()), ImportFormat::kZemax);
  EXPECT_EQ(DetectImportFormat(Gonio()), ImportFormat::kGonio);
  EXPECT_EQ(DetectImportFormat(brdf::test::DataPath("rgl/paper_white_rgb.bsdf")),
            ImportFormat::kRgl);

  LightToolsBsdf lt;
  lt.scatter_azimuth_deg = {0};
  lt.scatter_radial_deg = {0};
  LightToolsBlock b;
  b.values = {0.3};
  lt.blocks.push_back(b);
  const std::string lt_path = (dir / "a.bsdf").string();
  WriteLightToolsBsdf(lt_path, lt);
  EXPECT_EQ(DetectImportFormat(lt_path), ImportFormat::kLightTools);

  // A CSV point cloud under a misleading extension is still recognised by its header.
  const std::string csv_path = (dir / "points.txt").string();
  WriteFileAtomically(csv_path, "# c\ntheta_in,phi_in,theta_out,phi_out,r,g,b\n0,0,0,0,1,1,1\n");
  EXPECT_EQ(DetectImportFormat(csv_path), ImportFormat::kCsv);

  const std::string merl_path = (dir / "gold.binary").string();
  WriteFileAtomically(merl_path, "not really");
  EXPECT_EQ(DetectImportFormat(merl_path), ImportFormat::kMerl);

  const std::string other = (dir / "notes.txt").string();
  WriteFileAtomically(other, "hello\n");
  try {
    DetectImportFormat(other);
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(other), std::string::npos);
  }
  EXPECT_THROW(DetectImportFormat((dir / "missing.csv").string()), IoError);
}

TEST(ImportFile, ReadsEachPointCloudFormat) {
  const Measurement gonio = ImportFile(Gonio());
  EXPECT_EQ(gonio.slices.size(), 5u);
  EXPECT_EQ(gonio.metadata.extra.at("source_format"), "gonio");
  const Measurement zemax = ImportFile(Zemax(), ImportFormat::kAuto, ImportOptions{true});
  EXPECT_EQ(zemax.slices.size(), 13u);
  EXPECT_THROW(ImportFile(Zemax()), FormatError);  // BTDF without allow_btdf
}

TEST(ImportFile, EvaluableFormatsPointToVirtualCapture) {
  try {
    ImportFile(brdf::test::DataPath("rgl/paper_white_rgb.bsdf"));
    FAIL();
  } catch (const InvalidArgument& e) {
    // What to do is a structured remedy the tool words; the library names no command line.
    EXPECT_EQ(e.remedy().kind, RemedyKind::kCaptureEvaluable);
    EXPECT_NE(std::string(e.what()).find("evaluable"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
  }
}

// Every hand-made broken file must fail with a FormatError naming the file and a line.
TEST(ImportFile, BrokenFilesFailWithFileAndLine) {
  const fs::path root = fs::path(BRDF_SOURCE_DIR) / "tests/data/broken";
  const std::pair<const char*, ImportFormat> formats[] = {{"zemax", ImportFormat::kZemax},
                                                          {"lighttools", ImportFormat::kLightTools},
                                                          {"csv", ImportFormat::kCsv},
                                                          {"gonio", ImportFormat::kGonio}};
  for (const auto& [folder, format] : formats) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(root / folder)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    EXPECT_GE(files.size(), 6u) << folder;
    for (const fs::path& p : files) {
      try {
        ImportFile(p.string(), format);
        ADD_FAILURE() << p << " was accepted";
      } catch (const FormatError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.file(), p.string());
        EXPECT_EQ(what.rfind(p.string() + ": line ", 0), 0u) << what;
        EXPECT_FALSE(e.expected().empty()) << what;
        std::printf("%-40s %s\n", p.filename().c_str(), what.substr(p.string().size()).c_str());
      } catch (const std::exception& e) {
        ADD_FAILURE() << p << " threw something other than FormatError: " << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace brdf
