// RGL `.bsdf` evaluation (Dupuy & Jakob 2018): see brdf/core/rgl.h for the algorithm.
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
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "brdf/core/error.h"
#include "brdf/core/parallel.h"
#include "brdf/core/rgl.h"
#include "readers/rgl_internal.h"

namespace brdf {
namespace {

// Table dimensions are stored as int; real files use at most a few hundred.
constexpr std::uint64_t kMaxDimension = 1u << 16;
// Largest magnitude accepted in any table (real files stay below 1e5). With it, every
// product the evaluator forms (rgb · ndf / 4σ, σ ≥ the smallest float) stays finite in double.
constexpr double kMaxMagnitude = 1e30;

std::string Quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string FieldPosition(const TensorField& f) {
  return BytePosition(f.header_offset) + " (header of field " + Quoted(f.name) + ")";
}

std::string IndexString(const std::vector<std::uint64_t>& shape, std::uint64_t flat) {
  std::vector<std::uint64_t> idx(shape.size());
  for (std::size_t d = shape.size(); d-- > 0;) {
    idx[d] = shape[d] == 0 ? 0 : flat % shape[d];
    flat = shape[d] == 0 ? 0 : flat / shape[d];
  }
  std::string s = "[";
  for (std::size_t d = 0; d < idx.size(); ++d) s += (d ? ", " : "") + std::to_string(idx[d]);
  return s + "]";
}

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
constexpr double kAtanCoefficients[9] = {
    -0.33333333333256443, 0.19999999982070268,  -0.14285712838546033,
    0.11111053452336944,  -0.09089599958686255, 0.07674177368739588,
    -0.0650947129124945,  0.050351028123015215, -0.025445275546824294};
constexpr double kTanPiOver8 = 0.41421356237309503;

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

}  // namespace

struct RglBrdf::Tables {
  RglInfo info;
  std::vector<double> theta_i, phi_i, theta_i_inv_step, phi_i_inv_step;
  Interpolant2 ndf, sigma;
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

  Corners SlicesFor(double phi_i_rad, double theta_i_rad) const {
    Corners c;
    int ip, it;
    double wp, wt;
    Interval(phi_i, phi_i_inv_step, phi_i_rad, ip, wp);
    Interval(theta_i, theta_i_inv_step, theta_i_rad, it, wt);
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
  void InvertWarp(double ux, double uy, const Corners& c, double& x_out, double& y_out) const {
    const Cell cx = Locate(ux, vx), cy = Locate(uy, vy);
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
    x_out = row_total > 0 ? Clamp01(x / row_total) : 0.0;
    y_out = Clamp01(fy * (r0 + 0.5 * fy * (r1 - r0)) + m);
  }

  Rgb InterpolateRgb(double sx, double sy, const Corners& c) const {
    const Cell cx = Locate(sx, rx), cy = Locate(sy, ry);
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
    PairCoordinates p;
    if (!Coordinates(wi, wo, relative_phi_only, info.isotropic, p)) return {0.0, 0.0, 0.0};
    const double phi_i_rad = p.phi_i_rad, um_x = p.um_x, um_y = p.um_y;
    const Corners c = SlicesFor(phi_i_rad, p.theta_i_rad);
    double sx, sy;
    InvertWarp(um_x, um_y, c, sx, sy);
    Rgb f = InterpolateRgb(sx, sy, c);
    if (info.jacobian) {
      const double area = 4.0 * sigma.Eval(p.u_i, PhiToU(phi_i_rad));
      const double scale = ndf.Eval(um_x, um_y) / (divide_by_cos ? area * wo.z : area);
      for (double& v : f) v *= scale;
    } else if (divide_by_cos) {
      const double inv = 1.0 / wo.z;
      for (double& v : f) v *= inv;
    }
    return f;
  }
};

namespace {

// Field checks shared by every field the evaluator reads.
class FieldChecker {
 public:
  explicit FieldChecker(const TensorFile& tf) : tf_(tf) {}

  const TensorField& Get(std::string_view name, TensorDtype dtype, std::size_t rank,
                         std::string_view meaning) const {
    const TensorField& f = tf_.Require(name);
    if (f.dtype != dtype || f.shape.size() != rank)
      throw FormatError(tf_.file(), FieldPosition(f),
                        "field " + Quoted(name) + " (" + std::string(meaning) + ") of " +
                            TensorDtypeName(dtype) + " with rank " + std::to_string(rank),
                        TensorDtypeName(f.dtype) + " with shape " + f.ShapeString());
    for (std::size_t d = 0; d < rank; ++d)
      if (f.shape[d] == 0 || f.shape[d] > kMaxDimension)
        throw FormatError(
            tf_.file(), FieldPosition(f),
            "field " + Quoted(name) + " dimensions between 1 and " + std::to_string(kMaxDimension),
            "shape " + f.ShapeString());
    return f;
  }

  void Shape(const TensorField& f, const std::vector<std::uint64_t>& expected,
             std::string_view meaning) const {
    if (f.shape != expected) {
      TensorField e;
      e.shape = expected;
      throw FormatError(tf_.file(), FieldPosition(f),
                        "field " + Quoted(f.name) + " of shape " + e.ShapeString() + " (" +
                            std::string(meaning) + ")",
                        "shape " + f.ShapeString());
    }
  }

