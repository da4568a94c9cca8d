// BuildLut against docs/design.md §5 and §6: noise-free captures of analytic materials must
// reproduce the material texel by texel, the extrapolated band and the below-horizon region must
// follow the formulas (computed here independently, synthetic_capture.h), and irregular captures
// (random directions, a blind spot) must still give a complete, accurate LUT.
#include "brdf/processing/resample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "brdf/core/error.h"
#include "brdf/processing/measurement_brdf.h"
#include "synthetic_capture.h"

namespace brdf::processing {
namespace {

using test::Dir;

const std::vector<double> kThetaIn = {0, 20, 40, 60};

// Largest θout among valid samples, computed here from the data (docs/design.md §6: never
// hard-coded).
double ThetaBOf(const Measurement& m) {
  double t = 0;
  for (const Slice& s : m.slices)
    for (const Sample& x : s.samples)
      if (!(x.flags & kFlagInvalid)) t = std::max<double>(t, x.theta_out_deg);
  return t;
}

struct Comparison {
  std::vector<double> in_range, band, below;  // relative errors per texel and channel
  std::size_t bad_texels = 0;                 // NaN, infinite, zero or negative
  double max_near_pole_or_seam = 0;  // largest in-range error with θout < 2° or φout near 0°
  std::size_t compared = 0;
};

// Compares every texel with the analytic material: inside the measured range f_r at the
// texel's direction, beyond θb the §6 extrapolation of f_r(θb, φout), below the horizon the
// value at 90°. Texels within `skip_blind_deg` of the light direction are only checked for
// holes (a blind spot hides whatever peak is there).
Comparison CompareWithMaterial(const Lut& lut, const Material& m, double theta_b,
                               const ExtrapolationParams& params, double skip_blind_deg = 0) {
  Comparison out;
  for (int k = 0; k < lut.slices(); ++k) {
    const double ti = kThetaIn[static_cast<std::size_t>(k)];
    const Dir light = test::FromAngles(ti, 0.0);
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const float* texel = lut.Texel(k, j, i);
        for (int c = 0; c < 3; ++c)
          if (!(std::isfinite(texel[c]) && texel[c] > 0.0f)) {
            ++out.bad_texels;
            break;
          }
        const Dir w = test::TexelOutDirection(ti, i, j);
        if (skip_blind_deg > 0 && test::AngleBetweenDeg(w, light) < skip_blind_deg) continue;
        const double theta = test::ThetaDeg(w), phi = test::PhiDeg(w);
        Rgb f;
        std::vector<double>* bucket;
        if (w.z > 0 && theta <= theta_b) {
          f = test::EvalMaterial(m, ti, w);
          bucket = &out.in_range;
        } else {
          const double factor =
              test::FactorReference(w.z > 0 ? theta : 90.0, theta_b, params.p, params.l);
          if (test::IsNadir(w)) {  // the mean over φout of the horizon values
            f = {0, 0, 0};
            for (int n = 0; n < 360; ++n) {
              const Rgb h = test::EvalMaterial(m, ti, test::FromAngles(theta_b, n));
              for (int c = 0; c < 3; ++c) f[c] += h[c] / 360.0;
            }
          } else {
            f = test::EvalMaterial(m, ti, test::FromAngles(theta_b, phi));
          }
          for (double& v : f) v *= factor;
          bucket = w.z > 0 ? &out.band : &out.below;
        }
        for (int c = 0; c < 3; ++c) {
          if (!(f[c] > 0)) continue;
          const double e = std::fabs(texel[c] - f[c]) / f[c];
          bucket->push_back(e);
          if (bucket == &out.in_range && (theta < 2.0 || phi < 1.0 || phi > 359.0))
            out.max_near_pole_or_seam = std::max(out.max_near_pole_or_seam, e);
        }
        ++out.compared;
      }
  }
  return out;
}

void ExpectAccurate(const Comparison& c, double median, double p99, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(c.bad_texels, 0u);
  for (const auto& [name, v] :
       {std::pair{"in range", &c.in_range}, std::pair{"extrapolated band", &c.band},
        std::pair{"below horizon", &c.below}}) {
    ASSERT_GT(v->size(), 1000u) << name;
    const double m50 = test::Percentile(*v, 0.5), m99 = test::Percentile(*v, 0.99);
    EXPECT_LT(m50, median) << name;
    EXPECT_LT(m99, p99) << name;
    ::testing::Test::RecordProperty(what + " " + name + " median", std::to_string(m50));
    ::testing::Test::RecordProperty(what + " " + name + " p99", std::to_string(m99));
    std::printf("%-40s %-18s median %.5f%%  p99 %.5f%%\n", what.c_str(), name, 100 * m50,
                100 * m99);
  }
}

void ExpectSeamColumnEqualsColumnZero(const Lut& lut) {
  for (int k = 0; k < lut.slices(); ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(lut.Texel(k, j, 360)[c], lut.Texel(k, j, 0)[c]) << "k " << k << " j " << j;
}

class AnalyticCapture : public ::testing::TestWithParam<std::pair<const char*, Material>> {};

TEST_P(AnalyticCapture, RegularGridTexelsMatchTheMaterial) {
  const Material& m = GetParam().second;
  const Measurement meas = test::GridCapture(m);
  const double theta_b = ThetaBOf(meas);
  ASSERT_EQ(theta_b, 75.0);
  for (const ExtrapolationParams params : {ExtrapolationParams{}, ExtrapolationParams{0.2, 0.3}}) {
    ResampleReport report;
    const Lut lut = BuildLut(meas, params, {}, &report);
    EXPECT_EQ(report.theta_b_deg, theta_b);
    ASSERT_EQ(lut.theta_in_deg, kThetaIn);
    for (const auto& s : report.slices) EXPECT_EQ(s.method, InterpolationMethod::kRegularGrid);
    const Comparison c = CompareWithMaterial(lut, m, theta_b, params);
    ExpectAccurate(c, 0.005, 0.03,
                   std::string(GetParam().first) + " p=" + std::to_string(params.p));
    // A seam or pole artefact would hide inside the 1 % the percentile ignores: bound the max.
    EXPECT_LT(c.max_near_pole_or_seam, 0.03);
    ExpectSeamColumnEqualsColumnZero(lut);
  }
}

TEST_P(AnalyticCapture, ScatteredCaptureMeetsLooserBoundsWithoutHoles) {
  const Material& m = GetParam().second;
  const Measurement meas = test::ScatteredCapture(m, 76 * 360, 7);
  const double theta_b = ThetaBOf(meas);
  const ExtrapolationParams params{0.2, 0.3};
  ResampleReport report;
  const Lut lut = BuildLut(meas, params, {}, &report);
  EXPECT_EQ(report.theta_b_deg, theta_b);
  for (const auto& s : report.slices) EXPECT_EQ(s.method, InterpolationMethod::kScattered);
  const Comparison c = CompareWithMaterial(lut, m, theta_b, params);
  ExpectAccurate(c, 0.01, 0.06, std::string(GetParam().first) + " scattered");
  EXPECT_LT(c.max_near_pole_or_seam, 0.06);
  ExpectSeamColumnEqualsColumnZero(lut);
}

TEST_P(AnalyticCapture, ScatteredMethodOnGridDataMeetsLooserBounds) {
  const Material& m = GetParam().second;
  const Measurement meas = test::GridCapture(m);
  ResampleOptions options;
  options.allow_regular_grid = false;
  ResampleReport report;
  const Lut lut = BuildLut(meas, {}, options, &report);
  for (const auto& s : report.slices) EXPECT_EQ(s.method, InterpolationMethod::kScattered);
  ExpectAccurate(CompareWithMaterial(lut, m, 75.0, {}), 0.01, 0.06,
                 std::string(GetParam().first) + " forced scattered");
}

TEST_P(AnalyticCapture, GridBlindSpotIsFilledFromNeighbours) {
  const Material& m = GetParam().second;
  Measurement meas = test::GridCapture(m);
  ASSERT_GT(test::MarkBlindSpot(meas, 5.0), 0u);
  ResampleReport report;
  const Lut lut = BuildLut(meas, {}, {}, &report);
  for (const auto& s : report.slices) {
    EXPECT_EQ(s.method, InterpolationMethod::kRegularGrid);
    EXPECT_GT(s.filled_nodes, 0u);
    EXPECT_GT(s.invalid_samples, 0u);
  }
  // Outside the hole (plus the 1° lattice cell around it) nothing changes.
  const Comparison c = CompareWithMaterial(lut, m, 75.0, {}, 6.5);
  ExpectAccurate(c, 0.005, 0.03, std::string(GetParam().first) + " grid + blind spot");
  // Inside: no hole, and never outside what was measured around it.
  const Comparison all = CompareWithMaterial(lut, m, 75.0, {});
  EXPECT_EQ(all.bad_texels, 0u);
}

TEST_P(AnalyticCapture, ScatteredBlindSpotLeavesNoHoles) {
  const Material& m = GetParam().second;
  const Measurement meas = test::ScatteredCapture(m, 76 * 360, 11, 5.0);
  const ExtrapolationParams params{0.5, 0.7};
  const Lut lut = BuildLut(meas, params);
  const Comparison c = CompareWithMaterial(lut, m, ThetaBOf(meas), params, 6.5);
  ExpectAccurate(c, 0.01, 0.06, std::string(GetParam().first) + " scattered + blind spot");
  EXPECT_EQ(CompareWithMaterial(lut, m, ThetaBOf(meas), params).bad_texels, 0u);
}

INSTANTIATE_TEST_SUITE_P(Materials, AnalyticCapture,
                         ::testing::Values(std::pair{"lambert", test::Lambertian()},
                                           std::pair{"ggx a=0.3", test::GgxAlpha03()},
                                           std::pair{"lafortune n=20", test::LafortuneN20()}),
                         [](const auto& param) {
                           return std::string(param.index == 0   ? "Lambert"
                                              : param.index == 1 ? "GgxAlpha03"
                                                                 : "LafortuneN20");
                         });

TEST(ResampleScattered, LambertianBlindSpotIsFilledExactly) {
  // A constant is reproduced exactly by a local linear fit limited to the neighbours' range.
  Measurement meas = test::GridCapture(test::Lambertian());
  test::MarkBlindSpot(meas, 8.0);
  const Lut lut = BuildLut(meas, {0.3, 0.4});
  const Rgb rho_pi = test::Lambertian().Evaluate({0, 0, 1}, {0, 0, 1});
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const Dir w = test::TexelOutDirection(kThetaIn[k], i, j);
        const double f = test::FactorReference(w.z > 0 ? test::ThetaDeg(w) : 90.0, 75.0, 0.3, 0.4);
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(lut.Texel(k, j, i)[c], rho_pi[c] * f, 1e-6) << k << " " << j << " " << i;
      }
}

TEST(ResampleScattered, IrregularStepsUseTheScatteredMethod) {
  // θout steps that grow towards grazing are no lattice: the scattered method takes over and
  // still reproduces a constant exactly.
  Measurement meas;
  const Material m = test::Lambertian();
  for (double ti : kThetaIn) {
    Slice slice;
    slice.theta_in_deg = ti;
    for (double to : {0.0, 1.0, 3.0, 6.0, 10.0, 15.0, 21.0, 28.0, 36.0, 45.0, 55.0, 66.0, 72.0})
      for (int po = 0; po < 360; po += 2)
        slice.samples.push_back(
            test::MakeSample(ti, to, po, test::EvalMaterial(m, ti, test::FromAngles(to, po))));
    meas.slices.push_back(std::move(slice));
  }
  ResampleReport report;
  const Lut lut = BuildLut(meas, {0.2, 0.3}, {}, &report);
  EXPECT_EQ(report.theta_b_deg, 72.0);
  for (const auto& s : report.slices) EXPECT_EQ(s.method, InterpolationMethod::kScattered);
  const Comparison c = CompareWithMaterial(lut, m, 72.0, {0.2, 0.3});
  EXPECT_EQ(c.bad_texels, 0u);
  EXPECT_LT(test::Percentile(c.in_range, 1.0), 1e-6);
  EXPECT_LT(test::Percentile(c.band, 1.0), 1e-6);
  EXPECT_LT(test::Percentile(c.below, 1.0), 1e-6);
}

TEST(ResampleScattered, SparseCaptureStillFillsEveryTexel) {
  for (std::size_t n : {1u, 2u, 5u, 40u}) {
    const Measurement meas = test::ScatteredCapture(test::LafortuneN20(), n, 100 + n);
    const Lut lut = BuildLut(meas, {0.2, 0.3});
    double lo = 1e300, hi = -1e300;
    for (const Slice& s : meas.slices)
      for (const Sample& x : s.samples)
        for (float v : x.rgb) {
          lo = std::min<double>(lo, v);
          hi = std::max<double>(hi, v);
        }
    for (float v : lut.texels) {
      ASSERT_TRUE(std::isfinite(v) && v > 0.0f) << n << " samples per slice";
      // Interpolation never leaves the data's range; extrapolation scales it by p ≤ 1 here.
      ASSERT_LE(v, hi * (1 + 1e-6)) << n;
      ASSERT_GE(v, 0.2 * lo * (1 - 1e-6)) << n;
    }
  }
}

// A capture whose value depends on φout only, jagged from one degree to the next and scaled
// per slice, so every texel's expected value is known exactly: bilinear on the 1° lattice is
// linear in φ between nodes, constant in θ, and the pole row is the mean of all pole samples.
double NodeValue(int i, int c) { return 1.0 + 0.5 * ((i * 37) % 11) / 11.0 + 0.1 * c; }
double SliceScale(int k) { return 1.0 + 0.25 * k; }

Measurement PhiOnlyCapture(double theta_out_max = 75.0) {
  Measurement meas;
  for (int k = 0; k < 4; ++k) {
    Slice slice;
    slice.theta_in_deg = kThetaIn[static_cast<std::size_t>(k)];
    for (int a = 0; a <= static_cast<int>(theta_out_max); ++a)
      for (int i = 0; i < 360; ++i) {
        Rgb v;
        for (int c = 0; c < 3; ++c) v[c] = SliceScale(k) * NodeValue(i, c);
        slice.samples.push_back(test::MakeSample(slice.theta_in_deg, a, i, v));
      }
    meas.slices.push_back(std::move(slice));
  }
  return meas;
}

double NodeMean(int c) {
  double mean = 0;
  for (int i = 0; i < 360; ++i) mean += NodeValue(i, c) / 360.0;
  return mean;
}

double PhiOnlyExpected(int k, int c, double theta, double phi) {
  const int i0 = static_cast<int>(std::floor(phi)) % 360, i1 = (i0 + 1) % 360;
  const double t = phi - std::floor(phi);
  const double g = NodeValue(i0, c) + (NodeValue(i1, c) - NodeValue(i0, c)) * t;
  double v = g;
  if (theta < 1.0) v = NodeMean(c) + (g - NodeMean(c)) * theta;
  return SliceScale(k) * v;
}

void ExpectPhiOnlyLut(const Lut& lut, double theta_b, const ExtrapolationParams& params) {
  std::size_t band = 0, below = 0;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const Dir w = test::TexelOutDirection(kThetaIn[static_cast<std::size_t>(k)], i, j);
        const double theta = w.z > 0 ? test::ThetaDeg(w) : 90.0, phi = test::PhiDeg(w);
        const double f = test::FactorReference(theta, theta_b, params.p, params.l);
        band += theta > theta_b && w.z > 0;
        below += w.z <= 0;
        for (int c = 0; c < 3; ++c) {
          const double expected =
              (test::IsNadir(w) ? SliceScale(k) * NodeMean(c)
                                : PhiOnlyExpected(k, c, std::min(theta, theta_b), phi)) *
              f;
          ASSERT_NEAR(lut.Texel(k, j, i)[c], expected, 2e-6 * expected)
              << "k " << k << " j " << j << " i " << i << " θout " << theta << " φout " << phi;
        }
      }
  EXPECT_GT(band, 10000u);
  EXPECT_GT(below, 50000u);
}

