// processing::MeasurementAsBrdf: a capture evaluated at arbitrary directions through its LUT
// (`brdf eval FILE.bpc`, `brdf preview FILE.bpc`, the viewer). Expected values come from the
// NumPy transcription of docs/design.md §5, §6 and §9 (tests/python/capture_eval_oracle.py),
// from closed forms, or from the LUT texels BuildLut wrote (where agreeing by construction is
// the point).
#include "brdf/processing/measurement_brdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "brdf/core/error.h"
#include "brdf/processing/resample.h"
#include "synthetic_capture.h"
#include "test_support.h"

namespace brdf::processing {
namespace {

using test::Dir;

Vec3 V(const Dir& d) { return {d.x, d.y, d.z}; }

// f_r with the light at (θin, 0) and the view at (θout, φout), through the BrdfSource interface.
Rgb At(const BrdfSource& brdf, double ti, double to, double po) {
  return brdf.Eval(V(test::FromAngles(ti, 0)), V(test::FromAngles(to, po)));
}

// Value depends on φout only (1° nodes, linear between) and on the slice: s(θin)·g(φout).
double G(double phi, int c) {
  const auto node = [c](int i) { return 1.0 + 0.5 * ((i * 37) % 11) / 11.0 + 0.1 * c; };
  const int i0 = static_cast<int>(std::floor(phi)) % 360;
  return node(i0) + (node((i0 + 1) % 360) - node(i0)) * (phi - std::floor(phi));
}
double S(double theta_in) { return 1.0 + theta_in / 40.0; }

// Samples and texels are float32 (as in a .bpc file and the LUT): values hold to float precision.
void ExpectFloatClose(double got, double want) { EXPECT_NEAR(got, want, 5e-7 * std::fabs(want)); }

Measurement PhiOnly(const std::vector<double>& theta_in) {
  Measurement meas;
  meas.metadata.sample_name = "phi-only";
  for (double ti : theta_in) {
    Slice slice;
    slice.theta_in_deg = ti;
    for (int a = 1; a <= 75; ++a)  // no pole samples: the pole is filled from the first ring
      for (int i = 0; i < 360; ++i)
        slice.samples.push_back(
            test::MakeSample(ti, a, i, {S(ti) * G(i, 0), S(ti) * G(i, 1), S(ti) * G(i, 2)}));
    meas.slices.push_back(std::move(slice));
  }
  return meas;
}

// The NumPy oracle's value for each query (θin, θout, φout) of a grey GGX captured on the
// reference grid (θout ≤ 75°, 1° steps) at `theta_in`.
std::vector<double> OracleValues(double kd, double f0, double alpha,
                                 const std::vector<double>& theta_in,
                                 const std::vector<std::array<double, 3>>& queries) {
  std::ostringstream cmd;
  cmd.precision(17);
  cmd << BRDF_PYTHON3 << " " << BRDF_SOURCE_DIR << "/tests/python/capture_eval_oracle.py " << kd
      << " " << f0 << " " << alpha << " ";
  for (std::size_t k = 0; k < theta_in.size(); ++k) cmd << (k ? "," : "") << theta_in[k];
  cmd << " 75";
  for (const auto& q : queries) cmd << " " << q[0] << "," << q[1] << "," << q[2];
  const test::CommandOutput r = test::RunCommand(cmd.str());
  EXPECT_EQ(r.status, 0) << cmd.str();
  std::istringstream in(r.out);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  EXPECT_EQ(values.size(), queries.size()) << r.out;
  return values;
}

void ExpectMatchesOracle(const std::vector<double>& theta_in,
                         const std::vector<std::array<double, 3>>& queries) {
  const double kd = 0.1, f0 = 0.9, alpha = 0.3;
  const Material m =
      test::MakeMaterial(Model::kGgx, {kd, kd, kd}, {f0, f0, f0}, {alpha, alpha, alpha});
  const LutBrdf brdf = MeasurementAsBrdf(test::GridCapture(m, theta_in));
  const std::vector<double> want = OracleValues(kd, f0, alpha, theta_in, queries);
  ASSERT_EQ(want.size(), queries.size());
  for (std::size_t n = 0; n < queries.size(); ++n) {
    const auto& [ti, to, po] = queries[n];
    const Rgb got = At(brdf, ti, to, po);
    // Float32 texels and float lerps (Lut::SampleTrilinear), against the oracle in double.
    EXPECT_NEAR(got[1], want[n], 2e-6 * want[n] + 1e-9)
        << "θin " << ti << " θout " << to << " φout " << po;
  }
}

// Between measured θin the capture interpolates in the specular frame, as the LUT does: in the
// mirror direction of θin = 30° it reads the 20° and 40° slices at their mirror directions (the
// peak), not at the fixed 30° view where both slices are off their peaks (reading a gold
// capture that way gave 2.62 at 30° against 4.52 from the material).
TEST(MeasurementAsBrdf, InterpolatesBetweenSlicesInTheSpecularFrameLikeTheNumpyLut) {
  ExpectMatchesOracle({0, 20, 40, 60}, {{30, 30, 180},
                                        {10, 10, 180},
                                        {47.3, 44.1, 171.5},
                                        {30, 52, 200},
                                        {55, 12, 33},
                                        {13, 64, 290},
                                        {40, 38, 182},
                                        {20, 0, 0},
                                        {59.9, 70, 150}});
  // And far from a specular peak the same: the diffuse floor and the tails.
  ExpectMatchesOracle({0, 20, 40, 60}, {{25, 40, 0}, {35, 70, 90}, {50, 5, 10}});
}

// Light beyond the last measured θin, view inside the measured range: reciprocity answers from
// the measured slices (f(ωi, ωo) = f(ωo, ωi)), not the held 60° slice. Both beyond: the nearest
// slice at the same specular-frame angles.
TEST(MeasurementAsBrdf, UsesReciprocityForLightBeyondTheLastSlice) {
  ExpectMatchesOracle({0, 20, 40, 60}, {{70, 30, 180},
                                        {80, 45, 150},
                                        {89, 10, 20},
                                        {65, 59, 181},
                                        {75, 70, 180},
                                        {85, 62, 30},
                                        {70, 70, 180}});
  const Material m = test::GgxAlpha03();
  const LutBrdf brdf = MeasurementAsBrdf(test::GridCapture(m));
  // Exchanging the directions of a query answered by reciprocity gives the same number: the
  // exchanged query lies inside the measured range and is answered directly.
  for (const auto& [ti, to, po] :
       std::vector<std::array<double, 3>>{{70, 30, 180}, {80, 40, 95}, {64, 0, 0}}) {
    const Rgb a = At(brdf, ti, to, po);
    const Rgb b = brdf.Eval(V(test::FromAngles(to, po)), V(test::FromAngles(ti, 0)));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(a[c], b[c]) << ti << " " << to << " " << po;
  }
  // Which queries are exchanged (docs/design.md §5).
  const Lut& lut = brdf.lut();
  EXPECT_TRUE(lut.ExchangesLightAndView(70, 30));
  EXPECT_TRUE(lut.ExchangesLightAndView(80, 70));  // nearer the range, though outside it
  EXPECT_FALSE(lut.ExchangesLightAndView(70, 70));
  EXPECT_FALSE(lut.ExchangesLightAndView(70, 85));
  EXPECT_FALSE(lut.ExchangesLightAndView(60, 10));
  EXPECT_FALSE(lut.ExchangesLightAndView(30, 80));
  // Within 0.001° of the last slice is that slice (float32 noise of a measured 60°).
  EXPECT_FALSE(lut.ExchangesLightAndView(60.0005, 10));
  EXPECT_TRUE(lut.ExchangesLightAndView(60.002, 10));
}

TEST(MeasurementAsBrdf, AcceptsAnyDistinctThetaIn) {
  ExpectMatchesOracle({5, 15, 50}, {{32.5, 30, 180}, {10, 40, 170}, {2, 60, 90}, {70, 20, 180}});
  EXPECT_EQ(MeasurementAsBrdf(PhiOnly({5, 15, 50})).lut().theta_in_deg,
            (std::vector<double>{5, 15, 50}));
  EXPECT_THROW(MeasurementAsBrdf(PhiOnly({5, 5})), InvalidArgument);
  EXPECT_THROW(MeasurementAsBrdf(Measurement{}), InvalidArgument);
}

TEST(MeasurementAsBrdf, MatchesTheMaterialAtMeasuredThetaIn) {
  const Material m = test::LafortuneN20();
  const LutBrdf brdf = MeasurementAsBrdf(test::GridCapture(m));
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> errors;
  for (int n = 0; n < 20000; ++n) {
    const double ti = 20.0 * (n % 4), to = 75.0 * u(rng), po = 360.0 * u(rng);
    const Rgb want = test::EvalMaterial(m, ti, test::FromAngles(to, po));
    const Rgb got = At(brdf, ti, to, po);
    for (int c = 0; c < 3; ++c) errors.push_back(std::fabs(got[c] - want[c]) / want[c]);
  }
  EXPECT_LT(test::Percentile(errors, 0.5), 0.005);
  EXPECT_LT(test::Percentile(errors, 0.99), 0.03);
}

// At θin = 0 the specular frame is S(0) = diag(−1, −1, 1): texel (i, j) is (θout, φout) =
// (j°, i° − 180°), the capture's own 1° grid, so the §6 values at whole θout degrees are exact.
TEST(MeasurementAsBrdf, ExtrapolatesLikeDesignSection6) {
  const ExtrapolationParams params{0.2, 0.3};
  const LutBrdf brdf = MeasurementAsBrdf(PhiOnly({0, 20}), params);
  for (double to : {75.0, 76.0, 80.0, 89.0, 90.0})
    for (double phi : {3.5, 200.0})
      ExpectFloatClose(brdf.lut().SampleAngles(0, to, phi)[1],
                       S(0) * G(phi, 1) * test::FactorReference(to, 75.0, 0.2, 0.3));
  // Continuous across θb.
  const double below = At(brdf, 0, 75.0 - 1e-9, 3.5)[0];
  const double above = At(brdf, 0, 75.0 + 1e-9, 3.5)[0];
  EXPECT_NEAR(above, below, 1e-6 * below);
}

TEST(MeasurementAsBrdf, IsZeroBelowTheHorizonAndIsotropic) {
  const LutBrdf brdf = MeasurementAsBrdf(test::GridCapture(test::GgxAlpha03()));
  EXPECT_EQ(brdf.Eval(V(test::FromAngles(20, 0)), {0.5, 0, -0.5})[0], 0.0);
  EXPECT_EQ(brdf.Eval({0.5, 0, -0.5}, V(test::FromAngles(20, 0)))[0], 0.0);
  for (double rot : {90.0, 217.0})
    for (double po : {0.0, 100.0, 181.0}) {
      const Rgb a = brdf.Eval(V(test::FromAngles(40, 0)), V(test::FromAngles(33, po)));
      const Rgb b = brdf.Eval(V(test::FromAngles(40, rot)), V(test::FromAngles(33, po + rot)));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6 * a[c]);
    }
}

// By construction: at a measured θin and a texel's outgoing direction, the value is the texel
// BuildLut wrote (scattered method, §6 with p = 0.2, l = 0.3).
TEST(MeasurementAsBrdf, IsTheLutTexelAtTexelCentres) {
  const Measurement meas = test::ScatteredCapture(test::GgxAlpha03(), 8000, 21, 4.0);
  const ExtrapolationParams params{0.2, 0.3};
  const Lut lut = BuildLut(meas, params);
  const LutBrdf brdf = MeasurementAsBrdf(meas, params);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < Lut::kHeight; j += 7)
      for (int i = 0; i < Lut::kWidth; i += 11) {
        const Dir w = test::TexelOutDirection(20.0 * k, i, j);
        if (w.z <= 1e-6) continue;  // below the horizon Eval is 0 by the BrdfSource contract
        const Rgb f = At(brdf, 20.0 * k, test::ThetaDeg(w), test::PhiDeg(w));
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(lut.Texel(k, j, i)[c], f[c], 1e-5 * f[c]) << k << " " << j << " " << i;
      }
}

}  // namespace
}  // namespace brdf::processing