  void AtLeast(const TensorField& f, std::size_t dim, std::uint64_t min,
               std::string_view meaning) const {
    if (f.shape[dim] < min)
      throw FormatError(tf_.file(), FieldPosition(f),
                        "field " + Quoted(f.name) + " dimension " + std::to_string(dim) +
                            " >= " + std::to_string(min) + " (" + std::string(meaning) + ")",
                        "shape " + f.ShapeString());
  }

  // Every element finite and satisfying `ok`; the first offender is named by byte and index.
  template <class Pred>
  std::vector<float> Values(const TensorField& f, Pred ok, std::string_view requirement) const {
    std::vector<float> v = tf_.Float32(f);
    for (std::size_t k = 0; k < v.size(); ++k) {
      const bool absurd = std::isfinite(v[k]) && std::abs(v[k]) > kMaxMagnitude;
      if (!std::isfinite(v[k]) || absurd || !ok(v[k]))
        throw FormatError(tf_.file(),
                          BytePosition(f.data_offset + 4 * k) + " (field " + Quoted(f.name) +
                              " element " + IndexString(f.shape, k) + ")",
                          absurd ? "a magnitude of at most 1e30" : std::string(requirement),
                          FormatValue(v[k]));
    }
    return v;
  }

  static std::string FormatValue(float v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    return buf;
  }

  const TensorFile& tf() const { return tf_; }

