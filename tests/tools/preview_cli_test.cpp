// `brdf preview` run as a user runs it: outputs, the compare panel and its printed RMS, progress,
// and one-line failures.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <string>
#include <utility>
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

// --ibl engine: the engines' split sum of the source's IBL pack. A white Lambertian reflects
// exactly the furnace's radiance 1 at every view (its albedo is 1); the EXR says what ran; with
// --compare of the same source the second panel is the true image, so a glossy material under
// the studio map shows a difference, and the Lambertian under the furnace almost none.
TEST_F(PreviewCli, IblEngineRendersTheSplitSumAndComparesItWithTheTruth) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const ToolRun furnace =
      Run("preview " + Quote(dir_ / "white.json") + " --ibl engine --env furnace --size 48 --out " +
          Quote(dir_ / "e.exr"));
  ASSERT_EQ(furnace.exit_code, 0) << furnace.err;
  EXPECT_NE(furnace.err.find("split sum"), std::string::npos) << furnace.err;
  const exporter::ExrFile exr = exporter::ReadExr((dir_ / "e.exr").string());
  EXPECT_EQ(exr.Attribute("brdf:estimator"), "engine-split-sum");
  EXPECT_EQ(exr.Attribute("brdf:ibl"), "engine");
  for (int y = 6; y < 42; ++y) {
    for (int x = 6; x < 42; ++x) {
      if (std::hypot(x + 0.5 - 24.0, y + 0.5 - 24.0) < 0.45 * 48 - 1.5) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(exr.image.Pixel(x, y)[c], 1.0, 5e-3);
      }
    }
  }
  const ToolRun gold =
      Run("preview " + Quote(kMaterials + "gold.json") + " --ibl engine" + " --compare " +
          Quote(kMaterials + "gold.json") + " --size 32 --quiet --out " + Quote(dir_ / "g.exr"));
  ASSERT_EQ(gold.exit_code, 0) << gold.err;
  EXPECT_EQ(gold.out.find("RMS difference: 0 "), std::string::npos) << gold.out;
  EXPECT_NE(gold.out.find("RMS difference: "), std::string::npos) << gold.out;
  const ToolRun bad = Run("preview " + Quote(kMaterials + "gold.json") + " --ibl probe --out " +
                          Quote(dir_ / "b.exr"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--ibl"), std::string::npos) << bad.err;
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
  // The printed figures recomputed here from the two panels the EXR holds (source at x 0…31,
  // compare at x 36…67, docs/preview.md): over the pixels whose centres fall inside the sphere
  // (the unit sphere framed at 90 % of the height), √(Σ (a − b)² / 3N), that over the mean of b,
  // and the largest |a − b|.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      other.out, m,
      std::regex(R"(RMS difference: ([0-9.e+-]+) \(([0-9.]+) % of the mean of .*\) over (\d+) )"
                 R"(pixels; largest ([0-9.e+-]+))")))
      << other.out;
  const exporter::ExrFile exr = exporter::ReadExr((dir_ / "other.exr").string());
  ASSERT_EQ(exr.image.width, 3 * 32 + 8);
  double squares = 0, sum_b = 0, largest = 0;
  std::size_t pixels = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const double s = ((x + 0.5) / 32 * 2.0 - 1.0) / 0.9, t = (1.0 - (y + 0.5) / 32 * 2.0) / 0.9;
      if (s * s + t * t >= 1.0) continue;
      ++pixels;
      for (int c = 0; c < 3; ++c) {
        const double a = exr.image.Pixel(x, y)[c], b = exr.image.Pixel(x + 36, y)[c];
        squares += (a - b) * (a - b);
        sum_b += b;
        largest = std::max(largest, std::fabs(a - b));
      }
    }
  const double rms = std::sqrt(squares / (3.0 * pixels)), mean_b = sum_b / (3.0 * pixels);
  EXPECT_EQ(std::stoul(m[3]), pixels);
  EXPECT_NEAR(std::stod(m[1]), rms, 1e-5 * rms) << other.out;
  EXPECT_NEAR(std::stod(m[2]), 100 * rms / mean_b, 0.0006) << other.out;
  EXPECT_NEAR(std::stod(m[4]), largest, 1e-5 * largest) << other.out;
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

