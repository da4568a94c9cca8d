// MeasurementBrdf: a capture evaluated at arbitrary directions (`brdf eval FILE.bpc`).
#include "brdf/processing/measurement_brdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "brdf/core/error.h"
#include "brdf/processing/resample.h"
#include "synthetic_capture.h"

namespace brdf::processing {
namespace {

using test::Dir;

Vec3 V(const Dir& d) { return {d.x, d.y, d.z}; }

// Value depends on φout only (1° nodes, linear between) and on the slice: s(θin)·g(φout).
double G(double phi, int c) {
  const auto node = [c](int i) { return 1.0 + 0.5 * ((i * 37) % 11) / 11.0 + 0.1 * c; };
  const int i0 = static_cast<int>(std::floor(phi)) % 360;
  return node(i0) + (node((i0 + 1) % 360) - node(i0)) * (phi - std::floor(phi));
}
double S(double theta_in) { return 1.0 + theta_in / 40.0; }

// Samples are float32 (as in a .bpc file): expected values hold to float precision.
void ExpectFloatClose(double got, double want) { EXPECT_NEAR(got, want, 2e-7 * std::fabs(want)); }

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

TEST(MeasurementBrdf, ReproducesSamplesAtTheirDirections) {
  const Measurement meas = test::GridCapture(test::GgxAlpha03());
  const MeasurementBrdf brdf(meas);
  for (const Slice& slice : meas.slices)
    for (std::size_t n = 0; n < slice.samples.size(); n += 97) {
      const Sample& s = slice.samples[n];
      const Rgb f = brdf.EvalAngles(slice.theta_in_deg, s.theta_out_deg, s.phi_out_deg);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], s.rgb[c], 1e-9 * s.rgb[c]) << n;
    }
}

TEST(MeasurementBrdf, MatchesTheMaterialBetweenSamples) {
  const Material m = test::LafortuneN20();
  const MeasurementBrdf brdf(test::GridCapture(m));
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> errors;
  for (int n = 0; n < 20000; ++n) {
    const double ti = 20.0 * (n % 4), to = 75.0 * u(rng), po = 360.0 * u(rng);
    const Rgb want = test::EvalMaterial(m, ti, test::FromAngles(to, po));
    const Rgb got = brdf.Eval(V(test::FromAngles(ti, 0)), V(test::FromAngles(to, po)));
    for (int c = 0; c < 3; ++c) errors.push_back(std::fabs(got[c] - want[c]) / want[c]);
  }
  EXPECT_LT(test::Percentile(errors, 0.5), 0.005);
  EXPECT_LT(test::Percentile(errors, 0.99), 0.03);
}

TEST(MeasurementBrdf, InterpolatesLinearlyBetweenSlicesAndClampsOutside) {
  const MeasurementBrdf brdf(PhiOnly({0, 20, 40, 60}));
  for (double phi : {0.0, 12.5, 180.25, 359.5}) {
    for (int c = 0; c < 3; ++c) {
      ExpectFloatClose(brdf.EvalAngles(10, 30, phi)[c], 0.5 * (S(0) + S(20)) * G(phi, c));
      ExpectFloatClose(brdf.EvalAngles(47.5, 30, phi)[c],
                       (0.625 * S(40) + 0.375 * S(60)) * G(phi, c));
      ExpectFloatClose(brdf.EvalAngles(80, 30, phi)[c], S(60) * G(phi, c));
    }
  }
}

TEST(MeasurementBrdf, AcceptsAnyDistinctThetaIn) {
  const MeasurementBrdf brdf(PhiOnly({5, 15, 50}));
  EXPECT_EQ(brdf.theta_in_deg(), (std::vector<double>{5, 15, 50}));
  ExpectFloatClose(brdf.EvalAngles(32.5, 30, 10)[0], 0.5 * (S(15) + S(50)) * G(10, 0));
  EXPECT_THROW(MeasurementBrdf(PhiOnly({5, 5})), InvalidArgument);
  EXPECT_THROW(MeasurementBrdf(Measurement{}), InvalidArgument);
}

TEST(MeasurementBrdf, ExtrapolatesLikeDesignSection6) {
  const ExtrapolationParams params{0.2, 0.3};
  const MeasurementBrdf brdf(PhiOnly({0, 20}), params);
  EXPECT_EQ(brdf.theta_b_deg(), 75.0);
  for (double to : {75.0, 75.001, 80.0, 89.0, 90.0})
    for (double phi : {3.5, 200.0})
      ExpectFloatClose(brdf.EvalAngles(20, to, phi)[1],
                       S(20) * G(phi, 1) * test::FactorReference(to, 75.0, 0.2, 0.3));
  // Continuous across θb.
  const double below = brdf.EvalAngles(20, 75.0 - 1e-9, 3.5)[0];
  const double above = brdf.EvalAngles(20, 75.0 + 1e-9, 3.5)[0];
  EXPECT_NEAR(above, below, 1e-6 * below);
}

TEST(MeasurementBrdf, IsZeroBelowTheHorizonAndIsotropic) {
  const MeasurementBrdf brdf(test::GridCapture(test::GgxAlpha03()));
  EXPECT_EQ(brdf.Eval(V(test::FromAngles(20, 0)), {0.5, 0, -0.5})[0], 0.0);
  EXPECT_EQ(brdf.Eval({0.5, 0, -0.5}, V(test::FromAngles(20, 0)))[0], 0.0);
  for (double rot : {90.0, 217.0})
    for (double po : {0.0, 100.0, 181.0}) {
      const Rgb a = brdf.Eval(V(test::FromAngles(40, 0)), V(test::FromAngles(33, po)));
      const Rgb b = brdf.Eval(V(test::FromAngles(40, rot)), V(test::FromAngles(33, po + rot)));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-9 * a[c]);
    }
}

TEST(MeasurementBrdf, AgreesWithTheLutAtTexelCentres) {
  const Measurement meas = test::ScatteredCapture(test::GgxAlpha03(), 8000, 21, 4.0);
  const ExtrapolationParams params{0.2, 0.3};
  const Lut lut = BuildLut(meas, params);
  const MeasurementBrdf brdf(meas, params);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < Lut::kHeight; j += 7)
      for (int i = 0; i < Lut::kWidth; i += 11) {
        const Dir w = test::TexelOutDirection(20.0 * k, i, j);
        if (test::IsNadir(w)) continue;  // no φout there; the LUT holds the mean (resample_test)
        const Rgb f =
            brdf.EvalAngles(20.0 * k, w.z > 0 ? test::ThetaDeg(w) : 90.0, test::PhiDeg(w));
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(lut.Texel(k, j, i)[c], f[c], 1e-5 * f[c]) << k << " " << j << " " << i;
      }
}

}  // namespace
}  // namespace brdf::processing