 private:
  const TensorFile& tf_;
};

std::vector<double> StrictlyIncreasing(const FieldChecker& ck, const TensorField& f,
                                       std::string_view unit) {
  const std::vector<float> v = ck.Values(
      f, [](float) { return true; }, "finite " + std::string(unit));
  for (std::size_t k = 1; k < v.size(); ++k)
    if (!(v[k] > v[k - 1]))
      throw FormatError(
          ck.tf().file(),
          BytePosition(f.data_offset + 4 * k) + " (field " + Quoted(f.name) + " element " +
              std::to_string(k) + ")",
          "values increasing strictly (previous " + FieldChecker::FormatValue(v[k - 1]) + ")",
          FieldChecker::FormatValue(v[k]));
  return {v.begin(), v.end()};
}

}  // namespace

RglBrdf::RglBrdf(std::unique_ptr<Tables> tables, std::string name)
    : tables_(std::move(tables)), name_(std::move(name)) {}
RglBrdf::RglBrdf(RglBrdf&&) noexcept = default;
RglBrdf& RglBrdf::operator=(RglBrdf&&) noexcept = default;
RglBrdf::~RglBrdf() = default;

const RglInfo& RglBrdf::info() const { return tables_->info; }

Rgb RglBrdf::EvalCosine(const Vec3& wi, const Vec3& wo) const {
  return tables_->EvalCosine(wi, wo, false);
}

Rgb RglBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  return tables_->EvalCosine(wi, wo, true);
}

RglBrdf RglBrdf::Load(const std::string& path) {
  return FromTensorFile(TensorFile::Read(path), std::filesystem::path(path).filename().string());
}

RglBrdf RglBrdf::FromTensorFile(const TensorFile& tf, std::string name) {
  const FieldChecker ck(tf);
  auto t = std::make_unique<Tables>();
  RglInfo& info = t->info;

  if (const TensorField* d = tf.Find("description")) {
    if (d->dtype != TensorDtype::kUInt8 || d->shape.size() != 1)
      throw FormatError(tf.file(), FieldPosition(*d),
                        "field 'description' of uint8 with rank 1 (UTF-8 text)",
                        TensorDtypeName(d->dtype) + " with shape " + d->ShapeString());
    const auto bytes = tf.Data(*d);
    info.description.assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (!IsValidUtf8(info.description))
      throw FormatError(tf.file(), BytePosition(d->data_offset) + " (field 'description')",
                        "UTF-8 text", "invalid UTF-8 bytes");
  }

  const TensorField& phi_f = ck.Get("phi_i", TensorDtype::kFloat32, 1, "incidence azimuths, rad");
  const TensorField& theta_f =
      ck.Get("theta_i", TensorDtype::kFloat32, 1, "incidence elevations, rad");
  t->phi_i = StrictlyIncreasing(ck, phi_f, "azimuths in radians");
  t->theta_i = StrictlyIncreasing(ck, theta_f, "elevations in radians");
  const std::uint64_t np = t->phi_i.size(), nt = t->theta_i.size();
  for (auto [grid, inv] :
       {std::pair{&t->phi_i, &t->phi_i_inv_step}, std::pair{&t->theta_i, &t->theta_i_inv_step}})
    for (std::size_t k = 0; k + 1 < grid->size(); ++k)
      inv->push_back(1.0 / ((*grid)[k + 1] - (*grid)[k]));
  info.phi_i_rad = t->phi_i;
  info.theta_i_rad = t->theta_i;
  info.isotropic = np <= 2;
  if (!info.isotropic) {
    // The reference loader evaluates anisotropic files only when phi_i spans the full
    // circle; files reduced by symmetry (a half or a quarter) need mirroring it does not do.
    const double span = t->phi_i.back() - t->phi_i.front();
    const double reduction = std::rint(2.0 * kPi / span);
    if (reduction != 1.0)
      throw FormatError(tf.file(), FieldPosition(phi_f),
                        "phi_i covering the full circle (symmetry reduction 1)",
                        "a span of " + std::to_string(span) + " rad (reduction " +
                            std::to_string(reduction) + ")",
                        "reduced anisotropic files are not supported");
  }

  const TensorField& jac_f = ck.Get("jacobian", TensorDtype::kUInt8, 1, "flag");
  ck.Shape(jac_f, {1}, "one flag byte");
  info.jacobian = tf.Data(jac_f)[0] != 0;

  auto interpolant = [&](std::string_view field, std::string_view meaning, auto pred,
                         std::string_view requirement) {
    const TensorField& f = ck.Get(field, TensorDtype::kFloat32, 2, meaning);
    ck.AtLeast(f, 0, 2, "vertices along u(phi)");
    ck.AtLeast(f, 1, 2, "vertices along u(theta)");
    Interpolant2 out;
    out.ny = static_cast<int>(f.shape[0]);
    out.nx = static_cast<int>(f.shape[1]);
    out.v = ck.Values(f, pred, requirement);
    return out;
  };
  t->ndf = interpolant(
      "ndf", "microfacet normal distribution", [](float v) { return v >= 0; },
      "a finite NDF value >= 0");
  t->sigma = interpolant(
      "sigma", "projected microfacet area", [](float v) { return v > 0; },
      "a finite projected area > 0 (it divides)");

  const TensorField& vndf_f = ck.Get("vndf", TensorDtype::kFloat32, 4, "visible normal density");
  ck.Shape(vndf_f, {np, nt, vndf_f.shape[2], vndf_f.shape[3]},
           "[phi_i, theta_i, u(phi), u(theta)]");
  ck.AtLeast(vndf_f, 2, 2, "vertices along u(phi)");
  ck.AtLeast(vndf_f, 3, 2, "vertices along u(theta)");
  t->vy = static_cast<int>(vndf_f.shape[2]);
  t->vx = static_cast<int>(vndf_f.shape[3]);
  const std::vector<float> density = ck.Values(
      vndf_f, [](float x) { return x >= 0; }, "a finite density >= 0");

  const TensorField& rgb_f = ck.Get("rgb", TensorDtype::kFloat32, 5, "reflectance");
  ck.Shape(rgb_f, {np, nt, 3, rgb_f.shape[3], rgb_f.shape[4]},
           "[phi_i, theta_i, 3 channels, y, x]");
  ck.AtLeast(rgb_f, 3, 2, "vertices along y");
  ck.AtLeast(rgb_f, 4, 2, "vertices along x");
  t->ry = static_cast<int>(rgb_f.shape[3]);
  t->rx = static_cast<int>(rgb_f.shape[4]);
  const std::vector<float> planar = ck.Values(
      rgb_f, [](float) { return true; }, "a finite value");
  info.rgb_res = t->rx;
  info.rgb_values = planar.size();
  for (const float v : planar) info.negative_rgb_values += v < 0 ? 1 : 0;

  if (const TensorField* lum = tf.Find("luminance")) {
    // Only used for importance sampling, which we do not do; checked because the reference
    // loader requires it to match the RGB table.
    if (lum->dtype != TensorDtype::kFloat32 ||
        lum->shape != std::vector<std::uint64_t>{np, nt, rgb_f.shape[3], rgb_f.shape[4]})
      throw FormatError(tf.file(), FieldPosition(*lum),
                        "field 'luminance' of float32 with shape [phi_i, theta_i, y, x] = [" +
                            std::to_string(np) + ", " + std::to_string(nt) + ", " +
                            std::to_string(rgb_f.shape[3]) + ", " + std::to_string(rgb_f.shape[4]) +
                            "]",
                        TensorDtypeName(lum->dtype) + " with shape " + lum->ShapeString());
  }

  // Interleave the channels: [slice][c][y][x] -> [slice][y][x][c].
  const std::size_t slices = np * nt;
  const std::size_t plane = static_cast<std::size_t>(t->rx) * t->ry;
  t->rgb.resize(planar.size());
  for (std::size_t s = 0; s < slices; ++s)
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < plane; ++i)
        t->rgb[(s * plane + i) * 3 + c] = planar[(s * 3 + c) * plane + i];