TEST(ResampleRegularGrid, BandAndBelowHorizonFollowDesignExactly) {
  const ExtrapolationParams params{0.2, 0.3};
  ExpectPhiOnlyLut(BuildLut(PhiOnlyCapture(), params), 75.0, params);
}

TEST(ResampleRegularGrid, PEqualOneClampsTheBand) {
  ExpectPhiOnlyLut(BuildLut(PhiOnlyCapture(), {}), 75.0, {});
}

TEST(ResampleRegularGrid, ThetaBComesFromTheData) {
  const ExtrapolationParams params{0.5, 0.2};
  ResampleReport report;
  const Lut lut = BuildLut(PhiOnlyCapture(60.0), params, {}, &report);
  EXPECT_EQ(report.theta_b_deg, 60.0);
  ExpectPhiOnlyLut(lut, 60.0, params);
}

TEST(ResampleRegularGrid, BelowHorizonTexelsEqualTheirHorizonValue) {
  // Along a column of the θin = 0 slice φout is fixed (φout = φd + 180°), so every texel below
  // the horizon must equal the texel exactly at the horizon, θd = 90° (row 90). Row 180 is the
  // nadir, one direction where all φout meet: it holds their mean.
  const ExtrapolationParams params{0.2, 0.3};
  const Lut lut = BuildLut(PhiOnlyCapture(), params);
  for (int i = 0; i < Lut::kWidth; ++i)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(lut.Texel(0, 180, i)[c], NodeMean(c) * 0.2, 1e-6) << i;
  for (int i = 0; i < Lut::kWidth; ++i)
    for (int j = 91; j < Lut::kHeight - 1; ++j)
      for (int c = 0; c < 3; ++c)
        ASSERT_FLOAT_EQ(lut.Texel(0, j, i)[c], lut.Texel(0, 90, i)[c]) << i << " " << j;
}

