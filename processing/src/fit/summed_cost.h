// The Ceres residual blocks of a fit (private to brdf_fit): one block stands for many samples
// and hands Ceres the equivalent residuals of their summed JᵀJ and Jᵀr, from a model's kernel
// (CompressedCost, any loss) or from its linear form (LinearCost, engine models under ngan).
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "brdf/fit/fit.h"
#include "loss.h"

namespace brdf::processing::detail {

// One Ceres residual block standing for the samples [begin, end) of a block's problem.
//
// Why not a residual per sample: Levenberg-Marquardt uses the residuals r and Jacobian J of a
// block only through ½‖r‖² (the cost), JᵀJ and Jᵀr (the step, the gradient, the Jacobi
// scaling from diag JᵀJ and the predicted decrease ‖r‖² − ‖r + Jδ‖² = −2δᵀJᵀr − δᵀJᵀJδ). Any
// (r', J') with ‖r'‖ = ‖r‖, J'ᵀJ' = JᵀJ and J'ᵀr' = Jᵀr therefore gives Ceres the same
// iterations. This block sums JᵀJ and Jᵀr over its samples (the kernels' hand-written
// derivatives, fit_kernels.h) and hands Ceres N + 1 residuals: with JᵀJ = QΛQᵀ, J' = Λ^½Qᵀ and
// r'ᵢ = qᵢᵀJᵀr/√λᵢ (rows 0…N−1; Jᵀr lies in the range of JᵀJ), and a last row of zero slope
// carrying the rest of ‖r‖² (‖r'₀…N−1‖² = ‖P r‖² ≤ ‖r‖², P the projection on J's range).
// Ceres' cost, gradient, steps and summary are those of the per-sample problem, without a
// samples × N Jacobian to store and multiply.
//
// A robust loss is applied here per sample and channel, as Ceres applies one per residual
// block (Cauchy's ρ'' < 0, so Ceres' corrector scales r and J by √ρ'): the cost sums ρ(r²),
// JᵀJ and Jᵀr carry ρ'.
template <int kN>
class SummedCost : public ceres::CostFunction {
 public:
  SummedCost() {
    set_num_residuals(kN + 1);
    mutable_parameter_block_sizes()->push_back(kN);
  }
  // The gradient at the last point the Jacobian was evaluated, held values included (in the
  // fitter's coordinates), for BoundWatch: Ceres evaluates the Jacobian at every accepted point
  // before its callbacks run.
  mutable std::array<double, kN> last_gradient_{};

 protected:
  // Hands Ceres the equivalent residuals of `cost` = Σ r² (or Σ ρ), h = JᵀJ (upper triangle
  // used) and g = Jᵀr in the material's values, with dvdx the slopes of the values in the
  // fitter's coordinates (0 for held values) and dvdx_all the slopes without holding.
  bool Compress(double cost, const Eigen::Matrix<double, kN, kN>& h,
                const Eigen::Matrix<double, kN, 1>& g, const double* dvdx, const double* dvdx_all,
                double* residuals, double* jo) const {
    if (!std::isfinite(cost)) return false;
    if (jo == nullptr) {
      for (int i = 0; i < kN; ++i) residuals[i] = 0;
      residuals[kN] = std::sqrt(cost);
      return true;
    }
    Eigen::Matrix<double, kN, kN> hx;
    Eigen::Matrix<double, kN, 1> gx;
    for (int i = 0; i < kN; ++i) {
      gx(i) = g(i) * dvdx[i];
      for (int k = i; k < kN; ++k) hx(i, k) = hx(k, i) = h(i, k) * dvdx[i] * dvdx[k];
    }
    if (!hx.allFinite() || !gx.allFinite()) return false;
    for (int i = 0; i < kN; ++i) last_gradient_[static_cast<std::size_t>(i)] = g(i) * dvdx_all[i];
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kN, kN>> eig(hx);
    const auto& lambda = eig.eigenvalues();
    const auto& q = eig.eigenvectors();
    const double floor = std::max(0.0, lambda.maxCoeff()) * 1e-14;
    double projected = 0;
    // jo: row-major, (kN + 1) × kN
    for (int i = 0; i < kN; ++i) {
      const double l = std::max(0.0, lambda(i));
      const double root = std::sqrt(l);
      for (int k = 0; k < kN; ++k) jo[i * kN + k] = root * q(k, i);
      residuals[i] = l > floor ? q.col(i).dot(gx) / root : 0.0;
      projected += residuals[i] * residuals[i];
    }
    for (int k = 0; k < kN; ++k) jo[kN * kN + k] = 0;
    residuals[kN] = std::sqrt(std::max(0.0, cost - projected));
    return true;
  }
  // The values v of the fitter's coordinates x, their slopes dv/dx, and those without holding.
  static void Values(const double* x, const std::array<bool, kN>& log_scale,
                     const std::array<bool, kN>* fixed, double* v, double* dvdx, double* dvdx_all) {
    for (int i = 0; i < kN; ++i) {
      const bool log = log_scale[static_cast<std::size_t>(i)];
      v[i] = log ? std::exp(x[i]) : x[i];
      dvdx_all[i] = log ? v[i] : 1.0;
      // A value held at its bound (SolveBlock) has no slope: Levenberg-Marquardt leaves it.
      dvdx[i] = fixed != nullptr && (*fixed)[static_cast<std::size_t>(i)] ? 0.0 : dvdx_all[i];
    }
  }
};

template <class K>
class CompressedCost final : public SummedCost<K::kN> {
 public:
  static constexpr int kN = K::kN;

