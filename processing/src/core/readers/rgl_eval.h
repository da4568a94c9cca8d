// RGL `.bsdf` evaluation (Dupuy & Jakob 2018), private to the reader: see brdf/core/rgl.h for
// the algorithm. rgl_load.cpp fills RglBrdf::Tables, rgl_eval.cpp evaluates them and
// rgl_tabulate.cpp builds the tabulated form from them.
//
// Everything that depends only on the file is computed once here: each incidence slice's VNDF
// is normalised and its conditional (along u(θ)) and marginal (along u(φ)) CDFs are tabulated,
// and the RGB table is interleaved per texel so one evaluation touches a few cache lines. Eval
// then costs three atan2 (θi, θm and φm − φi; four for anisotropic files, all by FastAtan2's
// polynomial, not libm), the warp inversion on a 2×2 cell blended over (at most four)
// incidence slices, and three bilinear lookups.
//
// Tried and measured slower or no faster (bench_rgl and `brdf preview`, docs/benchmarks.md,
// "RGL and MERL evaluation", "Tried and not kept"): a per-cell warp layout (one 32-byte block per
// cell and slice: one cache line instead of two, but twice the table), 12-byte packed
// vertices (float density, double CDF), and a 32-bit fixed-point CDF (half the table, but the
// oracle then differs by 1e-5: X needs double).
//
// The warp tables are double where the reference loader keeps float. Measured against the
// float64 NumPy oracle, float tables move f_r by up to ~5e-5 relative at moderate angles and
// ~5e-4 at grazing half vectors (θm > 80°, where X = C / row_total divides small sums): the
// size of the reference's own rounding. With double tables the two agree to ~1e-11.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "brdf/core/rgl.h"