  // Normalise each VNDF slice and tabulate its CDFs (running sums in double).
  const std::size_t vx = t->vx, vy = t->vy, slice_size = vx * vy;
  t->warp.assign(2 * density.size(), 0.0);
  t->rows.assign(2 * slices * vy, 0.0);
  std::vector<double> row_cum(slice_size), marg_cum(vy);
  for (std::size_t s = 0; s < slices; ++s) {
    const float* d = density.data() + s * slice_size;
    for (std::size_t y = 0; y < vy; ++y) {
      double sum = 0.0;
      row_cum[y * vx] = 0.0;
      for (std::size_t x = 0; x + 1 < vx; ++x) {
        sum += 0.5 * (static_cast<double>(d[y * vx + x]) + d[y * vx + x + 1]);
        row_cum[y * vx + x + 1] = sum;
      }
    }
    double sum = 0.0;
    marg_cum[0] = 0.0;
    for (std::size_t y = 0; y + 1 < vy; ++y) {
      sum += 0.5 * (row_cum[y * vx + vx - 1] + row_cum[(y + 1) * vx + vx - 1]);
      marg_cum[y + 1] = sum;
    }
    if (!(sum > 0.0) || !std::isfinite(sum))
      throw FormatError(
          tf.file(),
          BytePosition(vndf_f.data_offset + 4 * s * slice_size) + " (field 'vndf' slice " +
              IndexString({np, nt}, static_cast<std::uint64_t>(s)) + ")",
          "a visible normal density with positive total mass", "total " + std::to_string(sum));
    const double norm = 1.0 / sum;
    double* w = t->warp.data() + 2 * s * slice_size;
    for (std::size_t i = 0; i < slice_size; ++i) {
      w[2 * i] = d[i] * norm;
      w[2 * i + 1] = row_cum[i] * norm;
    }
    double* r = t->rows.data() + 2 * s * vy;
    for (std::size_t y = 0; y < vy; ++y) {
      r[2 * y] = row_cum[y * vx + vx - 1] * norm;
      r[2 * y + 1] = marg_cum[y] * norm;
    }
  }
  bool sigma_same_for_all_phi = true;
  for (int y = 1; y < t->sigma.ny; ++y)
    for (int x = 0; x < t->sigma.nx; ++x)
      sigma_same_for_all_phi &=
          t->sigma.v[static_cast<std::size_t>(y) * t->sigma.nx + x] == t->sigma.v[x];
  t->relative_phi_only = info.isotropic && np == 1 && sigma_same_for_all_phi;
  info.vndf_theta_res = t->vx;
  info.vndf_phi_res = t->vy;
  return RglBrdf(std::move(t), std::move(name));
}

// The tabulated form (rgl.h, RglTabulatedBrdf).
//
// Incidence: interval j of theta_i holds K_j slots (incidence samples) at weights m/K_j
// (m = 0 … K_j − 1) of the way from theta_i[j] to theta_i[j + 1]; the last node is the final
// slot. So the slots blend as RglBrdf's slices do and every node is a slot.
// u(θm) and u(φm − φi): VNDF cell k (between vertices k and k + 1) holds cells[k] table cells of
// equal width, starting at table vertex offset[k] (TableAxis), more where the warp is steep.
// Storage: vertex (x, y) of slot s holds R, G, B as 16-bit fractions of the slot's per-channel
// maximum `scale[4 s + ch]` (scale[4 s + 3] = 0), at texel ((s·ny + y)·nx + x), 6 bytes each: a
// lookup's two x-neighbours are 12 contiguous bytes, and a real file's table a few MB.
namespace {

// One axis of the table: the VNDF grid's `n` even vertices over [0, 1], cell k split into
// cells[k] equal table cells starting at table vertex offset[k].
struct TableAxis {
  int n = 0, vertices = 0;
  std::vector<double> offset, cells;

  // Table cells per VNDF cell from `rate` (how many RGB cells the warped coordinate crosses in
  // each VNDF cell), as RglTabulationSettings says.
  static TableAxis FromRates(const std::vector<double>& rate, double cells_per_rgb_cell,
                             int max_cells) {
    TableAxis a;
    a.n = static_cast<int>(rate.size()) + 1;
    double total = 0.0;
    for (const double r : rate) {
      const double wanted = std::ceil(r * cells_per_rgb_cell - 1e-9);
      const double c = std::clamp(wanted, 1.0, static_cast<double>(max_cells));
      a.offset.push_back(total);
      a.cells.push_back(c);
      total += c;
    }
    a.vertices = static_cast<int>(total) + 1;
    return a;
  }
  // The unit-square coordinate of every table vertex.
  std::vector<double> Positions() const {
    std::vector<double> u(static_cast<std::size_t>(vertices));
    for (std::size_t k = 0; k < cells.size(); ++k)
      for (int i = 0; i <= static_cast<int>(cells[k]); ++i)
        u[static_cast<std::size_t>(offset[k]) + i] =
            (static_cast<double>(k) + i / cells[k]) / static_cast<double>(n - 1);
    return u;
  }
  Cell Map(double u) const {
    const Cell c = Locate(u, n);
    const double t = offset[c.i] + cells[c.i] * c.f;
    const int i = std::min(static_cast<int>(t), vertices - 2);
    return {i, t - i};
  }
};

}  // namespace

