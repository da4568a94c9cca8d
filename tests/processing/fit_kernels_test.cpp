// The fitter's hand-written model derivatives (processing/src/fit/fit_kernels.h).
//
// Oracles: the value of every kernel against models::EvaluateRgb / EvaluateChannel (the one
// formula of each model that evaluation and the simulator use), and its partial derivatives
// against Ceres' automatic differentiation of that same formula (ceres::Jet), at random
// directions above the surface and random parameters inside their ranges (away from the
// floors where a formula clamps, whose one-sided slopes Jets and kernels agree on trivially).
// A wrong derivative would still let a fit converge, more slowly and to the same point, so
// only this test catches it.
#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "brdf/core/models.h"
#include "fit_kernels.h"

namespace brdf::processing::kernels {
namespace {

ShadingGeometry RandomGeometry(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> theta(0.0, 85.0), phi(0.0, 360.0);
  return ShadingGeometry::Of(SphericalDirectionDeg(theta(rng), 0.0),
                             SphericalDirectionDeg(theta(rng), phi(rng)));
}

// |a − b| within `rel` of the larger magnitude (or of 1e-12 near zero).
void ExpectClose(double a, double b, double rel, const std::string& what) {
  EXPECT_NEAR(a, b, rel * std::max({std::fabs(a), std::fabs(b), 1e-12})) << what;
}

// Legacy kernels: one channel's (a, b, shape), shape drawn log-uniformly in [lo, hi].
template <class K>
void CheckLegacy(Model model, double shape_lo, double shape_hi) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  using J = ceres::Jet<double, 3>;
  for (int trial = 0; trial < 400; ++trial) {
    const ShadingGeometry g = RandomGeometry(rng);
    const double v[3] = {unit(rng), unit(rng), shape_lo * std::pow(shape_hi / shape_lo, unit(rng))};
    double grad[3];
    const double f = K::Eval(K::Prepare(g), v, grad);
    const std::string where = std::string(ModelName(model)) + " trial " + std::to_string(trial);
    ExpectClose(f, models::EvaluateChannel(model, g, v[0], v[1], v[2]), 1e-11, where + " value");
    double no_grad_value = K::Eval(K::Prepare(g), v, nullptr);
    EXPECT_EQ(no_grad_value, f) << where;
    const J jet = models::EvaluateChannel(model, g, J(v[0], 0), J(v[1], 1), J(v[2], 2));
    for (int i = 0; i < 3; ++i)
      ExpectClose(grad[i], jet.v[i], 1e-9, where + " d/dvalue " + std::to_string(i));
  }
}

TEST(FitKernels, LegacyModelsMatchTheirFormulaAndItsJetDerivatives) {
  CheckLegacy<GgxKernel>(Model::kGgx, 0.01, 1.0);
  CheckLegacy<WardKernel>(Model::kWard, 0.02, 1.0);
  CheckLegacy<LafortuneKernel>(Model::kLafortune, 1.0, 2000.0);
  CheckLegacy<BlinnPhongKernel>(Model::kBlinnPhong, 1.0, 2000.0);
  // Lambert: ρ/π.
  const double rho[1] = {0.7};
  double grad[1];
  EXPECT_DOUBLE_EQ(LambertKernel::Eval({}, rho, grad), 0.7 / kPi);
  EXPECT_DOUBLE_EQ(grad[0], 1.0 / kPi);
}

// Engine kernels: the whole value layout; the shape slider (last value) within [lo, hi].
template <class K>
void CheckEngine(Model model, double shape_lo, double shape_hi) {
  constexpr int kN = K::kN;
  ASSERT_EQ(kN, DescribeModel(model).value_count) << ModelName(model);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0), shape(shape_lo, shape_hi);
  using J = ceres::Jet<double, kN>;
  for (int trial = 0; trial < 400; ++trial) {
    const ShadingGeometry g = RandomGeometry(rng);
    double v[kN];
    for (int i = 0; i < kN; ++i) v[i] = unit(rng);
    v[kN - 1] = shape(rng);
    double f[3], grad[3][kN], f_only[3];
    K::Eval(K::Prepare(g), v, f, grad);
    K::Eval(K::Prepare(g), v, f_only, nullptr);
    const std::array<double, 3> want = models::EvaluateRgb(model, g, v);
    J x[kN];
    for (int i = 0; i < kN; ++i) x[i] = J(v[i], i);
    const std::array<J, 3> jet = models::EvaluateRgb(model, g, x);
    for (int c = 0; c < 3; ++c) {
      const std::string where = std::string(ModelName(model)) + " trial " + std::to_string(trial) +
                                " channel " + std::to_string(c);
      ExpectClose(f[c], want[static_cast<std::size_t>(c)], 1e-11, where + " value");
      EXPECT_EQ(f_only[c], f[c]) << where;
      for (int i = 0; i < kN; ++i)
        ExpectClose(grad[c][i], jet[static_cast<std::size_t>(c)].v[i], 1e-9,
                    where + " d/dvalue " + std::to_string(i));
    }
  }
}