namespace brdf::detail {

// Cell of a grid of `n` vertices spanning [0, 1] that holds u, and the position inside it.
// NaN maps to 0 (both comparisons fail), so no input can index outside the table.
struct Cell {
  int i;
  double f;
};
// Written as two selects so that the compiler emits maxsd/minsd, not branches.
inline double Clamp01(double u) {
  const double a = u > 0.0 ? u : 0.0;
  return a < 1.0 ? a : 1.0;
}
inline Cell Locate(double u, int n) {
  const double s = Clamp01(u) * (n - 1);
  const int i = std::min(static_cast<int>(s), n - 2);
  return {i, s - i};
}

inline double PhiToU(double phi) { return (phi + kPi) * (0.5 / kPi); }

// A bilinear interpolant over the unit square: nx vertices along x (u(θ)), ny along y (u(φ)),
// row-major [y][x]. Used for `ndf` and `sigma` (the reference's unnormalised Marginal2D).
struct Interpolant2 {
  int nx = 0, ny = 0;
  std::vector<float> v;
  double Eval(double ux, double uy) const {
    const Cell cx = Locate(ux, nx), cy = Locate(uy, ny);
    const float* p = v.data() + static_cast<std::size_t>(cy.i) * nx + cx.i;
    return (1 - cy.f) * ((1 - cx.f) * p[0] + cx.f * p[1]) +
           cy.f * ((1 - cx.f) * p[nx] + cx.f * p[nx + 1]);
  }
};

// Up to four incidence slices (2 along φi × 2 along θi) and their blend weights.
struct Corners {
  int n = 0;
  std::array<std::size_t, 4> slice{};
  std::array<double, 4> w{};
};

// Left vertex (clamped to [0, n−2]) and weight of the right one for linear interpolation of a
// tabulated parameter, as the reference's find_interval; a single-entry grid is constant.
// `inv_step[k]` = 1 / (grid[k + 1] − grid[k]), tabulated so that the blend weights (which
// every later step waits for) need no division.
inline void Interval(const std::vector<double>& grid, const std::vector<double>& inv_step, double x,
                     int& i, double& w) {
  const int n = static_cast<int>(grid.size());
  if (n == 1) {
    i = 0;
    w = 0.0;
    return;
  }
  // The upper-bound position by counting (grids hold a handful of entries, so a branch-free
  // count beats a binary search whose branches the predictor cannot learn).
  int above = 0;
  for (const double g : grid) above += g <= x ? 1 : 0;
  i = std::clamp(above - 1, 0, n - 2);
  w = Clamp01((x - grid[i]) * inv_step[i]);
}

// atan2(y, x) in radians, within ~2e-15 relative of the library's, without a libm call (the
// evaluator needs three or four per call; libm's acos and atan2 were ~18 % of its time). The
// quotient min/max of |x|, |y| is in [0, 1]; above tan(π/8) it is mapped through
// atan t = π/4 + atan((t − 1)/(t + 1)) so that the polynomial only spans |s| ≤ tan(π/8).
// The coefficients are a least-squares fit of (atan(s)/s − 1)/s² in s² on that interval
// (relative error 1.3e-15; the oracle's tolerance is 1e-6). Both zero, or NaN: std::atan2,
// whose conventions at the pole (atan2(0, −0) = π) the reference follows.
inline constexpr double kAtanCoefficients[9] = {
    -0.33333333333256443, 0.19999999982070268,  -0.14285712838546033,
    0.11111053452336944,  -0.09089599958686255, 0.07674177368739588,
    -0.0650947129124945,  0.050351028123015215, -0.025445275546824294};
inline constexpr double kTanPiOver8 = 0.41421356237309503;

inline double FastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double lo = ay < ax ? ay : ax, hi = ay < ax ? ax : ay;
  if (!(hi > 0.0) || !std::isfinite(hi)) return std::atan2(y, x);
  // The octant logic is arithmetic on 0/1 flags rather than branches (random directions make
  // them unpredictable); multiplying by 0 or 1 and adding 0 are exact, so the result is the
  // same number the branches would give.
  const double reduced = lo > kTanPiOver8 * hi ? 1.0 : 0.0;
  const double swapped = ay > ax ? 1.0 : 0.0, negative_x = x < 0.0 ? 1.0 : 0.0;
  // One division for either case: (t − 1)/(t + 1) = (lo − hi)/(lo + hi).
  const double s = (lo - reduced * hi) / (hi + reduced * lo);
  const double w = s * s;
  // Estrin's scheme: the evaluator is latency-bound, and this halves the dependency chain of
  // Horner's.
  constexpr const double* c = kAtanCoefficients;
  const double c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3], c4 = c[4], c5 = c[5], c6 = c[6],
               c7 = c[7], c8 = c[8];
  const double w2 = w * w, w4 = w2 * w2;
  const double p01 = c0 + c1 * w, p23 = c2 + c3 * w, p45 = c4 + c5 * w, p67 = c6 + c7 * w;
  const double p0_3 = p01 + p23 * w2, p4_7 = p45 + p67 * w2;
  const double p = p0_3 + (p4_7 + c8 * w4) * w4;
  double r = reduced * (0.25 * kPi) + (s + s * w * p);
  r = swapped * (0.5 * kPi) + (1.0 - 2.0 * swapped) * r;  // π/2 − r above the diagonal
  r = negative_x * kPi + (1.0 - 2.0 * negative_x) * r;    // π − r for x < 0
  return std::copysign(r, y);                             // r ≥ 0: −r for y < 0 (or −0)
}

