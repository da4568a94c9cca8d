// Per-sample model evaluation with hand-written derivatives for the fitter (private to brdf_fit).
//
// Why: Ceres' automatic derivatives evaluate each model on Jets (value + N partials carried
// through every operation, pow as exp·log on Jets) and hand Ceres a residual per sample and
// channel; on a 109,440-sample capture that Jacobian handling and the Jet arithmetic were most
// of a fit's time. These kernels evaluate the same formulas as brdf/core/models.h in doubles,
// with the partial derivatives written out, after taking every part that depends only on the
// geometry (tan²θ, cos²θh, (1 − v·h)⁵, ln(v·r) for the exponent lobes, ...) out of the loop
// (Prepare, once per fit). tests/processing/fit_kernels_test.cpp checks every kernel's value
// against models::EvaluateRgb and its derivatives against Ceres' Jets at random points.
//
// Two kinds:
//   legacy (channels independent): one channel from that channel's (a, b, shape) = (kd, ks, n),
//     (kd, f0, α), (ρd, ρs, α), or (ρ) for lambert: `static double Eval(geom, v, grad)`.
//   engine (channels coupled): all three channels from the whole value layout:
//     `static void Eval(geom, v, f[3], grad[3][kN])`.
// grad may be null (value only). Derivatives are with respect to the values as the material
// stores them (not the fitter's log coordinates); where a formula clamps (roughness floors,
// F90 saturation) the derivative is the one-sided derivative the clamped branch has, as Jets
// give it.
#pragma once

#include <ceres/jet.h>

#include <array>
#include <cmath>

#include "brdf/core/models.h"

