// Noise-free synthetic captures and independent reference formulas for the processing tests.
//
// Everything here is written from docs/design.md §4–§6 directly, without calling the code under
// test (brdf::processing): the specular frame matrix, the Bézier root by bisection, the
// extrapolation factor. Only brdf::core's analytic models supply BRDF values.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"

namespace brdf::test {

inline constexpr double kPiT = std::numbers::pi;
inline double Rad(double deg) { return deg * kPiT / 180.0; }
inline double Deg(double rad) { return rad * 180.0 / kPiT; }

struct Dir {
  double x, y, z;
};
inline Dir FromAngles(double theta_deg, double phi_deg) {
  return {std::sin(Rad(theta_deg)) * std::cos(Rad(phi_deg)),
          std::sin(Rad(theta_deg)) * std::sin(Rad(phi_deg)), std::cos(Rad(theta_deg))};
}
inline double ThetaDeg(const Dir& d) { return Deg(std::acos(std::clamp(d.z, -1.0, 1.0))); }
inline double PhiDeg(const Dir& d) {
  double p = Deg(std::atan2(d.y, d.x));
  if (p < 0) p += 360.0;
  if (p >= 360.0) p -= 360.0;
  return p;
}
// Straight down: every φout meets there (up to rounding), so the LUT holds the mean over φout.
inline bool IsNadir(const Dir& d) { return d.z < 0 && std::hypot(d.x, d.y) < 1e-9; }

inline double AngleBetweenDeg(const Dir& a, const Dir& b) {
  return Deg(std::acos(std::clamp(a.x * b.x + a.y * b.y + a.z * b.z, -1.0, 1.0)));
}

// ω_out of LUT texel (i, j) of the slice for θin, written out from docs/design.md §5:
// S(θm) = [[−cosθm, 0, −sinθm], [0, −1, 0], [−sinθm, 0, cosθm]], ω_out = S·ω_d (S = S⁻¹).
// Rows 0 and 180 are single directions (θd = 0°, 180°).
inline Dir TexelOutDirection(double theta_in_deg, int i, int j) {
  const double st = j == 0 || j == 180 ? 0.0 : std::sin(Rad(j)), ct = std::cos(Rad(j));
  const Dir d{st * std::cos(Rad(i)), st * std::sin(Rad(i)), ct};
  const double c = std::cos(Rad(theta_in_deg)), s = std::sin(Rad(theta_in_deg));
  return {-c * d.x - s * d.z, -d.y, -s * d.x + c * d.z};
}

// b(x, l) by bisection on x(t) = 2(1−t)t·l + t² (monotone on [0, 1]), then y(t): the curve of
// docs/design.md §6 solved numerically, not with the closed-form root. The comparison uses the
// factored forms x(t) = t·(2l + (1 − 2l)t) and 1 − x(t) = (1 − t)(1 + t − 2lt), each accurate to a
// few ulp relative where it is used, so t is pinned down even where x'(t) = 0 (l = 1 at x = 1).
inline double BezierByBisection(double x, double l) {
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 200 && hi - lo > 1e-17; ++it) {
    const double t = 0.5 * (lo + hi);
    const bool below = x <= 0.5 ? t * (2.0 * l + (1.0 - 2.0 * l) * t) < x
                                : (1.0 - t) * (1.0 + t - 2.0 * l * t) > 1.0 - x;
    (below ? lo : hi) = t;
  }
  const double t = 0.5 * (lo + hi);
  return 2.0 * (1.0 - t) * t * (1.0 - l) + t * t;
}

// docs/design.md §6 factor (1 − α) + α·p at θ (θ ≤ θb: 1; θ ≥ 90°: the horizon value).
inline double FactorReference(double theta_deg, double theta_b_deg, double p, double l) {
  if (theta_deg <= theta_b_deg) return 1.0;
  const double x = std::min((std::min(theta_deg, 90.0) - theta_b_deg) / (90.0 - theta_b_deg), 1.0);
  const double alpha = BezierByBisection(x, l);
  return (1.0 - alpha) + alpha * p;
}

// How far a fitted value may be from the truth when the capture was taken by the simulated
// reference instrument at noise level 1 (the reasons: fit_test.cpp, FitRecovery.NoisyCaptures...):
// 5 % for the lobe's shape, 3 % (or 0.005 absolute) for everything else, Unreal's Specular 0.05.
inline double NoisyRecoveryTolerance(const ModelInfo& info, const ParameterInfo& p, double truth) {
  if (p.name == "specular") return 0.05;
  const bool shape = static_cast<int>(&p - info.parameters.data()) == info.shape_parameter;
  return std::max((shape ? 0.05 : 0.03) * std::fabs(truth), 0.005);
}