// θ = atan2(ρ, z) and u(θ) = √(θ / (π/2)) of two directions at once in the two lanes of an
// SSE2 register (baseline x86-64): the same operations in the same order as FastAtan2 and
// √(θ·2/π), so the same numbers, for half the instructions. Needs z > 0 and finite inputs
// (then max(ρ, z) > 0 and neither the pole fallback nor the signs of FastAtan2 apply).
// `rho2` holds ρ².
inline void ThetaAndU(double rho2_a, double z_a, double rho2_b, double z_b, double theta[2],
                      double u[2]) {
#if !defined(__SSE2__)
  theta[0] = FastAtan2(std::sqrt(rho2_a), z_a);
  theta[1] = FastAtan2(std::sqrt(rho2_b), z_b);
  for (int k = 0; k < 2; ++k) u[k] = std::sqrt(theta[k] * (2.0 / kPi));
#else
  const __m128d y = _mm_sqrt_pd(_mm_set_pd(rho2_b, rho2_a)), x = _mm_set_pd(z_b, z_a);
  const __m128d one = _mm_set1_pd(1.0);
  const __m128d lo = _mm_min_pd(y, x), hi = _mm_max_pd(x, y);
  const __m128d reduced =
      _mm_and_pd(_mm_cmpgt_pd(lo, _mm_mul_pd(_mm_set1_pd(kTanPiOver8), hi)), one);
  const __m128d swapped = _mm_and_pd(_mm_cmpgt_pd(y, x), one);
  const __m128d s =
      _mm_div_pd(_mm_sub_pd(lo, _mm_mul_pd(reduced, hi)), _mm_add_pd(hi, _mm_mul_pd(reduced, lo)));
  const __m128d w = _mm_mul_pd(s, s), w2 = _mm_mul_pd(w, w), w4 = _mm_mul_pd(w2, w2);
  auto pair = [&](int k) {  // c[k] + c[k + 1]·w
    return _mm_add_pd(_mm_set1_pd(kAtanCoefficients[k]),
                      _mm_mul_pd(_mm_set1_pd(kAtanCoefficients[k + 1]), w));
  };
  const __m128d p0_3 = _mm_add_pd(pair(0), _mm_mul_pd(pair(2), w2));
  const __m128d p4_7 = _mm_add_pd(pair(4), _mm_mul_pd(pair(6), w2));
  const __m128d p = _mm_add_pd(
      p0_3, _mm_mul_pd(_mm_add_pd(p4_7, _mm_mul_pd(_mm_set1_pd(kAtanCoefficients[8]), w4)), w4));
  __m128d r = _mm_add_pd(_mm_mul_pd(reduced, _mm_set1_pd(0.25 * kPi)),
                         _mm_add_pd(s, _mm_mul_pd(_mm_mul_pd(s, w), p)));
  r = _mm_add_pd(_mm_mul_pd(swapped, _mm_set1_pd(0.5 * kPi)),
                 _mm_mul_pd(_mm_sub_pd(one, _mm_mul_pd(_mm_set1_pd(2.0), swapped)), r));
  _mm_storeu_pd(theta, r);
  _mm_storeu_pd(u, _mm_sqrt_pd(_mm_mul_pd(r, _mm_set1_pd(2.0 / kPi))));
#endif
}

// u(φ) of a half-vector azimuth that may span two turns (φm − φi ∈ [−2π, 2π), so PhiToU gives
// [−½, 3/2)), wrapped into [0, 1) as u − floor(u) does, without floor: baseline x86-64 has no
// rounding instruction and calls a function.
inline double RelativePhiToU(double phi) {
  const double u = PhiToU(phi);
  if (u < 0.0) return u + 1.0;
  if (u >= 1.0) return u - 1.0;
  return u;
}

// Where a direction pair lands in the file's parameterisation (rgl.h, step 1): the incidence
// elevation θi and u(θi), the incidence azimuth φi (left 0 when only φm − φi is needed) and the
// half vector's unit-square position u_m. False (and nothing set) when either direction is at
// or below the horizon or not finite.
struct PairCoordinates {
  double theta_i_rad, u_i, phi_i_rad, um_x, um_y;
};
inline bool Coordinates(const Vec3& wi, const Vec3& wo, bool relative_phi_only, bool isotropic,
                        PairCoordinates& out) {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return false;
  if (!std::isfinite(wi.x + wi.y + wi.z + wo.x + wo.y + wo.z)) return false;
  // θ and φ of ωi and of the half vector, all from atan2: both are invariant to the length
  // of their arguments, so h = ωi + ωo needs no normalisation, and atan2(ρ, z) is the acos
  // of a unit vector's z (better conditioned near the pole).
  const Vec3 h = wi + wo;
  double theta[2], u[2];  // ωi, h
  ThetaAndU(wi.x * wi.x + wi.y * wi.y, wi.z, h.x * h.x + h.y * h.y, h.z, theta, u);
  // The reference takes atan2 of each vector (atan2(0, ±0) = 0 or π at the pole); the
  // relative angle of the general case is the same number from one atan2 of the cross and
  // dot products of the projections.
  double phi_i_rad = 0.0, phi;
  if (relative_phi_only && (wi.x != 0.0 || wi.y != 0.0) && (h.x != 0.0 || h.y != 0.0)) {
    phi = FastAtan2(wi.x * h.y - wi.y * h.x, wi.x * h.x + wi.y * h.y);
  } else {
    phi_i_rad = FastAtan2(wi.y, wi.x);
    const double phi_m = FastAtan2(h.y, h.x);
    phi = isotropic ? phi_m - phi_i_rad : phi_m;
  }
  out = {theta[0], u[0], phi_i_rad, u[1], RelativePhiToU(phi)};
  return true;
}

