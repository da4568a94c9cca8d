// `brdf preview` run as a user runs it: outputs, the compare panel and its printed RMS, progress,
// and one-line failures.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "brdf/exporter/exr.h"
#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

const std::string kMaterials = std::string(BRDF_SOURCE_DIR) + "/data-samples/materials/";

// Width and height from a PNG's IHDR chunk (big-endian at bytes 16–23).
std::pair<int, int> PngSize(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[24] = {};
  in.read(reinterpret_cast<char*>(header), 24);
  auto be = [&](int o) {
    return (header[o] << 24) | (header[o + 1] << 16) | (header[o + 2] << 8) | header[o + 3];
  };
  return {be(16), be(20)};
}

class PreviewCli : public ToolTest {};

TEST_F(PreviewCli, WhiteLambertianUnderTheFurnaceIsOneInTheExr) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const ToolRun r = Run("preview " + Quote(dir_ / "white.json") +
                        " --env furnace --size 32 --spp 1024 --out " + Quote(dir_ / "w.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const exporter::ExrFile exr = exporter::ReadExr((dir_ / "w.exr").string());
  ASSERT_EQ(exr.image.width, 32);
  for (int y = 10; y < 22; ++y)
    for (int x = 10; x < 22; ++x) EXPECT_NEAR(exr.image.Pixel(x, y)[1], 1.0, 0.01);
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
}

// Without --spp or --rms the sphere is rendered by the hierarchical quadrature (the EXR says
// which estimator ran); asking for passes selects Monte Carlo.
TEST_F(PreviewCli, TheSphereDefaultsToTheHierarchicalQuadrature) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const ToolRun fast = Run("preview " + Quote(dir_ / "white.json") +
                           " --env furnace --size 48 --out " + Quote(dir_ / "h.exr"));
  ASSERT_EQ(fast.exit_code, 0) << fast.err;
  EXPECT_NE(fast.err.find("hierarchical quadrature"), std::string::npos) << fast.err;
  const exporter::ExrFile exr = exporter::ReadExr((dir_ / "h.exr").string());
  EXPECT_EQ(exr.Attribute("brdf:estimator"), "hierarchical");
  for (int y = 12; y < 36; ++y)
    for (int x = 12; x < 36; ++x) EXPECT_NEAR(exr.image.Pixel(x, y)[1], 1.0, 2e-3);
  const ToolRun mc = Run("preview " + Quote(dir_ / "white.json") +
                         " --env furnace --size 16 --spp 4 --out " + Quote(dir_ / "m.exr"));
  ASSERT_EQ(mc.exit_code, 0) << mc.err;
  EXPECT_EQ(exporter::ReadExr((dir_ / "m.exr").string()).Attribute("brdf:estimator"), "mis");
  const ToolRun plane = Run("preview " + Quote(dir_ / "white.json") +
                            " --env furnace --mesh plane --size 16 --out " + Quote(dir_ / "p.exr"));
  ASSERT_EQ(plane.exit_code, 0) << plane.err;
  EXPECT_EQ(exporter::ReadExr((dir_ / "p.exr").string()).Attribute("brdf:estimator"), "mis");
}

TEST_F(PreviewCli, CompareWritesThreePanelsAndPrintsTheRms) {
  const ToolRun same = Run("preview " + Quote(kMaterials + "gold.json") + " --compare " +
                           Quote(kMaterials + "gold.json") + " --size 32 --spp 4 --quiet --out " +
                           Quote(dir_ / "same.png"));
  ASSERT_EQ(same.exit_code, 0) << same.err;
  EXPECT_NE(same.out.find("RMS difference: 0 (0.000 %"), std::string::npos) << same.out;
  EXPECT_EQ(PngSize(dir_ / "same.png"), std::make_pair(3 * 32 + 8, 32));
  const ToolRun other = Run("preview " + Quote(kMaterials + "gold.json") + " --compare " +
                            Quote(kMaterials + "silver.json") +
                            " --size 32 --spp 4 --quiet --out " + Quote(dir_ / "other.exr"));
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_EQ(other.out.find("RMS difference: 0 "), std::string::npos) << other.out;
  EXPECT_NE(other.out.find("RMS difference: "), std::string::npos) << other.out;
}

TEST_F(PreviewCli, BadArgumentsFailWithOneLine) {
  const ToolRun ext =
      Run("preview " + Quote(kMaterials + "gold.json") + " --out " + Quote(dir_ / "x.tif"));
  EXPECT_EQ(ext.exit_code, 1);
  ASSERT_EQ(ext.ErrLines().size(), 1u) << ext.err;
  EXPECT_NE(ext.err.find(".exr"), std::string::npos) << ext.err;
  const ToolRun missing =
      Run("preview " + Quote(dir_ / "nope.json") + " --out " + Quote(dir_ / "x.png"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos) << missing.err;
  const ToolRun env = Run("preview " + Quote(kMaterials + "gold.json") + " --env moon --out " +
                          Quote(dir_ / "x.png"));
  EXPECT_EQ(env.exit_code, 1);
  ASSERT_EQ(env.ErrLines().size(), 1u) << env.err;
  EXPECT_NE(env.err.find("moon"), std::string::npos) << env.err;
  const ToolRun mesh = Run("preview " + Quote(kMaterials + "gold.json") + " --mesh " +
                           Quote(dir_ / "none.obj") + " --out " + Quote(dir_ / "x.png"));
  EXPECT_EQ(mesh.exit_code, 1);
  EXPECT_NE(mesh.err.find("none.obj"), std::string::npos) << mesh.err;
}

// The hierarchical quadrature (the sphere's default) is one long pass: stderr (a file here, not a
// terminal) gets plain progress lines with the percentage of the sphere's pixels done, the time
// elapsed and an ETA, at least at every further 10 %, percentages never decreasing, the last at
// 100 % with nothing left to wait for. With one thread every block row is reported.
TEST_F(PreviewCli, TheHierarchicalPassShowsProgressWithAnEta) {
  const ToolRun r = Run("preview " + Quote(kMaterials + "gold.json") +
                        " --size 96 --jobs 1 --out " + Quote(dir_ / "g.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::regex line(
      R"(^preview gold: (\d+) % of the pixels, ([0-9.]+)s elapsed, ETA (--|[0-9.]+s)$)");
  std::vector<int> percent;
  std::vector<double> elapsed;
  std::string last_eta;
  for (const std::string& l : r.ErrLines()) {
    std::smatch m;
    if (!std::regex_match(l, m, line)) continue;
    percent.push_back(std::stoi(m[1]));
    elapsed.push_back(std::stod(m[2]));
    last_eta = m[3];
  }
  ASSERT_GE(percent.size(), 4u) << r.err;
  for (std::size_t k = 1; k < percent.size(); ++k) {
    EXPECT_GE(percent[k], percent[k - 1]) << r.err;
    EXPECT_LE(percent[k] - percent[k - 1], 100 * 16 * 2 / 96 + 10) << r.err;  // ≤ 2 block rows
    EXPECT_GE(elapsed[k], elapsed[k - 1]) << r.err;
  }
  EXPECT_LT(percent.front(), 100) << r.err;
  EXPECT_EQ(percent.back(), 100) << r.err;
  EXPECT_EQ(last_eta, "0.0s") << r.err;
  EXPECT_NE(r.err.find("hierarchical quadrature"), std::string::npos) << r.err;
  // --quiet: nothing on stderr.
  const ToolRun quiet = Run("preview " + Quote(kMaterials + "gold.json") +
                            " --size 32 --quiet --out " + Quote(dir_ / "q.exr"));
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
}

}  // namespace
}  // namespace brdf::tooltest