inline Material MakeMaterial(Model model, Rgb kd, Rgb ks, Rgb shape) {
  Material m;
  m.model = model;
  const Rgb parameters[] = {kd, ks, shape};
  for (std::size_t i = 0; i < DescribeModel(model).parameters.size(); ++i)
    m.SetParameter(static_cast<int>(i), parameters[i]);
  return m;
}
inline Material Lambertian() { return MakeMaterial(Model::kLambert, {0.8, 0.5, 0.2}, {}, {}); }
inline Material GgxAlpha03() {
  return MakeMaterial(Model::kGgx, {0.1, 0.15, 0.2}, {0.9, 0.6, 0.3}, {0.3, 0.3, 0.3});
}
inline Material LafortuneN20() {
  return MakeMaterial(Model::kLafortune, {0.1, 0.2, 0.3}, {0.6, 0.5, 0.4}, {20, 20, 20});
}

inline Rgb EvalMaterial(const Material& m, double theta_in_deg, const Dir& out) {
  const Dir l = FromAngles(theta_in_deg, 0.0);
  return m.Evaluate(Vec3{l.x, l.y, l.z}, Vec3{out.x, out.y, out.z});
}

inline Sample MakeSample(double theta_in, double theta_out, double phi_out, const Rgb& v) {
  Sample s;
  s.theta_in_deg = static_cast<float>(theta_in);
  s.theta_out_deg = static_cast<float>(theta_out);
  s.phi_out_deg = static_cast<float>(phi_out);
  for (int c = 0; c < 3; ++c) s.rgb[c] = static_cast<float>(v[c]);
  return s;
}

// The reference instrument's grid (docs/design.md §1), noise-free: θin list, θout 0…max, φout
// 0…359.
inline Measurement GridCapture(const Material& m, std::vector<double> theta_in = {0, 20, 40, 60},
                               double theta_out_max = 75.0, double step_deg = 1.0) {
  Measurement meas;
  meas.metadata.sample_name = "synthetic";
  const int n_theta = static_cast<int>(std::lround(theta_out_max / step_deg));
  const int n_phi = static_cast<int>(std::lround(360.0 / step_deg));
  for (double ti : theta_in) {
    Slice slice;
    slice.theta_in_deg = ti;
    for (int a = 0; a <= n_theta; ++a)
      for (int b = 0; b < n_phi; ++b) {
        const double to = a * step_deg, po = b * step_deg;
        slice.samples.push_back(MakeSample(ti, to, po, EvalMaterial(m, ti, FromAngles(to, po))));
      }
    meas.slices.push_back(std::move(slice));
  }
  return meas;
}

// Random directions, uniform over the cap θout ≤ theta_out_max, `per_slice` of them per slice,
// none within `blind_deg` of the light direction (θin, 0).
inline Measurement ScatteredCapture(const Material& m, std::size_t per_slice, std::uint64_t seed,
                                    double blind_deg = 0.0, double theta_out_max = 75.0,
                                    std::vector<double> theta_in = {0, 20, 40, 60}) {
  Measurement meas;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uz(std::cos(Rad(theta_out_max)), 1.0), uphi(0.0, 360.0);
  for (double ti : theta_in) {
    Slice slice;
    slice.theta_in_deg = ti;
    const Dir light = FromAngles(ti, 0.0);
    while (slice.samples.size() < per_slice) {
      const double z = uz(rng), phi = uphi(rng);
      const double theta = Deg(std::acos(z));
      const Dir d = FromAngles(theta, phi);
      if (blind_deg > 0 && AngleBetweenDeg(d, light) < blind_deg) continue;
      slice.samples.push_back(MakeSample(ti, theta, phi, EvalMaterial(m, ti, d)));
    }
    meas.slices.push_back(std::move(slice));
  }
  return meas;
}

// Flags every sample within `blind_deg` of the light direction invalid and fills it with NaN,
// like an instrument whose detector cannot sit in the incident beam.
inline std::size_t MarkBlindSpot(Measurement& meas, double blind_deg) {
  std::size_t n = 0;
  for (Slice& slice : meas.slices) {
    const Dir light = FromAngles(slice.theta_in_deg, 0.0);
    for (Sample& s : slice.samples) {
      if (AngleBetweenDeg(FromAngles(s.theta_out_deg, s.phi_out_deg), light) < blind_deg) {
        s.flags |= kFlagInvalid;
        s.rgb = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN(),
                 std::numeric_limits<float>::quiet_NaN()};
        ++n;
      }
    }
  }
  return n;
}

inline double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace brdf::test