// Coordinates() in single precision for the tabulated form (whose own error is ~1e-2, so the
// atan's 2.4e-7 relative costs nothing): θi, θm and φm − φi in three lanes of one SSE register,
// one division and one square root for all three, a degree-3 polynomial (a least-squares fit of
// (atan(s)/s − 1)/s² on |s| ≤ tan(π/8), like kAtanCoefficients), then u(θ) for the first two.
// Falls back to Coordinates() where ωi or h has no horizontal part (the azimuth conventions at
// the pole) and without SSE2.
inline bool CoordinatesSingle(const Vec3& wi, const Vec3& wo, PairCoordinates& out) {
#if !defined(__SSE2__)
  return Coordinates(wi, wo, true, true, out);
#else
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return false;
  if (!std::isfinite(wi.x + wi.y + wi.z + wo.x + wo.y + wo.z)) return false;
  const Vec3 h = wi + wo;
  const double rho2_i = wi.x * wi.x + wi.y * wi.y, rho2_h = h.x * h.x + h.y * h.y;
  if (rho2_i == 0.0 || rho2_h == 0.0) return Coordinates(wi, wo, true, true, out);
  const double cross = wi.x * h.y - wi.y * h.x, dot = wi.x * h.x + wi.y * h.y;
  // Lanes 0, 1, 2: atan2(ρi, zi), atan2(ρh, zh), atan2(cross, dot).
  const __m128 ay = _mm_sqrt_ps(_mm_set_ps(0.0f, static_cast<float>(cross * cross),
                                           static_cast<float>(rho2_h), static_cast<float>(rho2_i)));
  const __m128 x =
      _mm_set_ps(1.0f, static_cast<float>(dot), static_cast<float>(h.z), static_cast<float>(wi.z));
  const __m128 sign_mask = _mm_set1_ps(-0.0f), one = _mm_set1_ps(1.0f);
  const __m128 ax = _mm_andnot_ps(sign_mask, x);
  const __m128 lo = _mm_min_ps(ay, ax), hi = _mm_max_ps(ay, ax);
  const __m128 reduced = _mm_and_ps(
      _mm_cmpgt_ps(lo, _mm_mul_ps(_mm_set1_ps(static_cast<float>(kTanPiOver8)), hi)), one);
  const __m128 swapped = _mm_and_ps(_mm_cmpgt_ps(ay, ax), one);
  const __m128 negative_x = _mm_and_ps(_mm_cmplt_ps(x, _mm_setzero_ps()), one);
  const __m128 t =
      _mm_div_ps(_mm_sub_ps(lo, _mm_mul_ps(reduced, hi)), _mm_add_ps(hi, _mm_mul_ps(reduced, lo)));
  const __m128 w = _mm_mul_ps(t, t);
  __m128 poly = _mm_set1_ps(0.086736299f);
  poly = _mm_add_ps(_mm_mul_ps(poly, w), _mm_set1_ps(-0.140584603f));
  poly = _mm_add_ps(_mm_mul_ps(poly, w), _mm_set1_ps(0.199930921f));
  poly = _mm_add_ps(_mm_mul_ps(poly, w), _mm_set1_ps(-0.333333015f));
  __m128 r = _mm_add_ps(_mm_mul_ps(reduced, _mm_set1_ps(static_cast<float>(0.25 * kPi))),
                        _mm_add_ps(t, _mm_mul_ps(_mm_mul_ps(t, w), poly)));
  const __m128 two = _mm_set1_ps(2.0f);
  r = _mm_add_ps(_mm_mul_ps(swapped, _mm_set1_ps(static_cast<float>(0.5 * kPi))),
                 _mm_mul_ps(_mm_sub_ps(one, _mm_mul_ps(two, swapped)), r));
  r = _mm_add_ps(_mm_mul_ps(negative_x, _mm_set1_ps(static_cast<float>(kPi))),
                 _mm_mul_ps(_mm_sub_ps(one, _mm_mul_ps(two, negative_x)), r));
  const __m128 u = _mm_sqrt_ps(_mm_mul_ps(r, _mm_set1_ps(static_cast<float>(2.0 / kPi))));
  alignas(16) float angle[4], unit[4];
  _mm_store_ps(angle, r);
  _mm_store_ps(unit, u);
  const double phi = cross < 0.0 ? -static_cast<double>(angle[2]) : angle[2];
  out = {angle[0], unit[0], 0.0, unit[1], RelativePhiToU(phi)};
  return true;
#endif
}

}  // namespace brdf::detail