namespace brdf::processing::kernels {

// ---------------------------------------------------------------------------------------------
// Legacy models.

struct LambertKernel {
  static constexpr bool kLegacy = true;
  static constexpr int kN = 1;
  struct Geom {};
  static Geom Prepare(const ShadingGeometry&) { return {}; }
  [[gnu::always_inline]] static double Eval(const Geom&, const double* v, double* grad) {
    if (grad) grad[0] = kInvPi;
    return v[0] * kInvPi;
  }
};

// kd/π + ks·(n + c)/(cπ)·x^n with x = v·r (Lafortune, c = 2) or n·h (Blinn-Phong, c = 8);
// x^n as exp(n·ln x), ln x once per sample.
template <int kC>
struct PhongLobeKernel {
  static constexpr bool kLegacy = true;
  static constexpr int kN = 3;
  struct Geom {
    double ln_x;  // ln x; −1e300 when x ≤ 0 (no lobe: exp(n·ln x) = 0 and its slope 0 too)
  };
  static Geom Prepare(double x) { return {x > 0 ? std::log(x) : -1e300}; }
  [[gnu::always_inline]] static double Eval(const Geom& g, const double* v, double* grad) {
    constexpr double kNorm = 1.0 / (kC * kPi);
    // Below e^−745 exp underflows to 0 anyway, through libm's slow path.
    const double y = v[2] * g.ln_x;
    const double lobe = y > -745.0 ? std::exp(y) : 0.0;
    const double shape = (v[2] + kC) * kNorm;
    if (grad) {
      grad[0] = kInvPi;
      grad[1] = shape * lobe;
      grad[2] = v[1] * kNorm * lobe * (1.0 + (v[2] + kC) * g.ln_x);
    }
    return v[0] * kInvPi + v[1] * shape * lobe;
  }
};
struct LafortuneKernel : PhongLobeKernel<2> {
  static Geom Prepare(const ShadingGeometry& g) { return PhongLobeKernel<2>::Prepare(g.v_dot_r); }
};
struct BlinnPhongKernel : PhongLobeKernel<8> {
  static Geom Prepare(const ShadingGeometry& g) { return PhongLobeKernel<8>::Prepare(g.n_dot_h); }
};

// kd/π + (f0 + (1 − f0)·fc)·G1(θl)·G1(θv)·D(θh) / (4 cosθl cosθv).
struct GgxKernel {
  static constexpr bool kLegacy = true;
  static constexpr int kN = 3;
  struct Geom {
    double cos_h2, tan2_l, tan2_v, fc, inv_4lv;
  };
  static Geom Prepare(const ShadingGeometry& g) {
    auto tan2 = [](double c) { return (1.0 - c * c) / (c * c); };
    return {g.n_dot_h * g.n_dot_h, tan2(g.n_dot_l), tan2(g.n_dot_v), models::Pow5(1.0 - g.v_dot_h),
            1.0 / (4.0 * g.n_dot_l * g.n_dot_v)};
  }
  [[gnu::always_inline]] static double Eval(const Geom& g, const double* v, double* grad) {
    const double a2 = v[2] * v[2];
    const double inv_denom = 1.0 / (g.cos_h2 * (a2 - 1.0) + 1.0);
    const double dist = a2 * kInvPi * inv_denom * inv_denom;
    const double ql = std::sqrt(1.0 + a2 * g.tan2_l), qv = std::sqrt(1.0 + a2 * g.tan2_v);
    // One division for G1(θl)·G1(θv) = 4/((1 + ql)(1 + qv)) and the slopes' 1/(q(1 + q)).
    const double pl = 1.0 + ql, pv = 1.0 + qv;
    const double inv = 1.0 / (pl * pv * ql * qv);
    const double spec = 4.0 * ql * qv * inv * dist * g.inv_4lv;
    const double fresnel = v[1] + (1.0 - v[1]) * g.fc;
    if (grad) {
      // d/dα² of ln D, ln G1(θl), ln G1(θv): 1/α² − 2cos²θh/denom, −tan²/(2q(1 + q)).
      const double dln = 1.0 / a2 - 2.0 * g.cos_h2 * inv_denom -
                         0.5 * inv * (g.tan2_l * pv * qv + g.tan2_v * pl * ql);
      grad[0] = kInvPi;
      grad[1] = (1.0 - g.fc) * spec;
      grad[2] = fresnel * spec * dln * 2.0 * v[2];
    }
    return v[0] * kInvPi + fresnel * spec;
  }
};

// ρd/π + ρs·exp(−tan²θh/α²) / (4πα²√(cosθl cosθv)).
struct WardKernel {
  static constexpr bool kLegacy = true;
  static constexpr int kN = 3;
  struct Geom {
    double tan2_h, k;  // k = 1/(4π√(cosθl cosθv))
  };
  static Geom Prepare(const ShadingGeometry& g) {
    const double cos2 = g.n_dot_h * g.n_dot_h;
    return {(1.0 - cos2) / cos2, 1.0 / (4 * kPi * std::sqrt(g.n_dot_l * g.n_dot_v))};
  }
  [[gnu::always_inline]] static double Eval(const Geom& g, const double* v, double* grad) {
    const double a2 = v[2] * v[2], inv_a2 = 1.0 / a2;
    // Below e^−745 exp underflows to 0 anyway, through libm's slow path.
    const double y = -g.tan2_h * inv_a2;
    const double spec = y > -745.0 ? std::exp(y) * g.k * inv_a2 : 0.0;
    if (grad) {
      grad[0] = kInvPi;
      grad[1] = spec;
      // d spec/dα² = spec·(tan²θh − α²)/α⁴
      grad[2] = v[1] * spec * (g.tan2_h - a2) * inv_a2 * inv_a2 * 2.0 * v[2];
    }
    return v[0] * kInvPi + v[1] * spec;
  }
};

// ---------------------------------------------------------------------------------------------
// Engine models (models.h documents each formula and its source).

// Unreal DefaultLit. v = {base r, g, b, metallic, specular, roughness}.
struct UnrealKernel {
  static constexpr bool kLegacy = false;
  static constexpr int kN = 6;
  struct Geom {
    double n_dot_h, no_l, no_v, fc;
  };
  static Geom Prepare(const ShadingGeometry& g) {
    return {g.n_dot_h, g.n_dot_l, std::min(1.0, std::fabs(g.n_dot_v) + 1e-5),
            models::Pow5(1.0 - g.v_dot_h)};
  }
  [[gnu::always_inline]] static void Eval(const Geom& g, const double* v, double* f,
                                          double (*grad)[kN]) {
    const double metallic = v[3], specular = v[4], roughness = v[5];
    const double r2 = roughness * roughness;
    // a2 = roughness⁴ (floored), a = √a2, and their slopes in roughness.
    double a2 = r2 * r2, da2 = 4.0 * r2 * roughness, da = 2.0 * roughness;
    if (a2 < 1e-12) a2 = 1e-12, da2 = 0, da = 0;
    const double a = std::sqrt(a2);
    const double d = (g.n_dot_h * a2 - g.n_dot_h) * g.n_dot_h + 1.0;
    const double dist = a2 / (kPi * d * d);
    const double k = g.no_l + g.no_v - 2.0 * g.no_l * g.no_v;
    const double den = g.no_l * (g.no_v * (1.0 - a) + a) + g.no_v * (g.no_l * (1.0 - a) + a);
    const double vis = 0.5 / den;
    const double dv = dist * vis;
    std::array<double, 3> f0;
    for (int c = 0; c < 3; ++c) f0[c] = 0.08 * specular * (1.0 - metallic) + v[c] * metallic;
    double f90 = 50.0 * f0[1];
    const bool f90_free = f90 <= 1.0 && f90 >= 0.0;
    f90 = std::clamp(f90, 0.0, 1.0);
    for (int c = 0; c < 3; ++c)
      f[c] = v[c] * (1.0 - metallic) * kInvPi + dv * (f90 * g.fc + (1.0 - g.fc) * f0[c]);
    if (!grad) return;
    // d(D·Vis)/d roughness = D·Vis·(d ln D/d a2 · da2 − k/den · da).
    const double ddv =
        dv * ((d - 2.0 * a2 * g.n_dot_h * g.n_dot_h) / (a2 * d) * da2 - k / den * da);
    const double df90_dg = f90_free ? 50.0 * metallic : 0.0;
    const double df90_dm = f90_free ? 50.0 * (v[1] - 0.08 * specular) : 0.0;
    const double df90_ds = f90_free ? 4.0 * (1.0 - metallic) : 0.0;
    for (int c = 0; c < 3; ++c) {
      double* gr = grad[c];
      for (int j = 0; j < 3; ++j) gr[j] = 0;
      gr[c] = (1.0 - metallic) * kInvPi + dv * (1.0 - g.fc) * metallic;
      gr[1] += dv * g.fc * df90_dg;
      gr[3] = -v[c] * kInvPi + dv * (g.fc * df90_dm + (1.0 - g.fc) * (v[c] - 0.08 * specular));
      gr[4] = dv * (g.fc * df90_ds + (1.0 - g.fc) * 0.08 * (1.0 - metallic));
      gr[5] = ddv * (f90 * g.fc + (1.0 - g.fc) * f0[c]);
    }
  }
};

// Unity HDRP Lit, metallic workflow. v = {base r, g, b, metallic, smoothness}.
struct HdrpKernel {
  static constexpr bool kLegacy = false;
  static constexpr int kN = 5;
  struct Geom {
    double n_dot_h, n_dot_l, n_dot_v, l_dot_v, p5l, p5v, fc;
  };
  static Geom Prepare(const ShadingGeometry& g) {
    const double n_dot_v = std::max(g.n_dot_v, 0.0001);
    return {g.n_dot_h,
            g.n_dot_l,
            n_dot_v,
            g.l_dot_v,
            models::Pow5(1.0 - g.n_dot_l),
            models::Pow5(1.0 - n_dot_v),
            models::Pow5(1.0 - g.v_dot_h)};
  }
  [[gnu::always_inline]] static void Eval(const Geom& g, const double* v, double* f,
                                          double (*grad)[kN]) {
    const double metallic = v[3];
    const double perceptual = 1.0 - v[4];
    double alpha = perceptual * perceptual, dalpha = 2.0 * perceptual;  // d α / d perceptual
    if (alpha < 1e-4) alpha = 1e-4, dalpha = 0;
    const double a2 = alpha * alpha;
    const double s = (g.n_dot_h * a2 - g.n_dot_h) * g.n_dot_h + 1.0;
    const double dist = kInvPi * a2 / (s * s);
    const double qv = std::sqrt((-g.n_dot_v * a2 + g.n_dot_v) * g.n_dot_v + a2);
    const double ql = std::sqrt((-g.n_dot_l * a2 + g.n_dot_l) * g.n_dot_l + a2);
    const double lambda = g.n_dot_l * qv + g.n_dot_v * ql;
    const double vis = 0.5 / lambda;
    const double dv = dist * vis;
    const double fd90 = 0.5 + perceptual * (1.0 + g.l_dot_v);
    const double light = 1.0 + (fd90 - 1.0) * g.p5l, view = 1.0 + (fd90 - 1.0) * g.p5v;
    constexpr double kDisney = kInvPi / 1.03571;
    const double disney = kDisney * light * view;
    for (int c = 0; c < 3; ++c) {
      const double f0 = 0.04 * (1.0 - metallic) + v[c] * metallic;
      f[c] = v[c] * (1.0 - metallic) * disney + (f0 + (1.0 - f0) * g.fc) * dv;
    }
    if (!grad) return;
    // d/d smoothness = −d/d perceptual; d a2/d perceptual = 2α·dα.
    const double da2 = 2.0 * alpha * dalpha;
    // d λ/d a2, from d√(x² + a2(1 − x²))/d a2 = (1 − x²)/(2√…).
    const double dlambda = 0.5 * (g.n_dot_l * (1.0 - g.n_dot_v * g.n_dot_v) / qv +
                                  g.n_dot_v * (1.0 - g.n_dot_l * g.n_dot_l) / ql);
    const double ddv_da2 =
        dv * ((s - 2.0 * a2 * g.n_dot_h * g.n_dot_h) / (a2 * s) - dlambda / lambda);
    const double ddisney = kDisney * (1.0 + g.l_dot_v) * (g.p5l * view + light * g.p5v);
    for (int c = 0; c < 3; ++c) {
      double* gr = grad[c];
      const double f0 = 0.04 * (1.0 - metallic) + v[c] * metallic;
      for (int j = 0; j < 3; ++j) gr[j] = 0;
      gr[c] = (1.0 - metallic) * disney + (1.0 - g.fc) * metallic * dv;
      gr[3] = -v[c] * disney + (1.0 - g.fc) * (v[c] - 0.04) * dv;
      gr[4] = -(v[c] * (1.0 - metallic) * ddisney + (f0 + (1.0 - f0) * g.fc) * ddv_da2 * da2);
    }
  }
};

// Unity URP Lit, metallic workflow. v = {albedo r, g, b, metallic, smoothness}.
struct UrpKernel {
  static constexpr bool kLegacy = false;
  static constexpr int kN = 5;
  struct Geom {
    double cos_h2, lo_h2;
  };
  static Geom Prepare(const ShadingGeometry& g) {
    return {g.n_dot_h * g.n_dot_h, std::max(0.1, g.v_dot_h * g.v_dot_h)};
  }
  [[gnu::always_inline]] static void Eval(const Geom& g, const double* v, double* f,
                                          double (*grad)[kN]) {
    const double metallic = v[3];
    const double perceptual = 1.0 - v[4];
    double roughness = perceptual * perceptual, drough = 2.0 * perceptual;
    if (roughness < 0.0078125) roughness = 0.0078125, drough = 0;
    const double r2 = std::max(roughness * roughness, 6.103515625e-5);
    const double d = g.cos_h2 * (r2 - 1.0) + 1.00001;
    const double term = r2 / (d * d * g.lo_h2 * (4.0 * roughness + 2.0));
    for (int c = 0; c < 3; ++c) {
      const double specular = 0.04 * (1.0 - metallic) + v[c] * metallic;
      f[c] = (v[c] * 0.96 * (1.0 - metallic) + term * specular) * kInvPi;
    }
    if (!grad) return;
    // d term/d roughness = term·(2/ρ − 4ρcos²θh/d − 4/(4ρ + 2)); d/d smoothness = −d/d perceptual.
    const double dterm =
        term * (2.0 / roughness - 4.0 * roughness * g.cos_h2 / d - 4.0 / (4.0 * roughness + 2.0)) *
        drough;
    for (int c = 0; c < 3; ++c) {
      double* gr = grad[c];
      const double specular = 0.04 * (1.0 - metallic) + v[c] * metallic;
      for (int j = 0; j < 3; ++j) gr[j] = 0;
      gr[c] = (0.96 * (1.0 - metallic) + term * metallic) * kInvPi;
      gr[3] = (-0.96 * v[c] + term * (v[c] - 0.04)) * kInvPi;
      gr[4] = -specular * dterm * kInvPi;
    }
  }
};

// Any engine model through models::EvaluateRgb, derivatives by Jets (the specular-colour
// variants, whose max() and fewer users do not justify their own code).
template <Model kModel, int kValues>
struct JetEngineKernel {
  static constexpr bool kLegacy = false;
  static constexpr int kN = kValues;
  using Geom = ShadingGeometry;
  static Geom Prepare(const ShadingGeometry& g) { return g; }
  [[gnu::always_inline]] static void Eval(const Geom& g, const double* v, double* f,
                                          double (*grad)[kN]) {
    if (!grad) {
      const std::array<double, 3> out = models::EvaluateRgb(kModel, g, v);
      for (int c = 0; c < 3; ++c) f[c] = out[c];
      return;
    }
    using J = ceres::Jet<double, kN>;
    J x[kN];
    for (int i = 0; i < kN; ++i) x[i] = J(v[i], i);
    const std::array<J, 3> out = models::EvaluateRgb(kModel, g, x);
    for (int c = 0; c < 3; ++c) {
      f[c] = out[c].a;
      for (int i = 0; i < kN; ++i) grad[c][i] = out[c].v[i];
    }
  }
};
using HdrpSpecularKernel = JetEngineKernel<Model::kUnityHdrpLitSpecular, 7>;
using UrpSpecularKernel = JetEngineKernel<Model::kUnityUrpLitSpecular, 7>;

}  // namespace brdf::processing::kernels
