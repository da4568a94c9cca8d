// The IBL pack of a BrdfSource (brdf/core/ibl_pack.h): directional albedo by quadrature around
// the mirror direction, and the diffuse/specular split with the equivalent GGX roughness fitted
// to the lobe's responses to Legendre rings about the normal and the mirror direction.
#include "brdf/core/ibl_pack.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/core/lut_brdf.h"

namespace brdf {
namespace {

constexpr int kBands = IblPack::kMaxBand + 1;
using Bands = std::array<double, kBands>;

// P_0…P_L at x (Bonnet's recurrence).
void Legendre(double x, Bands* p) {
  (*p)[0] = 1.0;
  (*p)[1] = x;
  for (int l = 1; l + 1 < kBands; ++l)
    (*p)[l + 1] = ((2.0 * l + 1.0) * x * (*p)[l] - l * (*p)[l - 1]) / (l + 1.0);
}

// GGX D at half-vector polar angle θh (docs/design.md §9), without the 1/π (it cancels).
double GgxD(double alpha, double theta_h) {
  const double c = std::cos(theta_h);
  const double t = std::tan(theta_h);
  const double a2 = alpha * alpha;
  const double d = a2 + t * t;
  return a2 / (c * c * c * c * d * d);
}

// κ_ℓ(α) on a log-spaced α grid, computed once: ∫ over γ ∈ [0, π/2] with γ = (π/2)·u² (nodes
// dense near γ = 0, where narrow kernels live), kernel D(γ/2)·cosγ normalised by its integral.
constexpr int kAlphaGrid = 64;
// The broad lobe's α_b is searched in [0.02, 0.75] and 1 (the cosine lobe): between 0.75 and 1
// the GGX kernels differ little from the cosine, and the engines' roughest probe levels (and
// the CPU preview's importance-sampled prefilter) differ from one another by more than that
// (docs/benchmarks/ibl.md, "A broad lobe").
constexpr double kMinBroadAlpha = 0.02, kMaxBroadAlpha = 0.75;
struct KappaTable {
  std::array<double, kAlphaGrid> log_alpha{};
  std::vector<Bands> kappa;
  KappaTable() {
    kappa.resize(kAlphaGrid);
    const double lo = std::log(IblPack::kMinAlpha);
    constexpr int kNodes = 2048;
    Bands p{};
    for (int a = 0; a < kAlphaGrid; ++a) {
      log_alpha[a] = lo + (0.0 - lo) * a / (kAlphaGrid - 1);
      const double alpha = std::exp(log_alpha[a]);
      Bands sum{};
      double norm = 0.0;
      for (int n = 0; n < kNodes; ++n) {
        const double u = (n + 0.5) / kNodes;
        const double gamma = 0.5 * kPi * u * u;
        const double dgamma = kPi * u / kNodes;
        const double c = std::cos(gamma);
        const double w = GgxD(alpha, 0.5 * gamma) * c * std::sin(gamma) * dgamma;
        norm += w;
        Legendre(c, &p);
        for (int l = 0; l < kBands; ++l) sum[l] += w * p[l];
      }
      for (int l = 0; l < kBands; ++l) kappa[a][l] = sum[l] / norm;
    }
  }
};
const KappaTable& Kappa() {
  static const KappaTable table;
  return table;
}

// One view's lobe (luminance or one channel): E and its responses to the Legendre rings.
struct Moments {
  double e = 0.0;
  Bands at_n{}, at_r{};  // t_{n,ℓ}, t_{R,ℓ}
};
// The model's zonal responses about n and about R of the two lobes for one view: the broad
// lobe (weight B) and the sharp lobe (weight S) per band ℓ.
struct Responses {
  Bands broad_n{}, broad_r{};
};
// The broad lobe's responses: B·κ_ℓ(α_b)·P_ℓ(a·R_b), R_b = normalize(mix(R, n, s_b)); at α_b = 1,
// s_b = 1 the clamped cosine about n (κ_ℓ(1) = A_ℓ/π).
void BroadResponses(const Bands& kappa_b, double mu, double shift, Responses* out) {
  const double sv = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  // R = (−sv, μ), n = (0, 1) in the plane of incidence.
  double x = (1.0 - shift) * -sv, z = (1.0 - shift) * mu + shift;
  const double len = std::sqrt(x * x + z * z);
  x /= len;
  z /= len;
  Bands pn{}, pr{};
  Legendre(z, &pn);                 // n·R_b
  Legendre(-sv * x + mu * z, &pr);  // R·R_b
  for (int l = 0; l < kBands; ++l) {
    out->broad_n[l] = kappa_b[l] * pn[l];
    out->broad_r[l] = kappa_b[l] * pr[l];
  }
}
// The fit criterion of one view (luminance or one channel): with u = t − E·b (the responses
// less the broad lobe's at B = E) and d = c − b, S by least squares, S = ⟨u, d⟩/⟨d, d⟩ clamped
// to [0, E] (B = E − S), and the weighted squared residual |u − S·d|² = ⟨u, u⟩ − 2S⟨u, d⟩ +
// S²⟨d, d⟩ returned (⟨u, u⟩ given: it does not depend on the sharp lobe); *s_out the S used.
// ⟨x, y⟩ = Σ_{ℓ≥1} (2ℓ+1)(x_{n,ℓ}y_{n,ℓ} + x_{R,ℓ}y_{R,ℓ}).
double Criterion(const Moments& m, const Responses& q, const Bands& kappa_s, const Bands& p_mu,
                 double uu, double* s_out) {
  double ud = 0.0, dd = 0.0;
  for (int l = 1; l < kBands; ++l) {
    const double weight = 2.0 * l + 1.0;
    const double dn = p_mu[l] * kappa_s[l] - q.broad_n[l], dr = kappa_s[l] - q.broad_r[l];
    ud += weight * ((m.at_n[l] - m.e * q.broad_n[l]) * dn + (m.at_r[l] - m.e * q.broad_r[l]) * dr);
    dd += weight * (dn * dn + dr * dr);
  }
  double s = dd > 0.0 ? ud / dd : 0.0;
  s = std::clamp(s, 0.0, std::max(0.0, m.e));
  *s_out = s;
  return std::max(0.0, uu - 2.0 * s * ud + s * s * dd);
}
// ⟨u, u⟩ of Criterion.
double BroadResidual(const Moments& m, const Responses& q) {
  double uu = 0.0;
  for (int l = 1; l < kBands; ++l) {
    const double un = m.at_n[l] - m.e * q.broad_n[l], ur = m.at_r[l] - m.e * q.broad_r[l];
    uu += (2.0 * l + 1.0) * (un * un + ur * ur);
  }
  return uu;
}

double Luma(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

}  // namespace

Bands GgxPrefilterLegendre(double alpha) {
  const KappaTable& t = Kappa();
  const double la = std::log(std::clamp(alpha, IblPack::kMinAlpha, 1.0));
  const double x = (la - t.log_alpha[0]) / (t.log_alpha[1] - t.log_alpha[0]);
  const int i = std::clamp(static_cast<int>(std::floor(x)), 0, kAlphaGrid - 2);
  const double f = std::clamp(x - i, 0.0, 1.0);
  Bands k{};
  for (int l = 0; l < kBands; ++l) k[l] = (1.0 - f) * t.kappa[i][l] + f * t.kappa[i + 1][l];
  return k;
}

Rgb IblPack::DiffuseFit(double m) const {
  const double t = 1.0 - m;
  const auto& q = diffuse_quadratic;
  Rgb d;
  for (int c = 0; c < 3; ++c) d[c] = q[0][c] + t * (q[1][c] + t * q[2][c]);
  return d;
}

double IblSpecularShift(double alpha_eq, double mu) {
  return std::clamp(alpha_eq, 0.0, 1.0) * (1.0 - std::clamp(mu, 0.0, 1.0));
}

namespace {
// normalize(mix(R, n, s)) with R = 2(n·v)n − v and s = shift(n·v): both lobes' lookup.
template <typename Shift>
Vec3 MixedReflection(const Vec3& n, const Vec3& v, Shift shift) {
  const double mu = Dot(n, v);
  const Vec3 r = n * (2.0 * mu) - v;
  return Normalize(r + (n - r) * shift(mu));
}
}  // namespace

Vec3 IblSpecularDirection(const Vec3& n, const Vec3& v, double alpha_eq) {
  return MixedReflection(n, v, [&](double mu) { return IblSpecularShift(alpha_eq, mu); });
}

Vec3 IblBroadDirection(const Vec3& n, const Vec3& v, double broad_alpha) {
  return MixedReflection(n, v, [&](double) { return std::clamp(broad_alpha, 0.0, 1.0); });
}

IblPack::Row IblPack::At(double m) const {
  Row row;
  if (mu.empty()) return row;
  const double x = m * kRows - 0.5;
  const int n = static_cast<int>(mu.size());
  const int i = std::clamp(static_cast<int>(std::floor(x)), 0, n - 1);
  const int j = std::min(i + 1, n - 1);
  const double f = std::clamp(x - i, 0.0, 1.0);
  for (int c = 0; c < 3; ++c) {
    row.albedo[c] = (1.0 - f) * albedo[i][c] + f * albedo[j][c];
    row.specular[c] = (1.0 - f) * specular[i][c] + f * specular[j][c];
  }
  row.diffuse = DiffuseFit(std::clamp(m, 0.5 / kRows, 1.0 - 0.5 / kRows));
  row.alpha = (1.0 - f) * alpha[i] + f * alpha[j];
  return row;
}

namespace {

// Midpoint nodes and weights on [lo, hi] for the density a + b·exp(−½((x − c)/σ)²) (a share
// `peak` of the nodes in the Gaussian, the rest uniform): node i sits at the inverse CDF of
// (i + 0.5)/n, weight 1/(n·ρ(x)). Smooth, so the rule stays second order; the CDF is tabulated
// on 512 intervals and inverted linearly.
void ConcentratedNodes(double lo, double hi, double c, double sigma, double peak, int n,
                       std::vector<double>* x, std::vector<double>* w) {
  constexpr int kTable = 512;
  const double h = (hi - lo) / kTable;
  // Gaussian mass inside [lo, hi], by the same table (normalised below).
  std::vector<double> cdf(kTable + 1, 0.0);
  auto gauss = [&](double t) { return std::exp(-0.5 * ((t - c) / sigma) * ((t - c) / sigma)); };
  double gauss_mass = 0.0;
  for (int k = 0; k < kTable; ++k) gauss_mass += gauss(lo + (k + 0.5) * h) * h;
  const double a = (1.0 - peak) / (hi - lo), b = peak / gauss_mass;
  auto density = [&](double t) { return a + b * gauss(t); };
  for (int k = 0; k < kTable; ++k) cdf[k + 1] = cdf[k] + density(lo + (k + 0.5) * h) * h;
  x->resize(n);
  w->resize(n);
  int k = 0;
  for (int i = 0; i < n; ++i) {
    const double target = (i + 0.5) / n * cdf[kTable];
    while (k + 1 < kTable && cdf[k + 1] < target) ++k;
    const double t = lo + (k + (target - cdf[k]) / (cdf[k + 1] - cdf[k])) * h;
    (*x)[i] = t;
    (*w)[i] = cdf[kTable] / (n * density(t));
  }
}

// D_fit(μ) = c0 + c1·t + c2·t², t = 1 − μ, by least squares over the rows per channel (the
// 3 × 3 normal equations, solved by Cramer's rule: t ∈ [0, 1] keeps them well conditioned),
// then S_i = E_i − D_fit(μ_i) (brdf/core/ibl_pack.h: the furnace exact at texel centres).
void FitDiffuseQuadratic(IblPack* pack) {
  double m[3][3] = {};
  double rhs[3][3] = {};  // [power][channel]
  for (std::size_t i = 0; i < pack->mu.size(); ++i) {
    const double t = 1.0 - pack->mu[i];
    const double pw[5] = {1.0, t, t * t, t * t * t, t * t * t * t};
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) m[a][b] += pw[a + b];
      for (int c = 0; c < 3; ++c) rhs[a][c] += pw[a] * pack->diffuse[i][c];
    }
  }
  auto det3 = [](const double(&x)[3][3]) {
    return x[0][0] * (x[1][1] * x[2][2] - x[1][2] * x[2][1]) -
           x[0][1] * (x[1][0] * x[2][2] - x[1][2] * x[2][0]) +
           x[0][2] * (x[1][0] * x[2][1] - x[1][1] * x[2][0]);
  };
  const double det = det3(m);
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) {
      double mk[3][3];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) mk[a][b] = b == k ? rhs[a][c] : m[a][b];
      pack->diffuse_quadratic[k][c] = det != 0.0 ? det3(mk) / det : 0.0;
    }
  }
  for (std::size_t i = 0; i < pack->mu.size(); ++i) {
    const Rgb d = pack->DiffuseFit(pack->mu[i]);
    for (int c = 0; c < 3; ++c) pack->specular[i][c] = pack->albedo[i][c] - d[c];
  }
}

