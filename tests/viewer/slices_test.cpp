// Slice heat maps and the hover probe (brdf::viewer::BuildSliceImage, ProbeSlice), and the
// coverage the viewer reports for measured, extrapolated and blind directions.
#include "brdf/viewer/slices.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/models.h"
#include "brdf/processing/resample.h"

namespace brdf::viewer {
namespace {

// A reference-geometry capture (θin 0/20/40/60°, θout 0–75°, φout 0–359° at 1°) of a
// Lambertian ρ = (0.3, 0.6, 0.9), written here sample by sample, with the samples in
// θout 30–34°, φout 100–110° of the θin = `blind_theta_in` slice flagged invalid (a blind
// spot); other θin lists for tables measured elsewhere.
Measurement CaptureWithBlindSpot(const std::vector<double>& theta_in_deg = {0, 20, 40, 60},
                                 double blind_theta_in = 20.0) {
  Measurement m;
  m.metadata.sample_name = "blind";
  for (double theta_in : theta_in_deg) {
    Slice slice;
    slice.theta_in_deg = theta_in;
    for (int t = 0; t <= 75; ++t) {
      for (int p = 0; p < 360; ++p) {
        Sample s;
        s.theta_in_deg = static_cast<float>(theta_in);
        s.theta_out_deg = static_cast<float>(t);
        s.phi_out_deg = static_cast<float>(p);
        s.rgb = {static_cast<float>(0.3 / kPi), static_cast<float>(0.6 / kPi),
                 static_cast<float>(0.9 / kPi)};
        if (theta_in == blind_theta_in && t >= 30 && t <= 34 && p >= 100 && p <= 110) {
          s.flags = kFlagInvalid;
          s.rgb = {1e6f, -5.0f, 0.0f};  // garbage, as an invalid sample may hold
        }
        slice.samples.push_back(s);
      }
    }
    m.slices.push_back(std::move(slice));
  }
  return m;
}

TEST(SliceProbe, MapsTexelsBackToTheOutgoingDirectionTheyHold) {
  const ViewSource source =
      ViewSourceFromBrdf(AnalyticBrdf(ParseMaterialJson(R"({"model": "lafortune", "kd": 0.2,
                                                             "ks": 0.7, "n": 20})")),
                         "glossy");
  for (int k = 0; k < source.lut.slices(); ++k) {
    const double ti = source.lut.theta_in_deg[k];
    // θd = 0 is the mirror direction (θin, 180°).
    SliceProbe p = ProbeSlice(source, k, Channel::kRed, 0.0, 0.0);
    EXPECT_NEAR(p.theta_out_deg, ti, 1e-9);
    if (ti > 0) {
      EXPECT_NEAR(p.phi_out_deg, 180.0, 1e-9);
    }
    // (θd, φd) = (θin, 0°): ω_d = (sinθin, 0, cosθin), S·ω_d = (−sin 2θin, 0, cos 2θin).
    p = ProbeSlice(source, k, Channel::kRed, 0.0, ti);
    EXPECT_NEAR(p.theta_out_deg, 2 * ti, 1e-9);
    if (ti > 0) {
      EXPECT_NEAR(p.phi_out_deg, 180.0, 1e-9);
    }
    EXPECT_EQ(p.below_horizon, 2 * ti > 90);
    // (θd, φd) = (θin, 180°) is the normal.
    p = ProbeSlice(source, k, Channel::kRed, 180.0, ti);
    EXPECT_NEAR(p.theta_out_deg, 0.0, 1e-6);
    // θd = 180° is (180° − θin, 0°): below the horizon, edge-extended.
    p = ProbeSlice(source, k, Channel::kRed, 33.0, 180.0);
    EXPECT_NEAR(p.theta_out_deg, 180.0 - ti, 1e-6);
    EXPECT_TRUE(p.below_horizon);
    EXPECT_EQ(p.coverage, Coverage::kExtrapolated);
    // The nearest texel, and its value.
    p = ProbeSlice(source, k, Channel::kGreen, 41.4, 12.6);
    EXPECT_EQ(p.i, 41);
    EXPECT_EQ(p.j, 13);
    EXPECT_EQ(p.value, source.lut.Texel(k, 13, 41)[1]);
  }
  // One past the last slice (9 with the default blind-spot fill: 0–80° every 10°).
  ASSERT_EQ(source.lut.slices(), 9);
  EXPECT_THROW(ProbeSlice(source, 9, Channel::kRed, 0, 0), InvalidArgument);
}

TEST(SliceImage, HoldsTheChannelOfEveryTexelTopRowFirst) {
  const ViewSource source = ViewSourceFromMeasurement(CaptureWithBlindSpot(), {}, "blind");
  // Slice 4 of the filled LUT (θin 0, 10, …, 80°, docs/design.md §5) is the measured 40° one.
  const SliceImage img = BuildSliceImage(source, 4, Channel::kLuminance);
  ASSERT_EQ(img.width, 361);
  ASSERT_EQ(img.height, 181);
  EXPECT_EQ(img.theta_in_deg, 40.0);
  // Rec.709 luminance of ρ/π = (0.3, 0.6, 0.9)/π.
  const double y = (0.2126 * 0.3 + 0.7152 * 0.6 + 0.0722 * 0.9) / kPi;
  for (float v : img.values) ASSERT_NEAR(v, y, 1e-6);
  const SliceImage red = BuildSliceImage(source, 0, Channel::kRed);
  EXPECT_EQ(red.At(100, 50), source.lut.Texel(0, 50, 100)[0]);
  EXPECT_THROW(BuildSliceImage(source, -1, Channel::kRed), InvalidArgument);
}

TEST(Coverage, BlindSpotIsUnmeasuredOnlyWhereSamplesWereInvalid) {
  const ViewSource source = ViewSourceFromMeasurement(CaptureWithBlindSpot(), {}, "blind");
  EXPECT_DOUBLE_EQ(source.theta_b_deg, 75.0);
  for (int t = 0; t <= 90; ++t) {
    for (int p = 0; p < 360; ++p) {
      const bool blind = t >= 30 && t <= 34 && p >= 100 && p <= 110;
      const Coverage want = t > 75  ? Coverage::kExtrapolated
                            : blind ? Coverage::kUnmeasured
                                    : Coverage::kMeasured;
      ASSERT_EQ(source.CoverageAt(20.0, t, p), want) << "θout " << t << " φout " << p;
      // Other slices have no blind spot.
      ASSERT_EQ(source.CoverageAt(40.0, t, p),
                t > 75 ? Coverage::kExtrapolated : Coverage::kMeasured);
    }
  }
  // Between 20° and the next LUT slice (30°, inserted by the default blind-spot fill) the LUT
  // blends both slices at the same (θd, φd): the blind direction of the 20° slice, moved into
  // the 25° specular frame, is unmeasured there too; the 30° slice itself is filled, shown as
  // the extrapolated band is.
  const Vec3 w_d = SpecularFrame::FromThetaInDeg(20).ToSpecular(SphericalDirectionDeg(32, 105));
  const Vec3 w25 = SpecularFrame::FromThetaInDeg(25).FromSpecular(w_d);
  EXPECT_EQ(source.CoverageAt(25.0, RadToDeg(ThetaOf(w25)), RadToDeg(PhiOf(w25))),
            Coverage::kUnmeasured);
  ASSERT_EQ(source.lut.theta_in_deg, (std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80}));
  ASSERT_TRUE(source.coverage[3].filled);
  EXPECT_EQ(source.CoverageAt(30.0, 10.0, 0.0), Coverage::kExtrapolated);
  EXPECT_EQ(source.CoverageAt(20.0, 10.0, 0.0), Coverage::kMeasured);
  // And the lobe marks those vertices.
  LobeOptions options;
  options.theta_in_deg = 20;
  options.theta_rows = 90;
  options.phi_columns = 360;
  const LobeMesh mesh = BuildLobe(source, options);
  EXPECT_EQ(mesh.coverage[32 * 360 + 105], Coverage::kUnmeasured);
  EXPECT_EQ(mesh.coverage[32 * 360 + 120], Coverage::kMeasured);
}

// A LUT at θin 0, 10, 50° (a table, not k·Δin; ViewSourceFromResampled as brdf-view gets it):
// θin 30° lies halfway between the 10° and 50° slices (Lut::SliceCoordinate 1.5), so the blind
// direction of the 10° slice, moved into the 30° specular frame, is unmeasured there.
TEST(Coverage, BetweenUnevenlySpacedSlicesBothNeighboursCount) {
  const Measurement m = CaptureWithBlindSpot({0, 10, 50}, 10.0);
  processing::ResampleOptions options;
  options.require_uniform_theta_in = false;
  processing::ResampleReport report;
  Lut lut = processing::BuildLut(m, {}, options, &report);
  const ViewSource source = ViewSourceFromResampled(m, std::move(lut), report, "table");
  const Vec3 w_d = SpecularFrame::FromThetaInDeg(10).ToSpecular(SphericalDirectionDeg(32, 105));
  const Vec3 w30 = SpecularFrame::FromThetaInDeg(30).FromSpecular(w_d);
  EXPECT_EQ(source.CoverageAt(30.0, RadToDeg(ThetaOf(w30)), RadToDeg(PhiOf(w30))),
            Coverage::kUnmeasured);
  // The same direction seen from θin 50° itself, where only the intact slice counts.
  const Vec3 w50 = SpecularFrame::FromThetaInDeg(50).FromSpecular(w_d);
  EXPECT_EQ(source.CoverageAt(50.0, RadToDeg(ThetaOf(w50)), RadToDeg(PhiOf(w50))),
            Coverage::kMeasured);
}

TEST(Coverage, ExportedLutWithoutMeasurementCountsAsMeasuredUpToThetaB) {
  ViewSource measured = ViewSourceFromMeasurement(CaptureWithBlindSpot(), {}, "blind");
  const ViewSource lut = ViewSourceFromLut(measured.lut, "lut", 75.0);
  EXPECT_EQ(lut.CoverageAt(20, 32, 105), Coverage::kMeasured);
  EXPECT_EQ(lut.CoverageAt(20, 80, 105), Coverage::kExtrapolated);
}

}  // namespace
}  // namespace brdf::viewer
