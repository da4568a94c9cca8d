// The IBL pack (brdf/core/ibl_pack.h) against analytic truths: a Lambertian's albedo is ρ at
// every view and has no specular part; a GGX material's albedo against a brute-force quadrature
// in the normal frame (tests/brute_force_albedo.h, a different grid from the pack's); at views near
// the normal, where the split sum's assumption n = v = R holds, the two lobes fitted to a GGX lobe
// bracket its α and keep its kernel's spectrum; the kernel's Legendre coefficients against the
// closed form of the limit α → 0 and a direct sum.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "brdf/core/brdf_source.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/core/models.h"
#include "brute_force_albedo.h"

namespace brdf {
namespace {

AnalyticBrdf Ggx(double kd, double f0, double alpha) {
  return AnalyticBrdf(
      Material::Make(Model::kGgx, {{kd, kd, kd}, {f0, f0, f0}, {alpha, alpha, alpha}}, "ggx"));
}

TEST(IblPack, LambertianAlbedoIsRhoAndAllDiffuseAtEveryView) {
  const AnalyticBrdf lambert(Material::Make(Model::kLambert, {{0.8, 0.5, 0.2}}, "lambert"));
  const IblPack pack = ComputeIblPack(lambert);
  ASSERT_EQ(pack.mu.size(), static_cast<std::size_t>(IblPack::kRows));
  EXPECT_EQ(pack.broad_alpha, 1.0);  // the broad lobe is the cosine lobe
  const double rho[3] = {0.8, 0.5, 0.2};
  for (int i = 0; i < IblPack::kRows; ++i) {
    EXPECT_NEAR(pack.mu[i], (i + 0.5) / IblPack::kRows, 1e-15);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(pack.albedo[i][c], rho[c], 1e-3 * rho[c]) << "row " << i;
      // The lobe is the irradiance kernel itself: nothing for the prefiltered radiance.
      EXPECT_LT(std::abs(pack.specular[i][c]), 1e-2 * rho[c]) << "row " << i;
    }
    EXPECT_LT(pack.residual[i], 1e-3) << "row " << i;
  }
  // D(μ) = ρ is its own quadratic: c0 = ρ, c1 = c2 = 0.
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(pack.diffuse_quadratic[0][c], rho[c], 2e-3 * rho[c]) << "channel " << c;
    EXPECT_NEAR(pack.diffuse_quadratic[1][c], 0.0, 1e-2 * rho[c]) << "channel " << c;
    EXPECT_NEAR(pack.diffuse_quadratic[2][c], 0.0, 1e-2 * rho[c]) << "channel " << c;
  }
}

// The engines' diffuse weight D_fit(μ) = c0 + c1·t + c2·t² (t = 1 − μ) is the least-squares
// quadratic of the split's D rows: its residual is orthogonal to 1, t and t² (the normal
// equations, the definition of the fit); and S_i = E_i − D_fit(μ_i), so the pack as an engine
// reads it (At) gives D + S = E at every texel centre and at both clamped ends.
TEST(IblPack, DiffuseQuadraticIsTheLeastSquaresFitAndKeepsTheAlbedoAtTexelCentres) {
  for (const double kd : {0.0, 0.3}) {
    const IblPack pack = ComputeIblPack(Ggx(kd, 0.04, 0.3));
    for (int c = 0; c < 3; ++c) {
      double orthogonality[3] = {}, scale = 0.0;
      for (int i = 0; i < IblPack::kRows; ++i) {
        const double t = 1.0 - pack.mu[i];
        const double q = pack.diffuse_quadratic[0][c] + pack.diffuse_quadratic[1][c] * t +
                         pack.diffuse_quadratic[2][c] * t * t;
        const double r = pack.diffuse[i][c] - q;
        orthogonality[0] += r;
        orthogonality[1] += r * t;
        orthogonality[2] += r * t * t;
        scale += std::abs(pack.diffuse[i][c]);
      }
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(orthogonality[k], 0.0, 1e-9 * std::max(scale, 1e-3))
            << "kd " << kd << " channel " << c << " power " << k;
    }
    for (int i = 0; i < IblPack::kRows; ++i) {
      const IblPack::Row row = pack.At(pack.mu[i]);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(row.diffuse[c] + row.specular[c], pack.albedo[i][c], 1e-12)
            << "kd " << kd << " row " << i;
    }
    for (const double mu : {0.0, 1.0}) {
      const IblPack::Row row = pack.At(mu);
      const Rgb& e = mu == 0.0 ? pack.albedo.front() : pack.albedo.back();
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(row.diffuse[c] + row.specular[c], e[c], 1e-12);
    }
  }
}