// The lobes' moments of one view: per channel and of the luminance, and P_ℓ(μ).
struct RowMoments {
  std::array<Moments, 3> channel{};
  Moments luma;
  Bands p_mu{};
};

// Σ (2ℓ+1)(t_{n,ℓ}² + t_{R,ℓ}²) over ℓ ≥ 1: what a row's residual is relative to.
double ResponseNorm(const Moments& m) {
  double norm = 0.0;
  for (int l = 1; l < kBands; ++l)
    norm += (2.0 * l + 1.0) * (m.at_n[l] * m.at_n[l] + m.at_r[l] * m.at_r[l]);
  return norm;
}

// The sharp lobe's α_s of one view given the broad lobe's responses q: the κ table's grid up
// to `max_alpha` (the sharp lobe is the narrower one), then (with `refine`) golden-section
// refinement in log α between the best node's neighbours. *value the criterion at the α
// returned.
double FitSharpAlpha(const Moments& luma, const Bands& p_mu, const Responses& q, double max_alpha,
                     bool refine, double* value) {
  const int stride = refine ? 1 : 2;
  const KappaTable& table = Kappa();
  const double max_la = std::log(std::clamp(max_alpha, IblPack::kMinAlpha, 1.0));
  const double uu = BroadResidual(luma, q);
  double sy = 0.0;
  int best = 0;
  double best_value = 0.0;
  int last = 0;
  for (int a = 0; a < kAlphaGrid && table.log_alpha[a] <= max_la + 1e-12; a += stride) {
    const double v = Criterion(luma, q, table.kappa[a], p_mu, uu, &sy);
    if (a == 0 || v < best_value) {
      best = a;
      best_value = v;
    }
    last = a;
  }
  double la = table.log_alpha[best];
  if (refine) {
    double lo = table.log_alpha[std::max(0, best - 1)];
    double hi = best == last ? max_la : table.log_alpha[best + 1];
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    auto value_at = [&](double x) {
      return Criterion(luma, q, GgxPrefilterLegendre(std::exp(x)), p_mu, uu, &sy);
    };
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = value_at(x1), f2 = value_at(x2);
    for (int it = 0; it < 24; ++it) {
      if (f1 < f2) {
        hi = x2;
        x2 = x1;
        f2 = f1;
        x1 = hi - g * (hi - lo);
        f1 = value_at(x1);
      } else {
        lo = x1;
        x1 = x2;
        f1 = f2;
        x2 = lo + g * (hi - lo);
        f2 = value_at(x2);
      }
    }
    const double mid = 0.5 * (lo + hi);
    const double v = value_at(mid);
    if (v <= best_value) {  // else the grid's best was not bracketed (an end of the range)
      la = mid;
      best_value = v;
    }
  }
  *value = best_value;
  return std::exp(la);
}

