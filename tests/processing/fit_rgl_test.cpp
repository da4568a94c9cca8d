// Real data: every RGL-EPFL material in $BRDF_DATA_DIR/rgl (default <repo>/../shared/brdf-data)
// is captured virtually at the reference geometry and fitted by GGX and by Lambert alone.
// Every fit converges with a report; on the glossy materials GGX beats Lambert by a clear
// margin; the colour-shifting finishes are flagged.
//
// Ground truth from outside the fitter: "glossy" is decided from each file's own data (the
// mirror-direction value at θin = 20° against the slice's median value); "colour-shifting" from
// the database's own material names: cc_ (colour-changing paints) and irid_ (iridescent flake
// paints) are such finishes, paper_white, colodur_napoli_4f (a matte colour) and
// cm_military_green (a matte paint) are not.
#include <gtest/gtest.h>

#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/rgl.h"
#include "brdf/fit/fit.h"

namespace brdf::processing {
namespace {

namespace fs = std::filesystem;

std::string DataDir() { return brdf::test::DataDir(); }

// The reference geometry with φout every 4° (27,360 samples instead of 109,440): the RGL
// materials' lobes are all several degrees wide, and the virtual capture dominates the cost.
Measurement VirtualCapture(const BrdfSource& source, const std::string& name) {
  Measurement m;
  m.metadata.sample_name = name;
  for (double ti : {0.0, 20.0, 40.0, 60.0}) {
    Slice s;
    s.theta_in_deg = ti;
    const Vec3 wi = SphericalDirectionDeg(ti, 0);
    for (int to = 0; to <= 75; ++to)
      for (int po = 0; po < 360; po += 4) {
        Sample x;
        x.theta_in_deg = static_cast<float>(ti);
        x.theta_out_deg = static_cast<float>(to);
        x.phi_out_deg = static_cast<float>(po);
        const Rgb f = source.Eval(wi, SphericalDirectionDeg(to, po));
        for (int c = 0; c < 3; ++c) x.rgb[c] = static_cast<float>(f[c]);
        s.samples.push_back(x);
      }
    m.slices.push_back(std::move(s));
  }
  return m;
}

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

TEST(FitRgl, EveryMaterialConvergesGgxBeatsLambertOnGlossyOnesAndFilmsAreFlagged) {
  const fs::path dir = fs::path(DataDir()) / "rgl";
  ASSERT_TRUE(fs::is_directory(dir))
      << "no RGL data at " << dir << "; set BRDF_DATA_DIR to the shared brdf-data folder";
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".bsdf") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 18u);
  int glossy = 0;
  for (const fs::path& file : files) {
    const std::string name = file.stem().string();
    const RglBrdf brdf = RglBrdf::Load(file.string());
    const Measurement meas = VirtualCapture(brdf, name);

    FitOptions o;
    o.model = Model::kGgx;
    const FitReport ggx = FitMaterial(meas, o).report;
    o.model = Model::kLambert;
    const FitReport lambert = FitMaterial(meas, o).report;
    for (const FitReport* r : {&ggx, &lambert}) {
      EXPECT_EQ(r->status, FitStatus::kConverged) << name << ": " << r->message;
      EXPECT_TRUE(std::isfinite(r->final_cost) && std::isfinite(r->rmse)) << name;
      EXPECT_EQ(r->slices.size(), 4u) << name;
      EXPECT_EQ(r->samples_used, meas.SampleCount()) << name;
      EXPECT_GT(r->iterations, 0) << name;
    }
    EXPECT_LE(ggx.final_cost, lambert.final_cost * (1 + 1e-9)) << name;

    // Glossy by its own data: the mirror value at θin = 20° over the median of that slice.
    const Rgb mirror = brdf.Eval(SphericalDirectionDeg(20, 0), SphericalDirectionDeg(20, 180));
    std::vector<double> lum;
    for (const Sample& x : meas.slices[1].samples)
      lum.push_back(0.2126 * x.rgb[0] + 0.7152 * x.rgb[1] + 0.0722 * x.rgb[2]);
    std::nth_element(lum.begin(), lum.begin() + static_cast<std::ptrdiff_t>(lum.size() / 2),
                     lum.end());
    const double peak = 0.2126 * mirror[0] + 0.7152 * mirror[1] + 0.0722 * mirror[2];
    if (peak > 5 * lum[lum.size() / 2]) {
      ++glossy;
      EXPECT_LT(ggx.final_cost, 0.5 * lambert.final_cost)
          << name << ": GGX " << ggx.final_cost << " vs Lambert " << lambert.final_cost;
    }
    if (StartsWith(name, "cc_") || StartsWith(name, "irid_")) {
      EXPECT_TRUE(ggx.colour_shift && !ggx.representable && !ggx.warnings.empty())
          << name << ": hue spread " << ggx.hue_spread;
    }
    if (name == "paper_white_rgb" || name == "colodur_napoli_4f_rgb" ||
        name == "cm_military_green_rgb") {
      EXPECT_FALSE(ggx.colour_shift) << name << ": hue spread " << ggx.hue_spread;
    }
    RecordProperty(name, "ggx rmse " + std::to_string(ggx.rmse) + ", lambert rmse " +
                             std::to_string(lambert.rmse) + ", hue spread " +
                             std::to_string(ggx.hue_spread));
  }
  EXPECT_GE(glossy, 5);  // the database is mostly glossy paints and coatings
}

}  // namespace
}  // namespace brdf::processing