  CompressedCost(const std::vector<typename K::Geom>* geom, const std::vector<LossSample>* loss,
                 std::size_t begin, std::size_t end, int channel, FitLoss loss_kind,
                 double robust_scale, const std::array<bool, kN>& log_scale,
                 const std::array<bool, kN>* fixed = nullptr)
      : geom_(geom),
        loss_(loss),
        begin_(begin),
        end_(end),
        channel_(channel),
        loss_kind_(loss_kind),
        b2_(robust_scale * robust_scale),
        log_scale_(log_scale),
        fixed_(fixed) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double v[kN], dvdx[kN], dvdx_all[kN];
    this->Values(parameters[0], log_scale_, fixed_, v, dvdx, dvdx_all);
    const bool jac = jacobians != nullptr && jacobians[0] != nullptr;
    // Samples in chunks: the first pass evaluates the chunk's residuals and their slopes (times
    // √ρ' under a robust loss) into columns, the second sums JᵀJ and Jᵀr over the chunk as dot
    // products of those columns, so no sum is carried from sample to sample through memory.
    constexpr int kRows = 240;  // a multiple of 3: whole samples of an engine model
    alignas(16) double rows_r[kRows];
    alignas(16) double rows_j[kN][kRows];
    double cost = 0;  // Σ r², or Σ ρ(r²)
    Eigen::Matrix<double, kN, kN> h = Eigen::Matrix<double, kN, kN>::Zero();
    Eigen::Matrix<double, kN, 1> g = Eigen::Matrix<double, kN, 1>::Zero();
    int row = 0;
    auto flush = [&] {
      using Column = Eigen::Map<const Eigen::VectorXd, Eigen::Aligned16>;
      const Column r(rows_r, row);
      for (int i = 0; i < kN; ++i) {
        const Column ji(rows_j[i], row);
        g(i) += ji.dot(r);
        for (int k = i; k < kN; ++k) h(i, k) += ji.dot(Column(rows_j[k], row));
      }
      row = 0;
    };
    auto add = [&](const LossSample& ls, int c, double f, const double* df) {
      double slope;
      const double r = LossResidual(loss_kind_, f, ls.target[static_cast<std::size_t>(c)],
                                    ls.cos_in, ls.sqrt_w, &slope);
      const double sq = r * r;
      double root_weight = 1;
      if (b2_ > 0) {
        cost += b2_ * std::log1p(sq / b2_);
        root_weight = std::sqrt(1.0 / (1.0 + sq / b2_));
      } else {
        cost += sq;
      }
      if (!jac) return;
      rows_r[row] = root_weight * r;
      const double s = root_weight * slope;
      for (int i = 0; i < kN; ++i) rows_j[i][row] = s * df[i];
      ++row;
    };
    const std::vector<typename K::Geom>& geom = *geom_;
    const std::vector<LossSample>& loss = *loss_;
    for (std::size_t k = begin_; k < end_; ++k) {
      if constexpr (K::kLegacy) {
        double df[kN];
        const double f = K::Eval(geom[k], v, jac ? df : nullptr);
        add(loss[k], channel_, f, df);
      } else {
        double f[3], df[3][kN];
        K::Eval(geom[k], v, f, jac ? df : nullptr);
        for (int c = 0; c < 3; ++c) add(loss[k], c, f[c], df[c]);
      }
      if (row == kRows) flush();
    }
    if (row > 0) flush();
    return this->Compress(cost, h, g, dvdx, dvdx_all, residuals, jac ? jacobians[0] : nullptr);
  }

 private:
  const std::vector<typename K::Geom>* geom_;
  const std::vector<LossSample>* loss_;
  std::size_t begin_, end_;
  int channel_;
  FitLoss loss_kind_;
  double b2_;
  std::array<bool, kN> log_scale_;
  const std::array<bool, kN>* fixed_;
};

// What LinearCost needs of a sample: the linear form's geometry, the ngan weight
// w = √(solid-angle weight)·cosθin and the measurement (r_c = w·(f_c − m_c)).
template <class L>
struct LinearSample {
  typename L::Geom g;
  double w;
  std::array<double, 3> m;
};

