// brdf::sources::OpenBrdf and OpenForView in-process (brdf/sources/open.h): each kind of file is
// evaluated the way the header promises, and OpenForView serves the BRDF and the LUT of a source
// from one open. Expected values come from outside the code under test: the analytic formulas
// of docs/design.md §9 written out in tests/tools/tool_test_util.h, the RGL reader's own
// evaluation of the same file, the Lambert value ρ/π a synthetic MERL file was written with.
#include "brdf/sources/open.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/merl.h"
#include "brdf/core/models.h"
#include "brdf/core/rgl.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/lut_export.h"
#include "brdf/processing/resample.h"
#include "test_support.h"
#include "tools/tool_test_util.h"

namespace brdf::sources {
namespace {

namespace fs = std::filesystem;
using tooltest::Analytic;
using tooltest::CaptureOf;
using tooltest::WriteText;

class Open : public tooltest::ToolTest {};

// Relative difference, for values that may be large (a glossy peak) or near zero.
double Relative(double got, double want) {
  return std::abs(got - want) / std::max(std::abs(want), 1e-6);
}

void ExpectFormula(const BrdfSource& brdf, const Analytic& m, double tolerance) {
  for (const auto& [ti, to, po] : {std::array<double, 3>{0, 0, 0},
                                   {20, 20, 180},
                                   {35, 50, 170},
                                   {60, 45, 90},
                                   {10, 80, 300}}) {
    const Rgb f = brdf.Eval(SphericalDirectionDeg(ti, 0), SphericalDirectionDeg(to, po));
    const std::array<double, 3> want = m.FAngles(ti, to, po);
    for (int c = 0; c < 3; ++c)
      EXPECT_LT(Relative(f[c], want[c]), tolerance)
          << "θin " << ti << " θout " << to << " φout " << po << " channel " << c << ": " << f[c]
          << " vs " << want[c];
  }
}

TEST_F(Open, AMaterialFileIsItsModelsFormula) {
  const fs::path file = dir_ / "shiny.json";
  WriteText(file, tooltest::Ggx03().Json());
  const OpenedSource opened = OpenBrdf(file.string());
  EXPECT_EQ(opened.kind, FileKind::kMaterial);
  EXPECT_EQ(opened.evaluation, Evaluation::kAnalytic);
  EXPECT_TRUE(opened.measured_theta_in_deg.empty());
  ExpectFormula(*opened.brdf, tooltest::Ggx03(), 1e-12);
}

TEST_F(Open, AnRglFileIsTheDatabasesOwnEvaluationWhateverItsName) {
  const std::string path = test::DataPath("rgl/chm_orange_rgb.bsdf");
  const RglBrdf direct = RglBrdf::Load(path);
  const fs::path renamed = dir_ / "orange.data";
  fs::copy_file(path, renamed);
  for (const std::string& p : {path, renamed.string()}) {
    const OpenedSource opened = OpenBrdf(p);
    EXPECT_EQ(opened.kind, FileKind::kRgl) << p;
    EXPECT_EQ(opened.evaluation, Evaluation::kMeasuredDatabase) << p;
    const Vec3 wi = SphericalDirectionDeg(35, 10), wo = SphericalDirectionDeg(33, 188);
    EXPECT_EQ(opened.brdf->Eval(wi, wo), direct.Eval(wi, wo)) << p;
  }
  EXPECT_EQ(OpenBrdf(path).brdf->Name(), "chm_orange_rgb.bsdf");
}

TEST_F(Open, AMerlFileIsTheValueItWasWrittenWith) {
  const fs::path merl = dir_ / "synthetic.binary";
  WriteMerlBinary(
      merl.string(),
      AnalyticBrdf(ParseMaterialJson(R"({"model": "lambert", "rho": [0.3, 0.3, 0.3]})")));
  const OpenedSource opened = OpenBrdf(merl.string());
  EXPECT_EQ(opened.kind, FileKind::kMerl);
  EXPECT_EQ(opened.brdf->Name(), "synthetic.binary");
  EXPECT_NEAR(opened.brdf->Eval(SphericalDirectionDeg(20, 0), SphericalDirectionDeg(40, 100))[1],
              0.3 / tooltest::kPi, 1e-15);
}

// A Lambertian capture: every resampled texel and the p = 1 extrapolation are ρ/π, so the
// evaluation is exactly the formula up to the float32 storage of samples and texels.
TEST_F(Open, ACaptureIsEvaluatedThroughItsResampledLut) {
  const fs::path cap = dir_ / "matte.bpc";
  WriteBpc(cap.string(), CaptureOf(tooltest::Lambertian(), {0, 20, 40, 60}, 75, 5, 5));
  const OpenedSource opened = OpenBrdf(cap.string());
  EXPECT_EQ(opened.kind, FileKind::kCapture);
  EXPECT_EQ(opened.evaluation, Evaluation::kResampledLut);
  EXPECT_EQ(opened.measured_theta_in_deg, (std::vector<double>{0, 20, 40, 60}));
  ASSERT_TRUE(opened.extrapolation.has_value());
  EXPECT_EQ(opened.extrapolation->origin, ExtrapolationChoice::Origin::kDefaults);
  ExpectFormula(*opened.brdf, tooltest::Lambertian(), 1e-6);
}

TEST_F(Open, ForTheViewerACaptureIsReadAndResampledOnceForBothTheLutAndTheBrdf) {
  const fs::path cap = dir_ / "matte.bpc";
  const Measurement written = CaptureOf(tooltest::Lambertian(), {0, 20, 40}, 70, 5, 10);
  WriteBpc(cap.string(), written);
  const OpenedForView view = OpenForView(cap.string());
  EXPECT_EQ(view.path, cap.string());
  EXPECT_EQ(view.evaluation, Evaluation::kResampledLut);
  // The measurement as the file holds it.
  ASSERT_TRUE(view.measurement.has_value());
  ASSERT_EQ(view.measurement->slices.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    ASSERT_EQ(view.measurement->slices[k].samples.size(), written.slices[k].samples.size());
    EXPECT_EQ(view.measurement->slices[k].samples[7].rgb, written.slices[k].samples[7].rgb);
  }
  // θb is the file's largest θout; the report describes the measured slices. The LUT is the
  // one the commands build, default blind-spot fill included: Δin/2 = 10° up to 80°
  // (docs/design.md §5, "Beyond the measured slices").
  EXPECT_DOUBLE_EQ(view.theta_b_deg, 70.0);
  ASSERT_TRUE(view.resample_report.has_value());
  EXPECT_EQ(view.resample_report->slices.size(), 3u);
  EXPECT_EQ(view.lut.theta_in_deg, (std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80}));
  // The BRDF samples that very LUT (one resampling, not two): same texels, same values.
  const auto* lut_brdf = dynamic_cast<const LutBrdf*>(view.brdf.get());
  ASSERT_NE(lut_brdf, nullptr);
  EXPECT_EQ(lut_brdf->lut().texels, view.lut.texels);
  ExpectFormula(*view.brdf, tooltest::Lambertian(), 1e-6);
}

TEST_F(Open, ForTheViewerAMaterialKeepsItsFormulaAndShowsItsReferenceCapture) {
  const fs::path file = dir_ / "shiny.json";
  WriteText(file, tooltest::Ggx03().Json());
  const OpenedForView view = OpenForView(file.string());
  EXPECT_EQ(view.evaluation, Evaluation::kAnalytic);
  ExpectFormula(*view.brdf, tooltest::Ggx03(), 1e-12);
  // The reference instrument of docs/design.md §1: θin 0/20/40/60°, θout 0–75°, φout 0–359°
  // in 1° steps.
  ASSERT_TRUE(view.measurement.has_value());
  ASSERT_EQ(view.measurement->slices.size(), 4u);
  for (const Slice& s : view.measurement->slices) EXPECT_EQ(s.samples.size(), 76u * 360u);
  // Its LUT, as `brdf convert` makes it with the default fill: 0–80° every 10°.
  EXPECT_EQ(view.lut.theta_in_deg, (std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80}));
  EXPECT_DOUBLE_EQ(view.theta_b_deg, 75.0);
  // A sample of the capture is the formula at its own direction.
  const Sample& x = view.measurement->slices[2].samples[30 * 360 + 180];
  EXPECT_EQ(x.theta_out_deg, 30.0f);
  EXPECT_EQ(x.phi_out_deg, 180.0f);
  EXPECT_LT(Relative(x.rgb[0], tooltest::Ggx03().FAngles(40, 30, 180)[0]), 1e-6);
}