TEST(FitKernels, EngineModelsMatchTheirFormulaAndItsJetDerivatives) {
  CheckEngine<UnrealKernel>(Model::kUnrealDefaultLit, 0.05, 1.0);  // roughness
  CheckEngine<HdrpKernel>(Model::kUnityHdrpLit, 0.0, 0.95);        // smoothness, floor at 0.99
  CheckEngine<UrpKernel>(Model::kUnityUrpLit, 0.0, 0.9);           // smoothness, floor at 0.9116
  // The specular-colour variants, evaluated through their linear forms.
  CheckEngine<HdrpSpecularKernel>(Model::kUnityHdrpLitSpecular, 0.0, 0.95);
  CheckEngine<UrpSpecularKernel>(Model::kUnityUrpLitSpecular, 0.0, 0.9);
}

// Linear forms (LinearCost): f_c = Σ_j coef[c][j]·basis_j against the formula, and the
// derivatives LinearCost assembles from them (Σ_j dcoef·basis for the non-shape values,
// Σ_j coef·dbasis for the shape) against Jets. `smooth` tests Unreal's F90 held at 1, which
// must equal the formula wherever 50·f0.g ≥ 1.
template <class L>
void CheckLinear(Model model, double shape_lo, double shape_hi, bool smooth = false) {
  constexpr int kN = L::kN, kB = L::kBasis;
  ASSERT_EQ(kN, DescribeModel(model).value_count) << ModelName(model);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0), shape(shape_lo, shape_hi);
  using J = ceres::Jet<double, kN>;
  int kinked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const ShadingGeometry g = RandomGeometry(rng);
    double v[kN];
    for (int i = 0; i < kN; ++i) v[i] = unit(rng);
    v[kN - 1] = shape(rng);
    if (smooth && !L::OnSmoothPiece(v)) continue;
    kinked += L::OnSmoothPiece(v) ? 0 : 1;
    double b[kB], db[kB], b_only[kB], coef[3][kB], dcoef[3][kB][kN];
    const typename L::Geom geom = L::Prepare(g);
    L::Basis(geom, L::ShapeOf(v[kN - 1]), b, db);
    L::Basis(geom, L::ShapeOf(v[kN - 1]), b_only, nullptr);
    L::Coefficients(v, smooth, coef, dcoef);
    const std::array<double, 3> want = models::EvaluateRgb(model, g, v);
    J x[kN];
    for (int i = 0; i < kN; ++i) x[i] = J(v[i], i);
    const std::array<J, 3> jet = models::EvaluateRgb(model, g, x);
    for (int j = 0; j < kB; ++j) EXPECT_EQ(b_only[j], b[j]);
    // The entry of u = (b, db) LinearCost leaves out of its sums enters no column.
    if (L::kUnused >= kB) {
      EXPECT_EQ(db[L::kUnused - kB], 0.0);
    } else {
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i + 1 < kN; ++i) EXPECT_EQ(dcoef[c][L::kUnused][i], 0.0);
    }
    for (int c = 0; c < 3; ++c) {
      const std::string where = std::string(ModelName(model)) + " linear trial " +
                                std::to_string(trial) + " channel " + std::to_string(c);
      double f = 0, grad[kN] = {};
      for (int j = 0; j < kB; ++j) {
        f += coef[c][j] * b[j];
        for (int i = 0; i + 1 < kN; ++i) grad[i] += dcoef[c][j][i] * b[j];
        grad[kN - 1] += coef[c][j] * db[j];
      }
      ExpectClose(f, want[static_cast<std::size_t>(c)], 1e-11, where + " value");
      for (int i = 0; i < kN; ++i)
        ExpectClose(grad[i], jet[static_cast<std::size_t>(c)].v[i], 1e-9,
                    where + " d/dvalue " + std::to_string(i));
    }
  }
  // Unreal's random points fall on both sides of the kink (F90 < 1 needs f0.g < 0.02).
  if (model == Model::kUnrealDefaultLit && !smooth) {
    EXPECT_GT(kinked, 0);
  }
}