TEST(IblPack, GgxAlbedoMatchesABruteForceQuadrature) {
  for (double alpha : {0.15, 0.4}) {
    const AnalyticBrdf ggx = Ggx(0.2, 0.5, alpha);
    const IblPack pack = ComputeIblPack(ggx);
    for (int i : {0, 5, 16, 32, 48, 63}) {
      const Rgb truth = testing::BruteForceAlbedo(ggx, pack.mu[i], 1500, 1440);
      EXPECT_NEAR(pack.albedo[i][0], truth[0], 3e-3 * truth[0])
          << "alpha " << alpha << " mu " << pack.mu[i];
    }
  }
}

// κ_ℓ(α) for ℓ = 0…4 by a direct midpoint sum over γ (uniform, 200 000 nodes) of the GGX D of
// §9 at γ/2 times cosγ, normalised: the prefilter kernel's Legendre coefficients.
std::array<double, 5> DirectKernelCoefficients(double alpha) {
  const double a2 = alpha * alpha;
  constexpr int kNodes = 200000;
  std::array<double, 5> p{};
  double norm = 0;
  for (int n = 0; n < kNodes; ++n) {
    const double g = (n + 0.5) * 0.5 * kPi / kNodes, h = 0.5 * g;
    const double t2 = std::tan(h) * std::tan(h), c4 = std::pow(std::cos(h), 4);
    const double w = a2 / (kPi * c4 * (a2 + t2) * (a2 + t2)) * std::cos(g) * std::sin(g);
    const double x = std::cos(g);
    const double leg[5] = {1.0, x, 0.5 * (3 * x * x - 1), 0.5 * (5 * x * x * x - 3 * x),
                           (35 * x * x * x * x - 30 * x * x + 3) / 8.0};
    norm += w;
    for (int l = 0; l < 5; ++l) p[l] += w * leg[l];
  }
  for (double& v : p) v /= norm;
  return p;
}

TEST(IblPack, TwoLobesOfAGgxLobeBracketItsAlphaAndKeepItsSpectrumNearTheNormal) {
  // Pure specular (kd 0, F = 1): at μ → 1, f·cosθl = D(h)·G/(4μ)·cosθl with v = n is the
  // prefilter kernel D(γ/2)·cosγ times G/(4μ) (nearly 1 over the lobe). The pack describes it
  // with two GGX kernels, the broad lobe's α_b (one per material, fitted over all views, where
  // the horizon clips and shifts the lobe) and the sharp one's α_s per row: near the normal they
  // must bracket α (α_s ≤ α ≤ α_b, 5 % allowed for the table's interpolation in log α), and
  // their mix about R, B·κ_ℓ(α_b)·P_ℓ(R·R_b) + S·κ_ℓ(α_s), must have the spectrum of E·κ_ℓ(α), the
  // kernel's own coefficients by a direct sum, within 0.06 for ℓ = 1…4 (the G factor, and α_b: one
  // per material, fitted over every view, it makes the mix up to 0.053 broader than the kernel at
  // α = 0.2 near the normal); most of the energy goes to the sharp lobe.
  for (double alpha : {0.05, 0.1, 0.2}) {
    const IblPack pack = ComputeIblPack(Ggx(0.0, 1.0, alpha));
    const std::array<double, 5> truth = DirectKernelCoefficients(alpha);
    const std::array<double, IblPack::kMaxBand + 1> broad = GgxPrefilterLegendre(pack.broad_alpha);
    EXPECT_GE(pack.broad_alpha, 0.95 * alpha);
    for (int i = IblPack::kRows - 4; i < IblPack::kRows; ++i) {
      SCOPED_TRACE(::testing::Message() << "alpha " << alpha << " mu " << pack.mu[i] << " alpha_b "
                                        << pack.broad_alpha << " alpha_s " << pack.alpha[i]);
      EXPECT_LE(pack.alpha[i], 1.05 * alpha);
      const double mu = pack.mu[i], e = pack.albedo[i][0];
      const Vec3 n = {0, 0, 1}, v = {std::sqrt(1 - mu * mu), 0, mu};
      const Vec3 r = n * (2 * mu) - v;  // the responses about the mirror direction
      const double x = Dot(r, IblBroadDirection(n, v, pack.broad_alpha));
      const double leg[5] = {1.0, x, 0.5 * (3 * x * x - 1), 0.5 * (5 * x * x * x - 3 * x),
                             (35 * x * x * x * x - 30 * x * x + 3) / 8.0};
      const double s = pack.specular[i][0], b = e - s;
      const std::array<double, IblPack::kMaxBand + 1> sharp = GgxPrefilterLegendre(pack.alpha[i]);
      for (int l = 1; l <= 4; ++l)
        EXPECT_NEAR((b * broad[l] * leg[l] + s * sharp[l]) / e, truth[l], 0.06) << "l " << l;
    }
    EXPECT_GT(pack.specular.back()[0], 0.5 * pack.albedo.back()[0]) << "alpha " << alpha;
  }
}