// A table measured at θin 10, 30, 50° (not k·Δin): opened for the viewer at its own θin, from
// its own samples, resampled once, as `brdf eval` evaluates it.
TEST_F(Open, ForTheViewerATableKeepsItsOwnIncidenceAngles) {
  std::string csv = "theta_in,phi_in,theta_out,phi_out,r,g,b\n";
  const Analytic m = tooltest::Lambertian();
  for (int ti : {10, 30, 50})
    for (int to = 0; to <= 70; to += 10)
      for (int po = 0; po < 360; po += 30) {
        const std::array<double, 3> f = m.FAngles(ti, to, po);
        csv += std::to_string(ti) + ",0," + std::to_string(to) + "," + std::to_string(po) + "," +
               std::to_string(f[0]) + "," + std::to_string(f[1]) + "," + std::to_string(f[2]) +
               "\n";
      }
  const fs::path table = dir_ / "table.csv";
  WriteText(table, csv);
  const OpenedForView view = OpenForView(table.string());
  EXPECT_EQ(view.kind, FileKind::kCsv);
  EXPECT_EQ(view.evaluation, Evaluation::kResampledLut);
  EXPECT_EQ(view.lut.theta_in_deg, (std::vector<double>{10, 30, 50}));
  ASSERT_TRUE(view.measurement.has_value());
  EXPECT_EQ(view.measurement->slices.size(), 3u);
  EXPECT_DOUBLE_EQ(view.theta_b_deg, 70.0);
  // std::to_string keeps six decimals: ρ/π to within 1e-6 absolute.
  const Rgb f = view.brdf->Eval(SphericalDirectionDeg(20, 0), SphericalDirectionDeg(35, 140));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], m.kd[c] / tooltest::kPi, 2e-6) << c;
  // And OpenBrdf evaluates the very same LUT.
  const OpenedSource opened = OpenBrdf(table.string());
  EXPECT_EQ(dynamic_cast<const LutBrdf&>(*opened.brdf).lut().texels, view.lut.texels);
}