// A capture against the material it was simulated from, over every lit pixel of the sphere:
// `brdf capture --device sim` (the reference instrument's detector noise, seed 1) with a geometry
// that covers what a sphere under a map shows (θin every 5° from 0 to 85°, θout to 89°), then
// `brdf preview CAPTURE --compare MATERIAL`. The printed RMS difference (over every pixel where
// either render shows the sphere; their number is the sphere's, from the camera's framing) is
// under 2 % for a rough dielectric and for polished gold. With the instrument's own geometry
// (θin 0/20/40/60°, θout ≤ 75°) only the pixels seen within 60° are covered; that scope is
// tested in tests/processing/preview_test.cpp (PreviewCapture) and explained in docs/preview.md.
TEST_F(PreviewCli, ASimulatedCaptureOfTheWholeSphereGeometryPreviewsWithin2PercentOfItsMaterial) {
  std::ofstream(dir_ / "rough.json")
      << R"({"name": "rough", "model": "ggx", "kd": [0.35, 0.2, 0.1], "f0": 0.04, "alpha": 0.35})";
  const int size = 64;
  std::size_t sphere = 0;  // pixel centres inside the unit sphere framed at 90 % of the height
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double s = ((x + 0.5) / size * 2.0 - 1.0) / 0.9,
                   t = (1.0 - (y + 0.5) / size * 2.0) / 0.9;
      if (s * s + t * t < 1.0) ++sphere;
    }
  for (const auto& [material, file] : std::vector<std::pair<std::string, std::string>>{
           {(dir_ / "rough.json").string(), (dir_ / "rough.json").string()},
           {"gold", kMaterials + "gold.json"}}) {
    const std::string capture =
        (dir_ / (std::filesystem::path(file).stem().string() + ".bpc")).string();
    const ToolRun c = Run("capture --device sim --material " + Quote(material) +
                          " --sample whole-sphere --theta-in "
                          "0,5,10,15,20,25,30,35,40,45,50,55,60,65,70,75,80,85 "
                          "--theta-out-max 89 --sim-pace-ms 0 --quiet --out " +
                          Quote(capture));
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const ToolRun p = Run("preview " + Quote(capture) + " --compare " + Quote(file) + " --size " +
                          std::to_string(size) + " --quiet --out " +
                          Quote(dir_ / (std::filesystem::path(file).stem().string() + ".exr")));
    ASSERT_EQ(p.exit_code, 0) << p.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        p.out, m, std::regex(R"(\(([0-9.]+) % of the mean of .*\) over (\d+) pixels)")))
        << p.out;
    EXPECT_LT(std::stod(m[1]), 2.0) << material << ": " << p.out;
    EXPECT_EQ(std::stoul(m[2]), sphere) << material << ": every lit pixel of the sphere";
  }
}

// The plane lies at z = 0, edge-on to the sphere's default camera (θ = 90°); without --view it is
// seen from θ = 60°, φ = 0. Orthographically, a point (x, y, 0) then appears at image right = y
// and image up = −x·cos60° (camera right (0, 1, 0), up (−cos60°, 0, sin60°)), the frame height
// spanning 2/0.9: the pixels whose centres fall inside |y| ≤ 1/√2, |x| ≤ 1/√2 show it, and under
// the furnace a white Lambertian shows 1 there. --view 90,0 still means edge-on: nothing.
TEST_F(PreviewCli, ThePlaneIsSeenFromAboveUnlessAViewIsGiven) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const int size = 40;
  const std::string common =
      " --env furnace --mesh plane --estimator hierarchical --no-background "
      "--size " +
      std::to_string(size) + " --quiet --out ";
  ASSERT_EQ(Run("preview " + Quote(dir_ / "white.json") + common + Quote(dir_ / "p.exr")).exit_code,
            0);
  const exporter::ExrFile exr = exporter::ReadExr((dir_ / "p.exr").string());
  const double half = 1.0 / 0.9, edge = 1.0 / std::sqrt(2.0), c60 = 0.5;
  int expected = 0, lit = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double right = ((x + 0.5) / size * 2.0 - 1.0) * half;
      const double up = (1.0 - (y + 0.5) / size * 2.0) * half;
      const bool on_plane = std::fabs(right) <= edge && std::fabs(up) <= edge * c60;
      expected += on_plane;
      const float g = exr.image.Pixel(x, y)[1];
      lit += g > 0.5f;
      if (on_plane) {
        EXPECT_NEAR(g, 1.0, 2e-3) << x << "," << y;
      }
    }
  EXPECT_EQ(lit, expected);
  EXPECT_GT(expected, 250);
  ASSERT_EQ(Run("preview " + Quote(dir_ / "white.json") + " --view 90,0" + common +
                Quote(dir_ / "edge.exr"))
                .exit_code,
            0);
  const exporter::ExrFile edge_on = exporter::ReadExr((dir_ / "edge.exr").string());
  for (float v : edge_on.image.rgb) ASSERT_EQ(v, 0.0f);
}