struct RglTabulatedBrdf::Table {
  // Per incidence sample: θi (rad) and 1 / (distance to the next; 0 for the last). bin_slot[b]:
  // the last sample at or below slot_theta[0] + b / bins_per_rad.
  std::vector<double> slot_theta, slot_inv_step;
  std::vector<std::uint16_t> bin_slot;
  double bins_per_rad = 0.0;
  TableAxis ax, ay;  // along u(θm) and u(φm − φi)
  int slots = 1, nx = 0, ny = 0;
  std::vector<std::uint16_t> texels;
  std::vector<float> scale;
  Interpolant2 ndf;
  bool ndf_same_for_all_phi = false;  // then its first row alone is looked up
  double self_check_p99 = 0.0;
  bool jacobian = true;

  Rgb EvalCosine(const Vec3& wi, const Vec3& wo, bool divide_by_cos) const {
    PairCoordinates p;
    if (!CoordinatesSingle(wi, wo, p)) return {0.0, 0.0, 0.0};
    // The incidence sample at or below θi: from the bin of θi, then at most a step or two up
    // (bins are no wider than the closest two samples, so usually none).
    const double theta = p.theta_i_rad;
    const double bin_position = (theta - slot_theta[0]) * bins_per_rad;
    const int bin =
        std::clamp(static_cast<int>(bin_position), 0, static_cast<int>(bin_slot.size()) - 1);
    int s0 = bin_slot[static_cast<std::size_t>(bin)];
    while (s0 + 2 < slots && theta >= slot_theta[static_cast<std::size_t>(s0) + 1]) ++s0;
    const int s1 = std::min(s0 + 1, slots - 1);
    const double ft = Clamp01((theta - slot_theta[static_cast<std::size_t>(s0)]) *
                              slot_inv_step[static_cast<std::size_t>(s0)]);
    const Cell cx = ax.Map(p.um_x), cy = ay.Map(p.um_y);
    const double fx = cx.f;
    const std::size_t row = 3 * static_cast<std::size_t>(nx);
    const std::size_t at =
        row * static_cast<std::size_t>(cy.i) + 3 * static_cast<std::size_t>(cx.i);
    const std::uint16_t* t0 = texels.data() + row * ny * static_cast<std::size_t>(s0) + at;
    const std::uint16_t* t1 = texels.data() + row * ny * static_cast<std::size_t>(s1) + at;
    const float w00 = static_cast<float>((1 - fx) * (1 - cy.f)),
                w10 = static_cast<float>(fx * (1 - cy.f)),
                w01 = static_cast<float>((1 - fx) * cy.f), w11 = static_cast<float>(fx * cy.f);
    Rgb f;
#if defined(__SSE2__)
    // Three 16-bit channels per vertex: one 8-byte load each (its fourth lane, the next
    // vertex's R or the tail pad, is multiplied by the scale's 0), widened to float.
    const __m128i zero = _mm_setzero_si128();
    auto texel = [&](const std::uint16_t* q) {
      return _mm_cvtepi32_ps(
          _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q)), zero));
    };
    auto corners = [&](const std::uint16_t* q, int slot, double weight) {
      __m128 a = _mm_mul_ps(texel(q), _mm_set1_ps(w00));
      a = _mm_add_ps(a, _mm_mul_ps(texel(q + 3), _mm_set1_ps(w10)));
      a = _mm_add_ps(a, _mm_mul_ps(texel(q + row), _mm_set1_ps(w01)));
      a = _mm_add_ps(a, _mm_mul_ps(texel(q + row + 3), _mm_set1_ps(w11)));
      return _mm_mul_ps(a, _mm_mul_ps(_mm_loadu_ps(scale.data() + 4 * slot),
                                      _mm_set1_ps(static_cast<float>(weight))));
    };
    alignas(16) float out[4];
    _mm_store_ps(out, _mm_add_ps(corners(t0, s0, 1 - ft), corners(t1, s1, ft)));
    for (int ch = 0; ch < 3; ++ch) f[ch] = out[ch];
#else
    for (int ch = 0; ch < 3; ++ch) {
      auto corners = [&](const std::uint16_t* q, int slot) {
        return (w00 * q[ch] + w10 * q[3 + ch] + w01 * q[row + ch] + w11 * q[row + 3 + ch]) *
               static_cast<double>(scale[4 * slot + ch]);
      };
      f[ch] = (1 - ft) * corners(t0, s0) + ft * corners(t1, s1);
    }
#endif
    // The slot scales hold 1 / 4σ; what is left of rgl.h's step 3 is ndf(u_m) [/ cosθo].
    double factor = 1.0;
    if (jacobian) {
      if (ndf_same_for_all_phi) {
        const Cell cn = Locate(p.um_x, ndf.nx);
        factor = (1 - cn.f) * ndf.v[cn.i] + cn.f * ndf.v[cn.i + 1];
      } else {
        factor = ndf.Eval(p.um_x, p.um_y);
      }
    }
    if (divide_by_cos) factor /= wo.z;
    for (double& v : f) v *= factor;
    return f;
  }
};

RglTabulatedBrdf::RglTabulatedBrdf(std::unique_ptr<Table> table, std::string name)
    : table_(std::move(table)), name_(std::move(name)) {}
RglTabulatedBrdf::RglTabulatedBrdf(RglTabulatedBrdf&&) noexcept = default;
RglTabulatedBrdf& RglTabulatedBrdf::operator=(RglTabulatedBrdf&&) noexcept = default;
RglTabulatedBrdf::~RglTabulatedBrdf() = default;