// An exported LUT is shown as stored: no measurement, θb from its sidecar; an atlas is refused
// with the remedy of evaluating one material's own LUT.
TEST_F(Open, ForTheViewerAnExportedLutIsAsStoredAndAnAtlasIsRefused) {
  const Lut lut = processing::BuildLut(CaptureOf(tooltest::Lambertian(), {0, 20, 40}, 70, 5, 10));
  exporter::TextureMetadata meta;
  meta.name = "matte";
  meta.extrapolation = exporter::ExtrapolationInfo{1.0, 0.5, 70.0};
  exporter::ExportLut(dir_.string(), lut, meta, {exporter::ParseExportFormats("ktx2,json"), {}});
  const OpenedForView view = OpenForView((dir_ / "matte.ktx2").string());
  EXPECT_EQ(view.evaluation, Evaluation::kExportedLut);
  EXPECT_FALSE(view.measurement.has_value());
  EXPECT_DOUBLE_EQ(view.theta_b_deg, 70.0);
  EXPECT_EQ(view.lut.theta_in_deg, (std::vector<double>{0, 20, 40}));
  // RGB9E5: 9 mantissa bits under the exponent the largest channel sets, so every channel is
  // within half a step, at most max/512, of ρ/π.
  const Rgb f = view.brdf->Eval(SphericalDirectionDeg(20, 0), SphericalDirectionDeg(35, 140));
  const double largest = tooltest::Lambertian().kd[0] / tooltest::kPi;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(f[c], tooltest::Lambertian().kd[c] / tooltest::kPi, largest / 512) << c;

  exporter::WriteAtlas((dir_ / "lib").string(), {{"a", &lut, ""}, {"b", &lut, ""}});
  try {
    OpenForView((dir_ / "lib.ktx2").string());
    ADD_FAILURE() << "an atlas opened for the viewer";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(e.remedy().kind, RemedyKind::kEvaluateSingleLut) << e.what();
    EXPECT_NE(std::string(e.what()).find("holds many materials"), std::string::npos) << e.what();
  }
}

TEST_F(Open, FilesThatAreNotBrdfsAreRefusedNamingWhatTheyAre) {
  WriteText(dir_ / "other.json", R"({"colour": "red"})");
  for (const auto& open : {+[](const std::string& p) { OpenBrdf(p); },
                           +[](const std::string& p) { OpenForView(p); }}) {
    try {
      open((dir_ / "other.json").string());
      ADD_FAILURE() << "other JSON opened";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find((dir_ / "other.json").string() + ": cannot evaluate"),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace brdf::sources