// --light alone: one directional light of irradiance π from (90°, 0), the camera's side. A white
// Lambertian then shows ρ/π · π · cosθ = n·(1, 0, 0) at the pixel whose normal is n (the
// sphere's normal at a pixel from the orthographic framing), and stderr says what ran.
TEST_F(PreviewCli, ADirectionalLightAloneLightsAWhiteLambertianByTheCosine) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const int size = 32;
  const ToolRun r = Run("preview " + Quote(dir_ / "white.json") + " --light 90,0 --size " +
                        std::to_string(size) + " --out " + Quote(dir_ / "l.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("the directional light only"), std::string::npos) << r.err;
  const exporter::ExrFile exr = exporter::ReadExr((dir_ / "l.exr").string());
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double s = ((x + 0.5) / size * 2.0 - 1.0) / 0.9,
                   t = (1.0 - (y + 0.5) / size * 2.0) / 0.9;
      const double cos_theta = s * s + t * t < 1.0 ? std::sqrt(1.0 - s * s - t * t) : 0.0;
      EXPECT_NEAR(exr.image.Pixel(x, y)[1], cos_theta, 1e-5) << x << "," << y;
    }
}

// A capture whose θin range stops short of grazing says so when previewed on the sphere: the
// instrument's default list (0, 20, 40, 60°) ends at 60°; a list up to 85° and a material (no
// measured range) get no note, and --quiet prints nothing.
TEST_F(PreviewCli, ACaptureThatStopsShortOfGrazingSaysSoOnTheSphere) {
  const std::string coarse = " --theta-out-step 5 --phi-out-step 10 --sim-pace-ms 0 --quiet";
  ASSERT_EQ(Run("capture --device sim --material gold --sample n" + coarse + " --out " +
                Quote(dir_ / "four.bpc"))
                .exit_code,
            0);
  ASSERT_EQ(Run("capture --device sim --material gold --sample n --theta-in 0,30,60,85" + coarse +
                " --out " + Quote(dir_ / "grazing.bpc"))
                .exit_code,
            0);
  const std::string render = " --size 16 --force --out " + Quote(dir_ / "n.png");
  const ToolRun four = Run("preview " + Quote(dir_ / "four.bpc") + render);
  ASSERT_EQ(four.exit_code, 0) << four.err;
  EXPECT_NE(four.err.find((dir_ / "four.bpc").string() + ": note: θin measured up to 60°"),
            std::string::npos)
      << four.err;
  const ToolRun grazing = Run("preview " + Quote(dir_ / "grazing.bpc") + " --compare " +
                              Quote(kMaterials + "gold.json") + render);
  ASSERT_EQ(grazing.exit_code, 0) << grazing.err;
  EXPECT_EQ(grazing.err.find("note:"), std::string::npos) << grazing.err;
  const ToolRun quiet = Run("preview " + Quote(dir_ / "four.bpc") + " --quiet" + render);
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
}

}  // namespace
}  // namespace brdf::tooltest