TEST(ResampleRegularGrid, PoleSamplesAreAveragedIntoOneDirection) {
  // Perturb the θout = 0 samples of the θin = 0 slice: they all name one direction, so the
  // LUT's pole (the specular direction of θin = 0, row 0) must hold their mean, the 1° ring
  // must be untouched, and the values in between must not depend on where the pole is
  // approached from.
  Measurement meas = test::GridCapture(test::Lambertian());
  Rgb mean{};
  std::size_t n = 0;
  for (Sample& s : meas.slices[0].samples)
    if (s.theta_out_deg == 0.0f) {
      for (int c = 0; c < 3; ++c) {
        s.rgb[c] *= static_cast<float>(1.0 + 0.2 * std::sin(0.37 * n + c));
        mean[c] += s.rgb[c];
      }
      ++n;
    }
  ASSERT_EQ(n, 360u);
  for (double& v : mean) v /= static_cast<double>(n);
  const Lut lut = BuildLut(meas);
  const Rgb rho_pi = test::Lambertian().Evaluate({0, 0, 1}, {0, 0, 1});
  for (int i = 0; i < Lut::kWidth; ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(lut.Texel(0, 0, i)[c], mean[c], 1e-6 * mean[c]);
      EXPECT_NEAR(lut.Texel(0, 1, i)[c], rho_pi[c], 1e-6 * rho_pi[c]);
    }
  const LutBrdf brdf = MeasurementAsBrdf(meas);
  for (double phi = 0; phi < 360; phi += 7.5)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(brdf.lut().SampleAngles(0, 1e-9, phi)[c], mean[c], 1e-6 * mean[c]) << phi;
      EXPECT_NEAR(brdf.lut().SampleAngles(0, 0.5, phi)[c], 0.5 * (mean[c] + rho_pi[c]),
                  1e-6 * mean[c]);
    }
}