Rgb RglTabulatedBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  return table_->EvalCosine(wi, wo, true);
}
Rgb RglTabulatedBrdf::EvalCosine(const Vec3& wi, const Vec3& wo) const {
  return table_->EvalCosine(wi, wo, false);
}
std::size_t RglTabulatedBrdf::table_bytes() const {
  return table_->texels.size() * sizeof(std::uint16_t) + table_->scale.size() * sizeof(float);
}
int RglTabulatedBrdf::incidence_samples() const { return table_->slots; }
int RglTabulatedBrdf::vertices_theta() const { return table_->nx; }
int RglTabulatedBrdf::vertices_phi() const { return table_->ny; }
double RglTabulatedBrdf::self_check_p99_error() const { return table_->self_check_p99; }

namespace {

// RglTabulatedBrdf::self_check_p99_error: the table against the exact evaluator at fixed
// pseudo-random pairs (SplitMix64, so every build checks the same pairs).
double SelfCheckP99(const RglBrdf& exact, const RglTabulatedBrdf& table) {
  std::uint64_t state = 0x5eed5eed12345678ull;
  auto next = [&] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  constexpr int kPairs = 16384;
  std::vector<std::array<double, 6>> values;  // exact, tabulated per channel
  values.reserve(kPairs);
  std::array<double, 3> peak{0, 0, 0};
  for (int k = 0; k < kPairs; ++k) {
    const double theta_i = std::acos(std::sqrt(1.0 - next())), phi_i = 2 * kPi * next();
    const Vec3 wi = SphericalDirection(theta_i, phi_i);
    Vec3 wo;
    if (k % 2 == 0) {
      wo = SphericalDirection(std::acos(std::sqrt(1.0 - next())), 2 * kPi * next());
    } else {  // within ±4° (uniform) of the mirror direction in θ and φ
      const double spread = 4.0 * kPi / 180.0;
      const double theta_o = std::abs(theta_i + spread * (2 * next() - 1));
      wo = SphericalDirection(std::min(theta_o, 0.5 * kPi - 1e-3),
                              phi_i + kPi + spread * (2 * next() - 1));
    }
    const Rgb a = exact.EvalCosine(wi, wo), b = table.EvalCosine(wi, wo);
    values.push_back({a[0], a[1], a[2], b[0], b[1], b[2]});
    for (int ch = 0; ch < 3; ++ch) peak[ch] = std::max(peak[ch], a[ch]);
  }
  std::vector<double> rel;
  for (const auto& v : values)
    for (int ch = 0; ch < 3; ++ch)
      if (v[ch] > 0.0 && v[ch] >= 0.01 * peak[ch])
        rel.push_back(std::abs(v[3 + ch] - v[ch]) / v[ch]);
  if (rel.empty()) return 0.0;
  const std::size_t at = rel.size() * 99 / 100;
  std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(at), rel.end());
  return rel[at];
}

}  // namespace