// The same residual block as CompressedCost for an engine model under the ngan loss without a
// robust loss, from the model's linear form (fit_kernels.h explains it): per sample the basis
// functions u = (b, db/d shape), the three residuals, Σ r², Σ w·r_c·u and the moments Σ w²·u·uᵀ;
// JᵀJ and Jᵀr follow from those sums and the coefficients' slopes, once per evaluation. A
// cost-only evaluation (Ceres testing a step) computes b and Σ r² only.
template <class L>
class LinearCost final : public SummedCost<L::kN> {
 public:
  static constexpr int kN = L::kN, kB = L::kBasis, kU = 2 * L::kBasis;

  LinearCost(const std::vector<LinearSample<L>>* samples, std::size_t begin, std::size_t end,
             const std::array<bool, kN>& log_scale, const std::array<bool, kN>* fixed,
             const bool* smooth)
      : samples_(samples),
        begin_(begin),
        end_(end),
        log_scale_(log_scale),
        fixed_(fixed),
        smooth_(smooth) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double v[kN], dvdx[kN], dvdx_all[kN];
    this->Values(parameters[0], log_scale_, fixed_, v, dvdx, dvdx_all);
    const bool jac = jacobians != nullptr && jacobians[0] != nullptr;
    const typename L::Shape shape = L::ShapeOf(v[kN - 1]);
    double coef[3][kB], dcoef[3][kB][kN];
    L::Coefficients(v, smooth_ != nullptr && *smooth_, coef, dcoef);
    const LinearSample<L>* samples = samples_->data();
    double cost[3] = {0, 0, 0};
    Eigen::Matrix<double, kN, kN> h = Eigen::Matrix<double, kN, kN>::Zero();
    Eigen::Matrix<double, kN, 1> g = Eigen::Matrix<double, kN, 1>::Zero();
    if (!jac) {
      for (std::size_t k = begin_; k < end_; ++k) {
        const LinearSample<L>& s = samples[k];
        double b[kB];
        L::Basis(s.g, shape, b, nullptr);
        for (int c = 0; c < 3; ++c) {
          double f = 0;
          for (int j = 0; j < kB; ++j) f += coef[c][j] * b[j];
          const double r = s.w * (f - s.m[static_cast<std::size_t>(c)]);
          cost[c] += r * r;
        }
      }
      return this->Compress(cost[0] + cost[1] + cost[2], h, g, dvdx, dvdx_all, residuals, nullptr);
    }
    double mom[kU][kU] = {}, wru[3][kU] = {};
    for (std::size_t k = begin_; k < end_; ++k) {
      const LinearSample<L>& s = samples[k];
      double u[kU];
      L::Basis(s.g, shape, u, u + kB);
      for (int c = 0; c < 3; ++c) {
        double f = 0;
        for (int j = 0; j < kB; ++j) f += coef[c][j] * u[j];
        const double r = s.w * (f - s.m[static_cast<std::size_t>(c)]);
        cost[c] += r * r;
        const double wr = s.w * r;
        for (int j = 0; j < kU; ++j)
          if (j != L::kUnused) wru[c][j] += wr * u[j];
      }
      double wu[kU];
      for (int j = 0; j < kU; ++j) wu[j] = s.w * u[j];
      for (int i = 0; i < kU; ++i)
        for (int j = i; j < kU; ++j)
          if (i != L::kUnused && j != L::kUnused) mom[i][j] += wu[i] * wu[j];
    }
    for (int i = 0; i < kU; ++i)
      for (int j = 0; j < i; ++j) mom[i][j] = mom[j][i];
    // Column i of channel c in terms of u: (dcoef[c][·][i], 0) for the non-shape values,
    // (0, coef[c][·]) for the shape value.
    for (int c = 0; c < 3; ++c) {
      double a[kN][kU] = {};
      for (int i = 0; i + 1 < kN; ++i)
        for (int j = 0; j < kB; ++j) a[i][j] = dcoef[c][j][i];
      for (int j = 0; j < kB; ++j) a[kN - 1][kB + j] = coef[c][j];
      double ma[kN][kU];  // mom·a_i
      for (int i = 0; i < kN; ++i)
        for (int p = 0; p < kU; ++p) {
          double sum = 0;
          for (int q = 0; q < kU; ++q) sum += mom[p][q] * a[i][q];
          ma[i][p] = sum;
        }
      for (int i = 0; i < kN; ++i) {
        double gi = 0;
        for (int q = 0; q < kU; ++q) gi += a[i][q] * wru[c][q];
        g(i) += gi;
        for (int k = i; k < kN; ++k) {
          double hik = 0;
          for (int q = 0; q < kU; ++q) hik += a[i][q] * ma[k][q];
          h(i, k) += hik;
        }
      }
    }
    return this->Compress(cost[0] + cost[1] + cost[2], h, g, dvdx, dvdx_all, residuals,
                          jacobians[0]);
  }

 private:
  const std::vector<LinearSample<L>>* samples_;
  std::size_t begin_, end_;
  std::array<bool, kN> log_scale_;
  const std::array<bool, kN>* fixed_;
  const bool* smooth_;
};

}  // namespace brdf::processing::detail