TEST(FitKernels, LinearFormsMatchTheFormulaAndItsJetDerivatives) {
  CheckLinear<UnrealLinear>(Model::kUnrealDefaultLit, 0.05, 1.0);
  CheckLinear<UnrealLinear>(Model::kUnrealDefaultLit, 0.05, 1.0, /*smooth=*/true);
  CheckLinear<HdrpLinear>(Model::kUnityHdrpLit, 0.0, 0.95);
  CheckLinear<UrpLinear>(Model::kUnityUrpLit, 0.0, 0.9);
  CheckLinear<HdrpSpecularLinear>(Model::kUnityHdrpLitSpecular, 0.0, 0.95);
  CheckLinear<UrpSpecularLinear>(Model::kUnityUrpLitSpecular, 0.0, 0.9);
}

// HDRP's diffuse colour is base·(1 − max(specular colour)): with two channels tied for the
// largest, the formula's comparisons pick the first, and so does the slope (as on Jets).
TEST(FitKernels, HdrpSpecularMaxSlopeGoesToTheFirstLargestChannel) {
  std::mt19937_64 rng(23);
  const ShadingGeometry g = RandomGeometry(rng);
  for (const std::array<double, 3>& spec :
       {std::array<double, 3>{0.4, 0.4, 0.1}, std::array<double, 3>{0.1, 0.4, 0.4},
        std::array<double, 3>{0.3, 0.3, 0.3}}) {
    const double v[7] = {0.6, 0.5, 0.4, spec[0], spec[1], spec[2], 0.5};
    double f[3], grad[3][7];
    HdrpSpecularKernel::Eval(HdrpSpecularKernel::Prepare(g), v, f, grad);
    using J = ceres::Jet<double, 7>;
    J x[7];
    for (int i = 0; i < 7; ++i) x[i] = J(v[i], i);
    const std::array<J, 3> jet = models::EvaluateRgb(Model::kUnityHdrpLitSpecular, g, x);
    for (int c = 0; c < 3; ++c)
      for (int i = 3; i < 6; ++i)
        ExpectClose(grad[c][i], jet[static_cast<std::size_t>(c)].v[i], 1e-9,
                    "tie " + std::to_string(spec[0]) + " channel " + std::to_string(c) +
                        " d/dspecular " + std::to_string(i - 3));
  }
}

// Below the floors the shape no longer changes the value: the slope in it is 0, as for Jets.
TEST(FitKernels, RoughnessFloorsHaveZeroSlope) {
  std::mt19937_64 rng(3);
  const ShadingGeometry g = RandomGeometry(rng);
  double f[3], grad_u[3][6], grad_h[3][5], grad_r[3][5];
  const double unreal[6] = {0.5, 0.4, 0.3, 0.2, 0.5, 0.0005};  // roughness⁴ < 1e-12
  UnrealKernel::Eval(UnrealKernel::Prepare(g), unreal, f, grad_u);
  const double hdrp[5] = {0.5, 0.4, 0.3, 0.2, 0.995};  // α = 0.005² < 1e-4
  HdrpKernel::Eval(HdrpKernel::Prepare(g), hdrp, f, grad_h);
  const double urp[5] = {0.5, 0.4, 0.3, 0.2, 0.95};  // 0.05² < 2⁻⁷
  UrpKernel::Eval(UrpKernel::Prepare(g), urp, f, grad_r);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(grad_u[c][5], 0.0);
    EXPECT_EQ(grad_r[c][4], 0.0);
  }
  // HDRP's Disney diffuse still depends on the unfloored perceptual roughness.
  using J = ceres::Jet<double, 5>;
  J x[5];
  for (int i = 0; i < 5; ++i) x[i] = J(hdrp[i], i);
  const std::array<J, 3> jet = models::EvaluateRgb(Model::kUnityHdrpLit, g, x);
  for (int c = 0; c < 3; ++c)
    ExpectClose(grad_h[c][4], jet[static_cast<std::size_t>(c)].v[4], 1e-9, "hdrp floor");
}

}  // namespace
}  // namespace brdf::processing::kernels