// The material's broad lobe α_b (read about R_b = mix(R, n, α_b)) and, per row, α_s, S and B;
// then B's quadratic and S_i = E_i − B_fit(μ_i) (brdf/core/ibl_pack.h).
void FitLobes(const std::vector<RowMoments>& rows, IblPack* pack) {
  const KappaTable& table = Kappa();
  const int n = static_cast<int>(rows.size());
  std::vector<double> norm(n);
  for (int i = 0; i < n; ++i) norm[i] = ResponseNorm(rows[i].luma);
  // Σ over the rows of the relative criterion of a candidate α_b (α_s on the grid only).
  auto total = [&](double ab) {
    const Bands kb = GgxPrefilterLegendre(ab);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      if (!(rows[i].luma.e > 0.0) || !(norm[i] > 0.0)) continue;
      Responses q;
      BroadResponses(kb, pack->mu[i], ab, &q);
      double v = 0.0;
      FitSharpAlpha(rows[i].luma, rows[i].p_mu, q, ab, false, &v);
      sum += v / norm[i];
    }
    return sum;
  };
  // α_b on every 2nd node of the κ table from 1 down to kMinBroadAlpha: every 6th first, then
  // the nodes 2 and 4 either side of the best of those.
  std::vector<int> nodes;
  for (int a = kAlphaGrid - 1; a >= 0 && table.log_alpha[a] >= std::log(kMinBroadAlpha); a -= 2)
    if (a == kAlphaGrid - 1 || table.log_alpha[a] <= std::log(kMaxBroadAlpha)) nodes.push_back(a);
  std::vector<double> value(nodes.size(), -1.0);
  auto value_of = [&](int k) {
    if (value[k] < 0.0) value[k] = total(std::exp(table.log_alpha[nodes[k]]));
    return value[k];
  };
  int best = 0;
  for (int k = 0; k < static_cast<int>(nodes.size()); k += 3)
    if (value_of(k) < value_of(best)) best = k;
  const int coarse = best;
  for (int k = std::max(0, coarse - 2); k <= std::min<int>(nodes.size() - 1, coarse + 2); ++k)
    if (value_of(k) < value_of(best)) best = k;
  const double alpha_b = std::exp(table.log_alpha[nodes[best]]);
  pack->broad_alpha = alpha_b;
  const Bands kb = GgxPrefilterLegendre(alpha_b);
  for (int i = 0; i < n; ++i) {
    const RowMoments& r = rows[i];
    double alpha = 1.0, residual = 0.0;
    Responses q;
    BroadResponses(kb, pack->mu[i], alpha_b, &q);
    if (r.luma.e > 0.0) {
      double row_value = 0.0;
      alpha = FitSharpAlpha(r.luma, r.p_mu, q, alpha_b, true, &row_value);
      residual = norm[i] > 0.0 ? row_value / norm[i] : 0.0;
    }
    const Bands ks = GgxPrefilterLegendre(alpha);
    for (int c = 0; c < 3; ++c) {
      double sc = 0.0;
      if (r.channel[c].e > 0.0)
        Criterion(r.channel[c], q, ks, r.p_mu, BroadResidual(r.channel[c], q), &sc);
      pack->specular[i][c] = sc;
      pack->diffuse[i][c] = std::max(0.0, r.channel[c].e - sc);
    }
    pack->alpha[i] = alpha;
    pack->residual[i] = residual;
  }
  FitDiffuseQuadratic(pack);
}

}  // namespace