namespace brdf {

struct RglBrdf::Tables {
  RglInfo info;
  std::vector<double> theta_i, phi_i, theta_i_inv_step, phi_i_inv_step;
  detail::Interpolant2 ndf, sigma;
  // VNDF warp of each slice s = p·T + t (vx × vy vertices), normalised so that the bilinear
  // density integrates to 1 over the index domain, as the reference does. `warp` interleaves,
  // per vertex, the density and the conditional CDF (the row's running integral along x);
  // `rows` holds, per row, the row's total and the marginal CDF along y. Double precision:
  // with float tables the ratio X = C / row_total loses ~1e-4 relative at grazing angles.
  int vx = 0, vy = 0;
  std::vector<double> warp, rows;
  // RGB of each slice, [y][x][channel].
  int rx = 0, ry = 0;
  std::vector<float> rgb;
  // Isotropic with one phi_i and a sigma table that does not vary with φ: φi itself is then
  // never needed, only φm − φi, which takes one atan2 instead of two.
  bool relative_phi_only = false;

  detail::Corners SlicesFor(double phi_i_rad, double theta_i_rad) const {
    detail::Corners c;
    int ip, it;
    double wp, wt;
    detail::Interval(phi_i, phi_i_inv_step, phi_i_rad, ip, wp);
    detail::Interval(theta_i, theta_i_inv_step, theta_i_rad, it, wt);
    const std::size_t t_count = theta_i.size();
    const int np = phi_i.size() == 1 ? 1 : 2, nt = theta_i.size() == 1 ? 1 : 2;
    for (int a = 0; a < np; ++a) {
      for (int b = 0; b < nt; ++b) {
        c.slice[c.n] =
            static_cast<std::size_t>(ip + a) * t_count + static_cast<std::size_t>(it + b);
        c.w[c.n] = (np == 1 ? 1.0 : (a ? wp : 1 - wp)) * (nt == 1 ? 1.0 : (b ? wt : 1 - wt));
        ++c.n;
      }
    }
    return c;
  }