TEST(ResampleScattered, HasNoSeamOrPoleDiscontinuity) {
  ResampleOptions scattered;
  scattered.allow_regular_grid = false;
  const Material m = test::GgxAlpha03();
  for (const Measurement& meas : {test::ScatteredCapture(m, 76 * 360, 3), test::GridCapture(m)}) {
    const LutBrdf brdf = MeasurementAsBrdf(meas, {}, scattered);
    for (double ti : {0.0, 20.0, 60.0}) {
      for (double theta = 1; theta < 75; theta += 3.7) {
        const auto a = brdf.lut().SampleAngles(ti, theta, 359.9999);
        const auto b = brdf.lut().SampleAngles(ti, theta, 0.0001);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-4 * a[c]) << ti << " " << theta;
      }
      const auto pole = brdf.lut().SampleAngles(ti, 0.0, 0.0);
      for (double phi = 0; phi < 360; phi += 10) {
        const auto near_pole = brdf.lut().SampleAngles(ti, 1e-5, phi);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(near_pole[c], pole[c], 1e-4 * pole[c]) << ti << " " << phi;
      }
    }
  }
}

TEST(BuildLut, AcceptsSlicesInAnyOrderAndRotatesPhiIn) {
  const Measurement meas = test::GridCapture(test::GgxAlpha03());
  const Lut reference = BuildLut(meas);
  Measurement shuffled;
  for (int k : {2, 0, 3, 1}) shuffled.slices.push_back(meas.slices[static_cast<std::size_t>(k)]);
  EXPECT_EQ(BuildLut(shuffled).texels, reference.texels);
  // The same capture recorded with the light at φin = 90° (outgoing azimuths rotated with it).
  Measurement rotated = meas;
  for (Slice& s : rotated.slices) {
    s.phi_in_deg = 90.0;
    for (Sample& x : s.samples)
      x.phi_out_deg = static_cast<float>(std::fmod(x.phi_out_deg + 90.0, 360.0));
  }
  const Lut lut = BuildLut(rotated);
  for (std::size_t n = 0; n < lut.texels.size(); ++n)
    ASSERT_NEAR(lut.texels[n], reference.texels[n], 1e-6 * reference.texels[n]) << n;
}