IblPack ComputeIblPack(const BrdfSource& source) {
  constexpr int kRows = IblPack::kRows;
  constexpr int kTheta = IblPack::kThetaSteps, kPhi = IblPack::kPhiSteps;
  // Histogram of the lobe over t = √(1 − cosγ) = √2·sin(γ/2) ∈ [0, √2], γ the angle between l
  // and R, for the moments about R (linear splatting: exact for constant and linear functions of
  // t, second order otherwise). t is nearly proportional to γ where lobes are narrow (γ ≪ 1) and
  // takes a square root per sample instead of an arc cosine.
  constexpr int kBins = 1024;
  constexpr double kMaxT = 1.4142135623730951;
  IblPack pack;
  pack.mu.resize(kRows);
  pack.albedo.resize(kRows);
  pack.diffuse.resize(kRows);
  pack.specular.resize(kRows);
  pack.alpha.resize(kRows);
  pack.residual.resize(kRows);

  std::vector<Bands> p_bins(kBins);
  for (int b = 0; b < kBins; ++b) {
    const double t = kMaxT * b / (kBins - 1);
    Legendre(1.0 - t * t, &p_bins[b]);
  }
  std::vector<Rgb> hist(kBins);
  Bands p{};
  std::vector<double> theta_x, theta_w, phi_x, phi_w, cos_phi(kPhi), sin_phi(kPhi);
  // A LUT is sampled by its own rule directly from the grid's angles (Lut::SampleAngles's rule
  // with the light at φ = 0 and the view at the relative azimuth, exactly what LutBrdf::Eval
  // computes from the vectors), which saves the vectors' trigonometry: most of the pack's cost.
  const auto* lut = dynamic_cast<const LutBrdf*>(&source);
  std::vector<double> phi_out_deg(kPhi), cos_phi_out(kPhi), sin_phi_out(kPhi);

  std::vector<RowMoments> rows(kRows);
  for (int row = 0; row < kRows; ++row) {
    const double mu = (row + 0.5) / kRows;
    const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double theta_v = std::acos(mu);
    const Vec3 v = {s, 0.0, mu};
    const Vec3 r = {-s, 0.0, mu};
    // Nodes in the normal frame, so the horizon is an edge of the grid, concentrated around
    // the mirror direction R = (θv, 180°): 40 % of the θ nodes within a few degrees of θv, and
    // of the φ nodes within a few degrees of arc of 180°.
    constexpr double kSigma = 0.1;  // rad, about 6°
    ConcentratedNodes(0.0, 0.5 * kPi, theta_v, kSigma, 0.3, kTheta, &theta_x, &theta_w);
    ConcentratedNodes(0.0, 2.0 * kPi, kPi, std::min(1.0, kSigma / std::max(s, 0.05)), 0.3, kPhi,
                      &phi_x, &phi_w);
    for (int k = 0; k < kPhi; ++k) {
      cos_phi[k] = std::cos(phi_x[k]);
      sin_phi[k] = std::sin(phi_x[k]);
      phi_out_deg[k] = WrapDeg360(-RadToDeg(phi_x[k]));
    }
    const double theta_v_deg = RadToDeg(theta_v);
    // The trigonometry Lut::SampleAngles would do per sample, once per row, per θ node or per
    // φ node (Lut::SampleTextureFrame; the same values, so the same bits): the view's and each
    // light's specular frame and slice coordinate, ω_out's azimuth terms.
    const SpecularFrame frame_v = SpecularFrame::FromThetaInDeg(theta_v_deg);
    const double sin_v = std::sin(DegToRad(theta_v_deg)), cos_v = std::cos(DegToRad(theta_v_deg));
    const double slice_v = lut != nullptr ? lut->lut().SliceCoordinate(theta_v_deg) : 0.0;
    for (int k = 0; k < kPhi; ++k) {
      cos_phi_out[k] = std::cos(DegToRad(phi_out_deg[k]));
      sin_phi_out[k] = std::sin(DegToRad(phi_out_deg[k]));
    }
    std::fill(hist.begin(), hist.end(), Rgb{0, 0, 0});
    std::array<Moments, 3> m{};
    Rgb e = {0, 0, 0};
    for (int j = 0; j < kTheta; ++j) {
      const double st = std::sin(theta_x[j]), ct = std::cos(theta_x[j]);
      const double row_weight = st * ct * theta_w[j];
      const double theta_l_deg = RadToDeg(theta_x[j]);
      // Lut::SampleAngles(θl, θv, φout): the texture at (θl; θv, φout), or with light and view
      // exchanged at (θv; θl, −φout) (sin(−φ) = −sin φ).
      const bool exchange =
          lut != nullptr && lut->lut().ExchangesLightAndView(theta_l_deg, theta_v_deg);
      const SpecularFrame frame_l = SpecularFrame::FromThetaInDeg(theta_l_deg);
      const double slice_l =
          lut != nullptr && !exchange ? lut->lut().SliceCoordinate(theta_l_deg) : 0.0;
      const double sin_l = std::sin(DegToRad(theta_l_deg)), cos_l = std::cos(DegToRad(theta_l_deg));
      Rgb ring = {0, 0, 0};
      for (int k = 0; k < kPhi; ++k) {
        const Vec3 l = {st * cos_phi[k], st * sin_phi[k], ct};
        Rgb f;
        if (lut != nullptr) {
          const std::array<float, 3> t =
              exchange ? lut->lut().SampleTextureFrame(frame_v.cos_m, frame_v.sin_m, slice_v,
                                                       sin_l * cos_phi_out[k],
                                                       sin_l * -sin_phi_out[k], cos_l)
                       : lut->lut().SampleTextureFrame(frame_l.cos_m, frame_l.sin_m, slice_l,
                                                       sin_v * cos_phi_out[k],
                                                       sin_v * sin_phi_out[k], cos_v);
          f = {t[0], t[1], t[2]};
        } else {
          f = source.Eval(l, v);
        }
        const double w = row_weight * phi_w[k];
        const double cos_gamma = std::clamp(Dot(l, r), -1.0, 1.0);
        const double x = std::sqrt(1.0 - cos_gamma) * ((kBins - 1) / kMaxT);
        const int b = std::min(kBins - 2, static_cast<int>(x));
        const double frac = x - b;
        for (int c = 0; c < 3; ++c) {
          const double wc = f[c] * w;
          ring[c] += wc;
          hist[b][c] += (1.0 - frac) * wc;
          hist[b + 1][c] += frac * wc;
        }
      }
      Legendre(ct, &p);
      for (int c = 0; c < 3; ++c) {
        e[c] += ring[c];
        for (int l = 0; l < kBands; ++l) m[c].at_n[l] += ring[c] * p[l];
      }
    }
    // Bins the lobe never reached are skipped; the three channels share each bin's P_ℓ.
    for (int b = 0; b < kBins; ++b) {
      const Rgb& h = hist[b];
      if (h[0] == 0.0 && h[1] == 0.0 && h[2] == 0.0) continue;
      const Bands& pb = p_bins[b];
      for (int l = 0; l < kBands; ++l) {
        m[0].at_r[l] += h[0] * pb[l];
        m[1].at_r[l] += h[1] * pb[l];
        m[2].at_r[l] += h[2] * pb[l];
      }
    }
    for (int c = 0; c < 3; ++c) m[c].e = e[c];
    Moments luma;
    luma.e = Luma(e);
    for (int l = 0; l < kBands; ++l) {
      luma.at_n[l] = Luma({m[0].at_n[l], m[1].at_n[l], m[2].at_n[l]});
      luma.at_r[l] = Luma({m[0].at_r[l], m[1].at_r[l], m[2].at_r[l]});
    }
    pack.mu[row] = mu;
    pack.albedo[row] = e;
    rows[row].channel = m;
    rows[row].luma = luma;
    Legendre(mu, &rows[row].p_mu);
  }
  FitLobes(rows, &pack);
  return pack;
}