  // The inverse of the VNDF warp: the warped-space position of the half vector whose unit
  // square coordinates are (ux = u(θm), uy = u(φm)). Y is the marginal CDF of the bilinear
  // density at uy; X is the conditional CDF along x at that height. Both are linear in the
  // slice data, so the nine quantities are blended over slices first.
  void InvertWarp(double ux, double uy, const detail::Corners& c, double& x_out,
                  double& y_out) const {
    const detail::Cell cx = detail::Locate(ux, vx), cy = detail::Locate(uy, vy);
    const std::size_t slice_size = static_cast<std::size_t>(vx) * vy;
    const std::size_t cell = 2 * (static_cast<std::size_t>(cy.i) * vx + cx.i);
    const std::size_t row_stride = 2 * static_cast<std::size_t>(vx);
    double v00 = 0, v10 = 0, v01 = 0, v11 = 0, c0 = 0, c1 = 0, r0 = 0, r1 = 0, m = 0;
    for (int k = 0; k < c.n; ++k) {
      const double w = c.w[k];
      const double* p = warp.data() + 2 * c.slice[k] * slice_size + cell;
      const double* q = rows.data() + 2 * (c.slice[k] * vy + static_cast<std::size_t>(cy.i));
      v00 += w * p[0];
      c0 += w * p[1];
      v10 += w * p[2];
      v01 += w * p[row_stride];
      c1 += w * p[row_stride + 1];
      v11 += w * p[row_stride + 2];
      r0 += w * q[0];
      m += w * q[1];
      r1 += w * q[2];
    }
    const double fx = cx.f, fy = cy.f;
    const double a0 = (1 - fy) * v00 + fy * v01;  // density along the row at height fy
    const double a1 = (1 - fy) * v10 + fy * v11;
    const double x = fx * (a0 + 0.5 * fx * (a1 - a0)) + (1 - fy) * c0 + fy * c1;
    const double row_total = (1 - fy) * r0 + fy * r1;
    // A row without mass is never reached by the forward warp (only the θi = 90° slice has
    // such rows, and ωi above the horizon never gives it the full weight); pin X to 0 there.
    x_out = row_total > 0 ? detail::Clamp01(x / row_total) : 0.0;
    y_out = detail::Clamp01(fy * (r0 + 0.5 * fy * (r1 - r0)) + m);
  }

  Rgb InterpolateRgb(double sx, double sy, const detail::Corners& c) const {
    const detail::Cell cx = detail::Locate(sx, rx), cy = detail::Locate(sy, ry);
    const std::size_t slice_size = static_cast<std::size_t>(rx) * ry * 3;
    const std::size_t cell = (static_cast<std::size_t>(cy.i) * rx + cx.i) * 3;
    const std::size_t row = static_cast<std::size_t>(rx) * 3;
    const double fx = cx.f, fy = cy.f;
    double r = 0, g = 0, b = 0;
    for (int k = 0; k < c.n; ++k) {
      const float* p = rgb.data() + c.slice[k] * slice_size + cell;
      const double w00 = c.w[k] * (1 - fx) * (1 - fy), w10 = c.w[k] * fx * (1 - fy);
      const double w01 = c.w[k] * (1 - fx) * fy, w11 = c.w[k] * fx * fy;
      r += w00 * p[0] + w10 * p[3] + w01 * p[row] + w11 * p[row + 3];
      g += w00 * p[1] + w10 * p[4] + w01 * p[row + 1] + w11 * p[row + 4];
      b += w00 * p[2] + w10 * p[5] + w01 * p[row + 2] + w11 * p[row + 5];
    }
    // Negative values come from out-of-gamut spectra; the reference loader clips them.
    return {r > 0.0 ? r : 0.0, g > 0.0 ? g : 0.0, b > 0.0 ? b : 0.0};
  }

  // f_r·cosθo, divided by cosθo when `divide_by_cos` (then f_r): one division serves both
  // that and the 1/(4σ) of the jacobian.
  Rgb EvalCosine(const Vec3& wi, const Vec3& wo, bool divide_by_cos) const {
    detail::PairCoordinates p;
    if (!detail::Coordinates(wi, wo, relative_phi_only, info.isotropic, p)) return {0.0, 0.0, 0.0};
    const double phi_i_rad = p.phi_i_rad, um_x = p.um_x, um_y = p.um_y;
    const detail::Corners c = SlicesFor(phi_i_rad, p.theta_i_rad);
    double sx, sy;
    InvertWarp(um_x, um_y, c, sx, sy);
    Rgb f = InterpolateRgb(sx, sy, c);
    if (info.jacobian) {
      const double area = 4.0 * sigma.Eval(p.u_i, detail::PhiToU(phi_i_rad));
      const double scale = ndf.Eval(um_x, um_y) / (divide_by_cos ? area * wo.z : area);
      for (double& v : f) v *= scale;
    } else if (divide_by_cos) {
      const double inv = 1.0 / wo.z;
      for (double& v : f) v *= inv;
    }
    return f;
  }
};

}  // namespace brdf