std::unique_ptr<RglTabulatedBrdf> RglBrdf::Tabulate(const RglTabulationSettings& settings) const {
  const RglTabulationSettings& o = settings;
  if (!(o.incidence_tolerance > 0.0) || !(o.cells_per_rgb_cell > 0.0) ||
      !std::isfinite(o.incidence_tolerance + o.cells_per_rgb_cell) ||
      o.max_samples_per_interval < 1 || o.max_samples_per_interval > 64 ||
      o.max_cells_per_vndf_cell < 1 || o.max_cells_per_vndf_cell > 64)
    throw InvalidArgument(
        "RGL tabulation: the incidence tolerance and cells per RGB cell must be finite and > 0, "
        "the largest samples per interval and cells per VNDF cell between 1 and 64");
  const Tables& e = *tables_;
  if (!e.relative_phi_only) return nullptr;
  auto t = std::make_unique<RglTabulatedBrdf::Table>();
  t->ndf = e.ndf;
  t->ndf_same_for_all_phi = true;
  for (int y = 1; y < e.ndf.ny; ++y)
    for (int x = 0; x < e.ndf.nx; ++x)
      t->ndf_same_for_all_phi &= e.ndf.v[static_cast<std::size_t>(y) * e.ndf.nx + x] == e.ndf.v[x];
  t->jacobian = e.info.jacobian;
  // Table cells per VNDF cell. Along u(θm): X, the conditional CDF the RGB table is indexed
  // by, changes by density / row total per VNDF cell (the warp tables are normalised over the
  // index domain). Along u(φm): Y, the marginal CDF, changes by the row total, and X at a
  // given u(θm) by the difference of the two rows' conditional CDFs (large between rows of
  // little mass, e.g. half vectors facing away from a grazing ωi; this term costs 8–40 % more
  // table and takes the preview of cc_ibiza_sunset from 0.61 to 0.57 % RMS). Each rate is the
  // largest over slices (and rows or columns), in RGB cells.
  const std::size_t vx = e.vx, vy = e.vy, slices = e.theta_i.size();
  std::vector<double> rate_x(vx - 1, 0.0), rate_y(vy - 1, 0.0);
  for (std::size_t sl = 0; sl < slices; ++sl)
    for (std::size_t y = 0; y < vy; ++y) {
      const double total = e.rows[2 * (sl * vy + y)];
      if (y + 1 < vy)
        rate_y[y] =
            std::max(rate_y[y], std::max(total, e.rows[2 * (sl * vy + y + 1)]) * (e.ry - 1));
      if (!(total > 0.0)) continue;
      for (std::size_t k = 0; k + 1 < vx; ++k) {
        const double* d = e.warp.data() + 2 * ((sl * vy + y) * vx + k);
        rate_x[k] = std::max(rate_x[k], std::max(d[0], d[2]) / total * (e.rx - 1));
      }
      const double next = y + 1 < vy ? e.rows[2 * (sl * vy + y + 1)] : 0.0;
      if (!(next > 0.0)) continue;
      for (std::size_t k = 0; k < vx; ++k) {
        const double* d = e.warp.data() + 2 * ((sl * vy + y) * vx + k);
        const double change = std::abs(d[2 * vx + 1] / next - d[1] / total);
        rate_y[y] = std::max(rate_y[y], change * (e.rx - 1));
      }
    }
  // Within the memory budget at the most incidence samples the refinement below can make:
  // fewer cells per RGB cell until it fits (files with finer RGB tables, e.g. cg_sunflower's
  // 64 × 64, would otherwise take 25 MB).
  const std::size_t most_slots =
      (slices - 1) * static_cast<std::size_t>(o.max_samples_per_interval) + 1;
  for (double cells = o.cells_per_rgb_cell;; cells *= 0.8) {
    t->ax = TableAxis::FromRates(rate_x, cells, o.max_cells_per_vndf_cell);
    t->ay = TableAxis::FromRates(rate_y, cells, o.max_cells_per_vndf_cell);
    const std::size_t bytes = 6 * most_slots * static_cast<std::size_t>(t->ax.vertices) *
                              static_cast<std::size_t>(t->ay.vertices);
    if (bytes <= o.max_table_bytes || (t->ax.vertices == e.vx && t->ay.vertices == e.vy)) break;
  }
  t->nx = t->ax.vertices;
  t->ny = t->ay.vertices;
  const std::size_t nx = t->nx, ny = t->ny, plane = nx * ny;
  const std::vector<double> ux = t->ax.Positions(), uy = t->ay.Positions();
  // Weights of the incidence test: f_r·cosθo at a vertex is g · ndf / 4σ and the vertex stands
  // for a solid angle of half vectors ∝ sinθm · u(θm) (θm = u² π/2), so an error in g there
  // counts with ndf² · sinθm · u in the RMS of f over directions.
  std::vector<double> weight(plane);
  for (std::size_t y = 0; y < ny; ++y)
    for (std::size_t x = 0; x < nx; ++x) {
      const double n = e.info.jacobian ? e.ndf.Eval(ux[x], uy[y]) : 1.0;
      weight[y * nx + x] = n * n * std::sin(ux[x] * ux[x] * 0.5 * kPi) * ux[x];
    }
  // g at weight w of interval j (RGB per vertex, double).
  auto sample = [&](int j, double w) {
    Corners c;
    const bool single = slices == 1;
    c.n = single ? 1 : 2;
    c.slice = {static_cast<std::size_t>(j), static_cast<std::size_t>(single ? j : j + 1), 0, 0};
    c.w = {1.0 - w, w, 0.0, 0.0};
    std::vector<double> g(3 * plane);
    for (std::size_t y = 0; y < ny; ++y)
      for (std::size_t x = 0; x < nx; ++x) {
        double sx, sy;
        e.InvertWarp(ux[x], uy[y], c, sx, sy);
        const Rgb v = e.InterpolateRgb(sx, sy, c);
        for (int ch = 0; ch < 3; ++ch) g[3 * (y * nx + x) + ch] = v[ch];
      }
    return g;
  };
  // Incidence samples per interval: doubled until linear interpolation between the samples
  // predicts every new midpoint within incidence_tolerance (weighted RMS relative to the
  // midpoint's own weighted RMS). Intervals are independent: built on `jobs` threads, each
  // holding its slots from w = 0 to w = 1 (the shared nodes are computed twice).
  const int intervals = static_cast<int>(slices) - 1;
  std::vector<std::vector<std::vector<double>>> runs(std::max(1, intervals));
  auto build_interval = [&](int j) {
    std::vector<std::vector<double>> run = {sample(j, 0.0)};
    if (intervals == 0) {
      runs[0] = std::move(run);
      return;
    }
    run.push_back(sample(j, 1.0));  // run[m] at w = m / k_samples
    int k_samples = 1;
    while (k_samples < o.max_samples_per_interval) {
      std::vector<std::vector<double>> refined;
      double err = 0.0, norm = 0.0;
      for (int m = 0; m < k_samples; ++m) {
        std::vector<double> mid = sample(j, (m + 0.5) / k_samples);
        for (std::size_t v = 0; v < plane; ++v)
          for (int ch = 0; ch < 3; ++ch) {
            const std::size_t i = 3 * v + static_cast<std::size_t>(ch);
            const double d = mid[i] - 0.5 * (run[m][i] + run[m + 1][i]);
            err += weight[v] * d * d;
            norm += weight[v] * mid[i] * mid[i];
          }
        refined.push_back(std::move(run[m]));
        refined.push_back(std::move(mid));
      }
      refined.push_back(std::move(run[k_samples]));
      run = std::move(refined);
      k_samples *= 2;
      if (!(err > o.incidence_tolerance * o.incidence_tolerance * norm)) break;
    }
    runs[j] = std::move(run);
  };
  ParallelChunks(runs.size(), 1, ResolveJobs(o.jobs), nullptr,
                 [&](std::size_t begin, std::size_t end) {
                   for (std::size_t j = begin; j < end; ++j) build_interval(static_cast<int>(j));
                 });
  // Slots in order, each interval's w = 1 end dropped in favour of the next one's w = 0 (the
  // same node; the last node kept).
  std::vector<const std::vector<double>*> slot_values;
  std::vector<double> slot_theta;
  for (int j = 0; j < static_cast<int>(runs.size()); ++j) {
    const int k_samples = std::max(1, static_cast<int>(runs[j].size()) - 1);
    const bool last = j + 1 == static_cast<int>(runs.size());
    for (std::size_t m = 0; m < runs[j].size(); ++m) {
      if (intervals > 0 && m + 1 == runs[j].size() && !last) break;
      slot_values.push_back(&runs[j][m]);
      slot_theta.push_back(intervals == 0 ? e.theta_i[0]
                                          : e.theta_i[j] + (e.theta_i[j + 1] - e.theta_i[j]) *
                                                               static_cast<double>(m) / k_samples);
    }
  }
  t->slots = static_cast<int>(slot_values.size());
  t->slot_theta = slot_theta;
  t->slot_inv_step.assign(slot_theta.size(), 0.0);
  double closest = kPi;
  for (std::size_t k = 0; k + 1 < slot_theta.size(); ++k) {
    t->slot_inv_step[k] = 1.0 / (slot_theta[k + 1] - slot_theta[k]);
    closest = std::min(closest, slot_theta[k + 1] - slot_theta[k]);
  }
  const double span = slot_theta.back() - slot_theta.front();
  const std::size_t bins =
      std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(span / closest)) + 1, 1, 1u << 14);
  t->bins_per_rad = span > 0.0 ? static_cast<double>(bins) / span : 0.0;
  t->bin_slot.resize(bins);
  for (std::size_t b = 0, k = 0; b < bins; ++b) {
    const double start = slot_theta.front() + static_cast<double>(b) / t->bins_per_rad;
    while (k + 1 < slot_theta.size() && slot_theta[k + 1] <= start) ++k;
    t->bin_slot[b] = static_cast<std::uint16_t>(
        std::min<std::size_t>(k, slot_theta.size() > 1 ? slot_theta.size() - 2 : 0));
  }
  // 16-bit fractions of each slot's per-channel maximum (values are ≥ 0: RglBrdf clips). With
  // the jacobian, the slot's 1 / (4σ(θi)) is folded into its scale: σ is smooth in θi (the
  // projected area of the microsurface), so interpolating g / 4σ between slots instead of g
  // and σ separately changes f by far less than the tabulation of g itself.
  t->texels.assign(3 * plane * slot_values.size() + 1, 0);  // + the last load's fourth lane
  t->scale.assign(4 * slot_values.size(), 0.0f);
  for (std::size_t sl = 0; sl < slot_values.size(); ++sl) {
    const std::vector<double>& g = *slot_values[sl];
    const double factor =
        e.info.jacobian
            ? 1.0 / (4.0 * e.sigma.Eval(std::sqrt(slot_theta[sl] * (2.0 / kPi)), PhiToU(0.0)))
            : 1.0;
    for (int ch = 0; ch < 3; ++ch) {
      double peak = 0.0;
      for (std::size_t v = 0; v < plane; ++v) peak = std::max(peak, g[3 * v + ch]);
      const double step = peak > 0.0 ? peak / 65535.0 : 1.0;
      t->scale[4 * sl + ch] = static_cast<float>(step * factor);
      for (std::size_t v = 0; v < plane; ++v)
        t->texels[3 * (sl * plane + v) + ch] =
            static_cast<std::uint16_t>(std::min(65535.0, std::rint(g[3 * v + ch] / step)));
    }
  }
  RglTabulatedBrdf::Table* raw = t.get();
  std::unique_ptr<RglTabulatedBrdf> out(new RglTabulatedBrdf(std::move(t), name_ + " (tabulated)"));
  raw->self_check_p99 = SelfCheckP99(*this, *out);
  return out;
}

std::unique_ptr<BrdfSource> RglBrdf::QuadratureApproximation() const {
  std::unique_ptr<RglTabulatedBrdf> table = Tabulate(RglTabulationSettings{});
  if (table == nullptr || table->self_check_p99_error() > kRglApproximationMaxP99Error)
    return nullptr;
  return table;
}

}  // namespace brdf