std::string IblPackJson(const IblPack& pack) {
  std::string out =
      "{\"convention\": \"docs/engines.md, IBL pack: mu = cos(theta_view) at texel "
      "centres (i + 0.5)/rows; radiance = D_fit(mu) * prefiltered(broad_alpha, R_b) + "
      "specular_rgb * prefiltered(alpha_eq, R'), R = reflect(-v, n), R_b = normalize(mix(R, n, "
      "broad_alpha)) (at broad_alpha = 1 the cosine lobe about n: irradiance/pi), R' = "
      "normalize(mix(R, n, alpha_eq (1 - mu))), D_fit(mu) = c0 + c1 t + c2 t^2, t = 1 - mu, "
      "[c0, c1, c2] = diffuse_quadratic_rgb (least squares to diffuse_rgb, the broad lobe's "
      "part); albedo_rgb = D_fit(mu) + specular_rgb at every mu\", \"rows\": ";
  out += std::to_string(pack.mu.size());
  char buf[96];
  auto list = [&](const char* key, auto&& value) {
    out += ", \"";
    out += key;
    out += "\": [";
    for (std::size_t i = 0; i < pack.mu.size(); ++i) {
      if (i) out += ", ";
      out += value(i);
    }
    out += "]";
  };
  auto number = [&](double x) {
    std::snprintf(buf, sizeof buf, "%.7g", x);
    return std::string(buf);
  };
  auto rgb = [&](const Rgb& c) {
    std::snprintf(buf, sizeof buf, "[%.7g, %.7g, %.7g]", c[0], c[1], c[2]);
    return std::string(buf);
  };
  list("mu", [&](std::size_t i) { return number(pack.mu[i]); });
  list("albedo_rgb", [&](std::size_t i) { return rgb(pack.albedo[i]); });
  list("diffuse_rgb", [&](std::size_t i) { return rgb(pack.diffuse[i]); });
  list("specular_rgb", [&](std::size_t i) { return rgb(pack.specular[i]); });
  out += ", \"diffuse_quadratic_rgb\": [";
  for (int k = 0; k < 3; ++k) {
    if (k) out += ", ";
    out += rgb(pack.diffuse_quadratic[k]);
  }
  out += "]";
  list("alpha_eq", [&](std::size_t i) { return number(pack.alpha[i]); });
  list("fit_residual", [&](std::size_t i) { return number(pack.residual[i]); });
  out += ", \"broad_alpha\": " + number(pack.broad_alpha);
  out += "}";
  return out;
}

}  // namespace brdf