TEST(BuildLut, SerialAndParallelAgree) {
  const Measurement meas = test::ScatteredCapture(test::LafortuneN20(), 5000, 5, 4.0);
  ResampleOptions serial;
  serial.parallel = false;
  EXPECT_EQ(BuildLut(meas, {0.2, 0.3}, serial).texels, BuildLut(meas, {0.2, 0.3}).texels);
}

TEST(BuildLut, SingleNormalIncidenceSlice) {
  const Measurement meas = test::GridCapture(test::LafortuneN20(), {0.0});
  const Lut lut = BuildLut(meas);
  ASSERT_EQ(lut.slices(), 1);
  EXPECT_EQ(lut.texels.size(), 361u * 181u * 3u);
}

void ExpectInvalid(const Measurement& meas, const std::vector<std::string>& needles,
                   const ExtrapolationParams& params = {}, const ResampleOptions& options = {}) {
  try {
    BuildLut(meas, params, options);
    ADD_FAILURE() << "accepted";
  } catch (const InvalidArgument& e) {
    for (const std::string& n : needles)
      EXPECT_NE(std::string(e.what()).find(n), std::string::npos)
          << "'" << n << "' not in: " << e.what();
  }
}

TEST(BuildLut, RejectsThetaInThatIsNotKTimesDelta) {
  ExpectInvalid(test::GridCapture(test::Lambertian(), {0, 20, 45, 60}, 10),
                {"docs/design.md §5", "45", "not uniform"});
  ExpectInvalid(test::GridCapture(test::Lambertian(), {10, 30}, 10), {"first is not 0"});
  ExpectInvalid(test::GridCapture(test::Lambertian(), {0, 20, 20, 40}, 10), {"duplicate"});
  ExpectInvalid(test::GridCapture(test::Lambertian(), {0, 0}, 10), {"duplicate"});
  ExpectInvalid(test::GridCapture(test::Lambertian(), {0, 95}, 10), {"slice 1", "θin"});
  ExpectInvalid(Measurement{}, {"no slices"});
}

