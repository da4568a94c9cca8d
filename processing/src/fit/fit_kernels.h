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

#include <algorithm>
#include <array>
#include <cmath>

#include "brdf/core/models.h"

namespace brdf::processing::kernels {

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

struct UnrealLinear;
struct HdrpLinear;
struct UrpLinear;

// Unreal DefaultLit (models.h documents each engine formula and its source).
// v = {base r, g, b, metallic, specular, roughness}.
struct UnrealKernel {
  static constexpr bool kLegacy = false;
  using Linear = UnrealLinear;  // its linear form (below)
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
  using Linear = HdrpLinear;
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
  using Linear = UrpLinear;
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

// Linear forms of the engine models (LinearCost in summed_cost.h).
//
// For a fixed shape slider (roughness or smoothness) each engine model is linear in a few
// coefficients made of the other values: f_c = Σ_j coef[c][j]·basis_j, where the basis functions
// depend only on the geometry and the shape, and the coefficients only on the base colour,
// metallic and specular. So every column of a sample's Jacobian is a combination of the same
// 2·kBasis numbers (the basis functions and their slopes in the shape), with coefficients that
// are the same for every sample: d f_c/d v_i = Σ_j dcoef[c][j][i]·basis_j for the non-shape
// values, d f_c/d shape = Σ_j coef[c][j]·dbasis_j. Under the ngan loss (a fixed weight per
// sample) JᵀJ is then a fixed combination of the moments Σ w²·u·uᵀ of u = (basis, dbasis), and
// Jᵀr of Σ w·r_c·u: a few sums per sample instead of a Jacobian per channel. Same formulas as
// the kernels above (and models.h); tests/processing/fit_kernels_test.cpp checks the values
// against models::EvaluateRgb and the assembled derivatives against Jets.
//
// Interface: kN values, kBasis basis functions, the shape value is the last one (kN − 1);
//   Geom Prepare(ShadingGeometry)          the geometric part, once per fit;
//   Shape ShapeOf(shape value)             what depends only on the shape, once per evaluation;
//   Basis(geom, shape, b, db)              basis functions, and their slopes in the shape value
//                                          when db is not null;
//   Coefficients(v, smooth, coef, dcoef)   coefficients and their slopes in v[0 … kN − 2];
//   kUnused                                the entry of u = (b, db) no Jacobian column uses
//                                          (LinearCost leaves it out of the sums);
//   kKink, OnSmoothPiece(v)                Unreal's saturate(50·f0.g) (below): with `smooth` the
//                                          coefficient is its value above the kink, 1.

// Unreal DefaultLit: f_c = b_c(1 − m)·(1/π) + F90·(D·Vis·Fc) + f0_c·(D·Vis·(1 − Fc)).
struct UnrealLinear {
  static constexpr int kN = 6, kBasis = 3;
  static constexpr int kUnused = 3;  // db[0] = 0
  static constexpr bool kKink = true;
  struct Geom {
    double cos_h2, lv2, k, fc;  // lv2 = 2·NoL·NoV, k = NoL + NoV − 2·NoL·NoV
  };
  static Geom Prepare(const ShadingGeometry& g) {
    const double no_l = g.n_dot_l, no_v = std::min(1.0, std::fabs(g.n_dot_v) + 1e-5);
    return {g.n_dot_h * g.n_dot_h, 2.0 * no_l * no_v, no_l + no_v - 2.0 * no_l * no_v,
            models::Pow5(1.0 - g.v_dot_h)};
  }
  struct Shape {
    double a2, a, half_a2_pi, dln_a2, two_da2, da;  // dln_a2 = (d a2/d roughness)/a2
  };
  static Shape ShapeOf(double roughness) {
    const double r2 = roughness * roughness;
    double a2 = r2 * r2, da2 = 4.0 * r2 * roughness, da = 2.0 * roughness;
    if (a2 < 1e-12) a2 = 1e-12, da2 = 0, da = 0;
    return {a2, std::sqrt(a2), 0.5 * a2 * kInvPi, da2 / a2, 2.0 * da2, da};
  }
  [[gnu::always_inline]] static void Basis(const Geom& g, const Shape& s, double* b, double* db) {
    // D·Vis = a2/(π d²) · 0.5/den, den = NoL(NoV(1 − a) + a) + NoV(NoL(1 − a) + a).
    const double d = g.cos_h2 * (s.a2 - 1.0) + 1.0;
    const double den = g.lv2 + s.a * g.k;
    const double inv_d = 1.0 / d, inv_den = 1.0 / den;
    const double dv = s.half_a2_pi * inv_d * inv_d * inv_den;
    b[0] = kInvPi;
    b[1] = dv * g.fc;
    b[2] = dv - b[1];
    if (db) {
      // d ln(D·Vis)/d roughness = (1/a2 − 2cos²θh/d)·da2 − k/den·da.
      const double ddv = dv * (s.dln_a2 - s.two_da2 * g.cos_h2 * inv_d - s.da * g.k * inv_den);
      db[0] = 0;
      db[1] = ddv * g.fc;
      db[2] = ddv - db[1];
    }
  }
  static double F0g(const double* v) { return 0.08 * v[4] * (1.0 - v[3]) + v[1] * v[3]; }
  static bool OnSmoothPiece(const double* v) { return 50.0 * F0g(v) > 1.0; }
  static void Coefficients(const double* v, bool smooth, double (*coef)[kBasis],
                           double (*dcoef)[kBasis][kN]) {
    const double m = v[3], spec = v[4];
    double f90 = 50.0 * F0g(v);
    const bool free = !smooth && f90 <= 1.0 && f90 >= 0.0;
    f90 = smooth ? 1.0 : std::clamp(f90, 0.0, 1.0);
    for (int c = 0; c < 3; ++c) {
      coef[c][0] = v[c] * (1.0 - m);
      coef[c][1] = f90;
      coef[c][2] = 0.08 * spec * (1.0 - m) + v[c] * m;
      for (int j = 0; j < kBasis; ++j)
        for (int i = 0; i < kN; ++i) dcoef[c][j][i] = 0;
      dcoef[c][0][c] = 1.0 - m;
      dcoef[c][0][3] = -v[c];
      if (free) {
        dcoef[c][1][1] = 50.0 * m;
        dcoef[c][1][3] = 50.0 * (v[1] - 0.08 * spec);
        dcoef[c][1][4] = 4.0 * (1.0 - m);
      }
      dcoef[c][2][c] = m;
      dcoef[c][2][3] = v[c] - 0.08 * spec;
      dcoef[c][2][4] = 0.08 * (1.0 - m);
    }
  }
};

// The Unity metallic workflow's coefficients of the diffuse basis function, b_c(1 − m), and of
// the F0 one, lerp(0.04, b_c, m) = 0.04(1 − m) + b_c·m (both pipelines), and their slopes in
// v = {b r, g, b, metallic, …}; the other coefficients are set to 0 and have no slope.
template <int kBasis, int kN>
void UnityMetallicCoefficients(const double* v, double (*coef)[kBasis],
                               double (*dcoef)[kBasis][kN]) {
  const double m = v[3];
  for (int c = 0; c < 3; ++c) {
    for (int j = 0; j < kBasis; ++j) {
      coef[c][j] = 0;
      for (int i = 0; i < kN; ++i) dcoef[c][j][i] = 0;
    }
    coef[c][0] = v[c] * (1.0 - m);
    coef[c][1] = 0.04 * (1.0 - m) + v[c] * m;
    dcoef[c][0][c] = 1.0 - m;
    dcoef[c][0][3] = -v[c];
    dcoef[c][1][c] = m;
    dcoef[c][1][3] = v[c] - 0.04;
  }
}

// Unity HDRP Lit (metallic): f_c = b_c(1 − m)·Disney + f0_c·(D·V·(1 − Fc)) + 1·(D·V·Fc).
struct HdrpLinear {
  static constexpr int kN = 5, kBasis = 3;
  static constexpr int kUnused = 2;  // b[2]: its coefficient 1 has no slope
  static constexpr bool kKink = false;
  struct Geom {
    double cos_h2, n_dot_l, n_dot_v, lv1, p5l, p5v, fc;  // lv1 = 1 + l·v
  };
  static Geom Prepare(const ShadingGeometry& g) {
    const double n_dot_v = std::max(g.n_dot_v, 0.0001);
    return {g.n_dot_h * g.n_dot_h,
            g.n_dot_l,
            n_dot_v,
            1.0 + g.l_dot_v,
            models::Pow5(1.0 - g.n_dot_l),
            models::Pow5(1.0 - n_dot_v),
            models::Pow5(1.0 - g.v_dot_h)};
  }
  struct Shape {
    double perceptual, a2, half_a2_pi, inv_a2, da2;  // da2 = d a2/d smoothness
  };
  static Shape ShapeOf(double smoothness) {
    const double perceptual = 1.0 - smoothness;
    double alpha = perceptual * perceptual, dalpha = 2.0 * perceptual;
    if (alpha < 1e-4) alpha = 1e-4, dalpha = 0;
    const double a2 = alpha * alpha;
    return {perceptual, a2, 0.5 * a2 * kInvPi, 1.0 / a2, -2.0 * alpha * dalpha};
  }
  [[gnu::always_inline]] static void Basis(const Geom& g, const Shape& s, double* b, double* db) {
    constexpr double kDisney = kInvPi / 1.03571;
    const double nl2 = g.n_dot_l * g.n_dot_l, nv2 = g.n_dot_v * g.n_dot_v;
    const double sd = g.cos_h2 * (s.a2 - 1.0) + 1.0;
    const double qv = std::sqrt(nv2 + s.a2 * (1.0 - nv2));
    const double ql = std::sqrt(nl2 + s.a2 * (1.0 - nl2));
    const double lambda = g.n_dot_l * qv + g.n_dot_v * ql;
    // One division for 1/s, 1/λ, 1/qv and 1/ql.
    const double sl = sd * lambda, qq = qv * ql;
    const double inv = 1.0 / (sl * qq);
    const double inv_sd = inv * qq * lambda, inv_lambda = inv * qq * sd;
    const double dv = s.half_a2_pi * inv_sd * inv_sd * inv_lambda;  // D·V
    const double fd90m1 = s.perceptual * g.lv1 - 0.5;
    const double light = 1.0 + fd90m1 * g.p5l, view = 1.0 + fd90m1 * g.p5v;
    b[0] = kDisney * light * view;
    b[2] = dv * g.fc;
    b[1] = dv - b[2];
    if (db) {
      // d ln(D·V)/d a2 = 1/a2 − 2cos²θh/s − (dλ/d a2)/λ; d Disney/d smoothness = −d/d perceptual.
      const double inv_qv = inv * sl * ql, inv_ql = inv * sl * qv;
      const double dlambda =
          0.5 * (g.n_dot_l * (1.0 - nv2) * inv_qv + g.n_dot_v * (1.0 - nl2) * inv_ql);
      const double ddv = dv * (s.inv_a2 - 2.0 * g.cos_h2 * inv_sd - dlambda * inv_lambda) * s.da2;
      db[0] = -kDisney * g.lv1 * (g.p5l * view + light * g.p5v);
      db[2] = ddv * g.fc;
      db[1] = ddv - db[2];
    }
  }
  static bool OnSmoothPiece(const double*) { return true; }
  static void Coefficients(const double* v, bool, double (*coef)[kBasis],
                           double (*dcoef)[kBasis][kN]) {
    UnityMetallicCoefficients<kBasis, kN>(v, coef, dcoef);
    for (int c = 0; c < 3; ++c) coef[c][2] = 1.0;
  }
};

// Unity URP Lit (metallic): f_c = 0.96·b_c(1 − m)·(1/π) + (0.04(1 − m) + b_c·m)·(specularTerm/π).
struct UrpLinear {
  static constexpr int kN = 5, kBasis = 2;
  static constexpr int kUnused = 2;  // db[0] = 0
  static constexpr bool kKink = false;
  struct Geom {
    double cos_h2, inv_lo_h2;  // 1/max(0.1, LoH²)
  };
  static Geom Prepare(const ShadingGeometry& g) {
    return {g.n_dot_h * g.n_dot_h, 1.0 / std::max(0.1, g.v_dot_h * g.v_dot_h)};
  }
  struct Shape {
    double r2, k, d1, d2;  // k = roughness2/((4ρ + 2)π); slope factors d1, d2 (Basis)
  };
  static Shape ShapeOf(double smoothness) {
    const double perceptual = 1.0 - smoothness;
    double roughness = perceptual * perceptual, drough = 2.0 * perceptual;
    if (roughness < 0.0078125) roughness = 0.0078125, drough = 0;
    const double r2 = std::max(roughness * roughness, 6.103515625e-5);
    // d term/d roughness = term·(2/ρ − 4/(4ρ + 2) − 4ρcos²θh/d); d/d smoothness = −d/d ρ · drough.
    return {r2, r2 * kInvPi / (4.0 * roughness + 2.0),
            -drough * (2.0 / roughness - 4.0 / (4.0 * roughness + 2.0)), 4.0 * roughness * drough};
  }
  [[gnu::always_inline]] static void Basis(const Geom& g, const Shape& s, double* b, double* db) {
    const double d = g.cos_h2 * (s.r2 - 1.0) + 1.00001;
    const double inv_d = 1.0 / d;
    b[0] = 0.96 * kInvPi;
    b[1] = s.k * inv_d * inv_d * g.inv_lo_h2;
    if (db) {
      db[0] = 0;
      db[1] = b[1] * (s.d1 + s.d2 * g.cos_h2 * inv_d);
    }
  }
  static bool OnSmoothPiece(const double*) { return true; }
  static void Coefficients(const double* v, bool, double (*coef)[kBasis],
                           double (*dcoef)[kBasis][kN]) {
    UnityMetallicCoefficients<kBasis, kN>(v, coef, dcoef);
  }
};

// Unity HDRP Lit, specular colour: the metallic form's basis functions with
// f_c = b_c(1 − max(s))·Disney + s_c·(D·V·(1 − Fc)) + 1·(D·V·Fc), v = {b r, g, b, s r, g, b,
// smoothness}. max(s) takes the first of the largest channels, as models.h's comparisons do
// (on Jets too), so its slope goes to that channel alone.
struct HdrpSpecularLinear : HdrpLinear {
  static constexpr int kN = 7;
  static int MaxSpecular(const double* v) {
    int k = 0;
    if (v[4] > v[3 + k]) k = 1;
    if (v[5] > v[3 + k]) k = 2;
    return k;
  }
  static void Coefficients(const double* v, bool, double (*coef)[kBasis],
                           double (*dcoef)[kBasis][kN]) {
    const int k = MaxSpecular(v);
    const double keep = 1.0 - v[3 + k];
    for (int c = 0; c < 3; ++c) {
      for (int j = 0; j < kBasis; ++j)
        for (int i = 0; i < kN; ++i) dcoef[c][j][i] = 0;
      coef[c][0] = v[c] * keep;
      coef[c][1] = v[3 + c];
      coef[c][2] = 1.0;
      dcoef[c][0][c] = keep;
      dcoef[c][0][3 + k] = -v[c];
      dcoef[c][1][3 + c] = 1.0;
    }
  }
};

// Unity URP Lit, specular setup: the metallic form's basis functions (0.96/π and
// specularTerm/π) with f_c = (b_c(1 − s_c)/0.96)·(0.96/π) + s_c·(specularTerm/π),
// v = {albedo r, g, b, s r, g, b, smoothness}.
struct UrpSpecularLinear : UrpLinear {
  static constexpr int kN = 7;
  static void Coefficients(const double* v, bool, double (*coef)[kBasis],
                           double (*dcoef)[kBasis][kN]) {
    constexpr double kInvDiffuse = 1.0 / 0.96;
    for (int c = 0; c < 3; ++c) {
      for (int j = 0; j < kBasis; ++j)
        for (int i = 0; i < kN; ++i) dcoef[c][j][i] = 0;
      const double s = v[3 + c];
      coef[c][0] = v[c] * (1.0 - s) * kInvDiffuse;
      coef[c][1] = s;
      dcoef[c][0][c] = (1.0 - s) * kInvDiffuse;
      dcoef[c][0][3 + c] = -v[c] * kInvDiffuse;
      dcoef[c][1][3 + c] = 1.0;
    }
  }
};

// An engine kernel evaluated through its linear form L: f_c = Σ_j coef[c][j]·basis_j, the slopes
// Σ_j dcoef[c][j][i]·basis_j for the non-shape values and Σ_j coef[c][j]·dbasis_j for the shape
// (the assembly LinearCost makes from sums). For the models whose linear form is all the
// hand-written code they need: the sweep, the other losses and the robust loss use it.
template <class L>
struct LinearFormKernel {
  static constexpr bool kLegacy = false;
  using Linear = L;
  static constexpr int kN = L::kN;
  using Geom = typename L::Geom;
  static Geom Prepare(const ShadingGeometry& g) { return L::Prepare(g); }
  [[gnu::always_inline]] static void Eval(const Geom& g, const double* v, double* f,
                                          double (*grad)[kN]) {
    constexpr int kB = L::kBasis;
    double b[kB], db[kB], coef[3][kB], dcoef[3][kB][kN];
    L::Basis(g, L::ShapeOf(v[kN - 1]), b, grad ? db : nullptr);
    L::Coefficients(v, false, coef, dcoef);
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (int j = 0; j < kB; ++j) sum += coef[c][j] * b[j];
      f[c] = sum;
      if (!grad) continue;
      for (int i = 0; i < kN; ++i) grad[c][i] = 0;
      for (int j = 0; j < kB; ++j) {
        for (int i = 0; i + 1 < kN; ++i) grad[c][i] += dcoef[c][j][i] * b[j];
        grad[c][kN - 1] += coef[c][j] * db[j];
      }
    }
  }
};
using HdrpSpecularKernel = LinearFormKernel<HdrpSpecularLinear>;
using UrpSpecularKernel = LinearFormKernel<UrpSpecularLinear>;

}  // namespace brdf::processing::kernels