// A clear coat's shape: a narrow GGX lobe over a broad one, f = a + b.
class TwoGgxLobes : public BrdfSource {
 public:
  TwoGgxLobes(double alpha_a, double f0_a, double alpha_b, double f0_b)
      : a_(Ggx(0.0, f0_a, alpha_a)), b_(Ggx(0.0, f0_b, alpha_b)) {}
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    const Rgb x = a_.Eval(wi, wo), y = b_.Eval(wi, wo);
    return {x[0] + y[0], x[1] + y[1], x[2] + y[2]};
  }
  std::string Name() const override { return "two_ggx"; }

 private:
  AnalyticBrdf a_, b_;
};

TEST(IblPack, TwoLobesOfACoatOverABroadLobeAreFoundAsSuch) {
  // A narrow lobe (α 0.05, F 0.3) over a broad one (α 0.35, F 0.7): the broad lobe's α_b lies
  // near 0.35 (within the search grid's step, a factor 1.18, and the horizon's distortion: a
  // factor 1.5 either way is asserted), the sharp lobe's α_s near 0.05 at the normal, and the
  // weights near the normal split about as the two lobes' albedos do (their own packs: the
  // sharp lobe's share within 0.1).
  const TwoGgxLobes coat(0.05, 0.3, 0.35, 0.7);
  const IblPack pack = ComputeIblPack(coat);
  EXPECT_GT(pack.broad_alpha, 0.35 / 1.5);
  EXPECT_LT(pack.broad_alpha, 0.35 * 1.5);
  const IblPack narrow = ComputeIblPack(Ggx(0.0, 0.3, 0.05));
  for (int i = IblPack::kRows - 4; i < IblPack::kRows; ++i) {
    EXPECT_NEAR(pack.alpha[i], 0.05, 0.0125) << "mu " << pack.mu[i];
    EXPECT_NEAR(pack.specular[i][0] / pack.albedo[i][0], narrow.albedo[i][0] / pack.albedo[i][0],
                0.1)
        << "mu " << pack.mu[i];
  }
  // The single-lobe form (the broad lobe the cosine) could not: one α_eq per view blurs both.
}