TEST(BuildLut, RejectsUnusableSamplesNamingThem) {
  Measurement meas = test::GridCapture(test::Lambertian(), {0, 20}, 10);
  Measurement all_invalid = meas;
  for (Sample& s : all_invalid.slices[1].samples) s.flags |= kFlagInvalid;
  ExpectInvalid(all_invalid, {"slice 1", "no valid sample"});
  Measurement empty = meas;
  empty.slices[0].samples.clear();
  ExpectInvalid(empty, {"slice 0", "no valid sample"});
  Measurement nan_value = meas;
  nan_value.slices[1].samples[17].rgb[2] = std::numeric_limits<float>::quiet_NaN();
  ExpectInvalid(nan_value, {"slice 1", "sample 17", "flagged invalid"});
  Measurement below = meas;
  below.slices[0].samples[5].theta_out_deg = 95.0f;
  ExpectInvalid(below, {"slice 0", "sample 5", "θout", "95"});
  Measurement bad_phi = meas;
  bad_phi.slices[0].samples[3].phi_out_deg = std::numeric_limits<float>::infinity();
  ExpectInvalid(bad_phi, {"sample 3", "φout"});
  ExpectInvalid(meas, {"parameter p"}, {-1.0, 0.5});
  ResampleOptions options;
  options.neighbours = 2;
  ExpectInvalid(meas, {"neighbours"}, {}, options);
}

}  // namespace
}  // namespace brdf::processing