TEST(IblPack, KernelCoefficientsMatchADirectSumAndTheMirrorLimit) {
  // α → 0: the kernel is a delta at R, every κ_ℓ → 1.
  const auto sharp = GgxPrefilterLegendre(IblPack::kMinAlpha);
  for (int l = 0; l <= 8; ++l) EXPECT_NEAR(sharp[l], 1.0, 2e-3 * (l * l + 1)) << l;
  // α = 0.3 against a direct midpoint sum over γ (uniform, 200 000 nodes), GGX D of §9.
  const double alpha = 0.3, a2 = alpha * alpha;
  constexpr int kNodes = 200000;
  double norm = 0, p1 = 0, p2 = 0;
  for (int n = 0; n < kNodes; ++n) {
    const double g = (n + 0.5) * 0.5 * kPi / kNodes, h = 0.5 * g;
    const double t2 = std::tan(h) * std::tan(h), c4 = std::pow(std::cos(h), 4);
    const double w = a2 / (kPi * c4 * (a2 + t2) * (a2 + t2)) * std::cos(g) * std::sin(g);
    const double x = std::cos(g);
    norm += w;
    p1 += w * x;
    p2 += w * 0.5 * (3 * x * x - 1);
  }
  const auto k = GgxPrefilterLegendre(alpha);
  EXPECT_NEAR(k[0], 1.0, 1e-12);
  EXPECT_NEAR(k[1], p1 / norm, 2e-3);
  EXPECT_NEAR(k[2], p2 / norm, 2e-3);
}

TEST(IblPack, RowsInterpolateLikeALinearTexture) {
  const IblPack pack = ComputeIblPack(Ggx(0.3, 0.04, 0.3));
  EXPECT_DOUBLE_EQ(pack.At(0.0).albedo[0], pack.albedo[0][0]);
  EXPECT_DOUBLE_EQ(pack.At(1.0).alpha, pack.alpha.back());
  const double mid = 0.5 * (pack.mu[10] + pack.mu[11]);
  EXPECT_NEAR(pack.At(mid).specular[1], 0.5 * (pack.specular[10][1] + pack.specular[11][1]), 1e-12);
}

// The dominant direction R' = normalize(mix(R, n, α·(1 − μ))): R itself at the normal and for
// a mirror (α → 0); for n = z and v at θ in the xz plane, R = (−sinθ, 0, cosθ) and R' lies in
// that plane at the angle atan2((1 − s)·sinθ, (1 − s)·cosθ + s) from n, s = α·(1 − cosθ).
TEST(IblPack, SpecularDirectionMovesTheMirrorDirectionTowardTheNormal) {
  const Vec3 n = {0.0, 0.0, 1.0};
  for (const double alpha : {0.0, 0.1, 0.5, 1.0}) {
    const Vec3 at_normal = IblSpecularDirection(n, n, alpha);
    EXPECT_NEAR(at_normal.z, 1.0, 1e-15) << alpha;
    for (const double theta_deg : {20.0, 60.0, 85.0}) {
      const double t = theta_deg * kPi / 180.0;
      const Vec3 v = {std::sin(t), 0.0, std::cos(t)};
      const Vec3 r = IblSpecularDirection(n, v, alpha);
      const double s = alpha * (1.0 - std::cos(t));
      const double want = std::atan2((1.0 - s) * std::sin(t), (1.0 - s) * std::cos(t) + s);
      EXPECT_NEAR(std::atan2(-r.x, r.z), want, 1e-12) << alpha << " " << theta_deg;
      EXPECT_NEAR(r.y, 0.0, 1e-15);
      EXPECT_NEAR(r.x * r.x + r.y * r.y + r.z * r.z, 1.0, 1e-12);
    }
  }
}

TEST(IblPack, BroadDirectionMovesTheMirrorDirectionTowardTheNormalByAlpha) {
  const Vec3 n = {0.0, 0.0, 1.0};
  for (const double alpha : {0.1, 0.5, 1.0}) {
    for (const double theta_deg : {0.0, 20.0, 60.0, 85.0}) {
      const double t = theta_deg * kPi / 180.0;
      const Vec3 v = {std::sin(t), 0.0, std::cos(t)};
      const Vec3 r = IblBroadDirection(n, v, alpha);
      const double want =
          std::atan2((1.0 - alpha) * std::sin(t), (1.0 - alpha) * std::cos(t) + alpha);
      EXPECT_NEAR(std::atan2(-r.x, r.z), want, 1e-12) << alpha << " " << theta_deg;
      EXPECT_NEAR(r.x * r.x + r.y * r.y + r.z * r.z, 1.0, 1e-12);
    }
  }
}

}  // namespace
}  // namespace brdf
