// FitMaterial: data preparation, the deterministic multi-start sweep, the Ceres refinement and
// the report (brdf/fit/fit.h explains the method).
#include "brdf/fit/fit.h"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/core/parallel.h"
#include "fit_data.h"
#include "fit_kernels.h"

namespace brdf::processing {

namespace {

using Clock = std::chrono::steady_clock;

// ----------------------------------------------------------------------------------------------
// Residuals.

constexpr double kCbrtEpsilon = 1e-6;

template <class T>
T Residual(FitLoss loss, const T& f, double m, double cos_in, double sqrt_w) {
  using std::cbrt;
  using std::log;
  switch (loss) {
    case FitLoss::kNgan:
      return sqrt_w * cos_in * (f - m);
    case FitLoss::kLog:
      return sqrt_w * (log(T(1) + cos_in * f) - std::log1p(cos_in * m));
    case FitLoss::kCbrt:
      return sqrt_w * (cbrt(cos_in * f + kCbrtEpsilon) - std::cbrt(cos_in * m + kCbrtEpsilon));
  }
  return T(0);
}

// The fitted unknowns: one block per independent problem.
struct Block {
  std::vector<int> value_index;  // into Material::values
  int channel = -1;
};

std::vector<Block> BlocksOf(Model model) {
  const ModelInfo& info = DescribeModel(model);
  std::vector<Block> blocks;
  if (models::ChannelsIndependent(model)) {
    for (int c = 0; c < 3; ++c) {
      Block b;
      b.channel = c;
      for (const ParameterInfo& p : info.parameters) b.value_index.push_back(p.offset + c);
      blocks.push_back(b);
    }
  } else {
    Block b;
    for (int i = 0; i < info.value_count; ++i) b.value_index.push_back(i);
    blocks.push_back(b);
  }
  return blocks;
}

const ParameterInfo& ParameterOfValue(const ModelInfo& info, int value_index) {
  for (const ParameterInfo& p : info.parameters)
    if (value_index >= p.offset && value_index < p.offset + p.Count()) return p;
  return info.parameters.front();
}

// The residual of one sample and channel given the model value f, and its slope dr/df, as
// Residual above; `target` is the measurement in the loss' own terms (LossTarget, once per fit).
inline double LossResidual(FitLoss loss, double f, double target, double cos_in, double sqrt_w,
                           double* slope) {
  switch (loss) {
    case FitLoss::kNgan:
      *slope = sqrt_w * cos_in;
      return sqrt_w * cos_in * (f - target);
    case FitLoss::kLog: {
      const double u = 1.0 + cos_in * f;
      *slope = sqrt_w * cos_in / u;
      return sqrt_w * (std::log(u) - target);
    }
    case FitLoss::kCbrt: {
      const double q = std::cbrt(cos_in * f + kCbrtEpsilon);
      *slope = sqrt_w * cos_in / (3.0 * q * q);
      return sqrt_w * (q - target);
    }
  }
  *slope = 0;
  return 0;
}

double LossTarget(FitLoss loss, double m, double cos_in) {
  switch (loss) {
    case FitLoss::kNgan:
      return m;
    case FitLoss::kLog:
      return std::log1p(cos_in * m);
    case FitLoss::kCbrt:
      return std::cbrt(cos_in * m + kCbrtEpsilon);
  }
  return m;
}

// What the residuals need of a sample besides the model's geometry.
struct LossSample {
  double sqrt_w, cos_in;
  std::array<double, 3> target;
};

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

// Stops Ceres when a free value sits on one of its bounds with the gradient pointing out of
// the range (SolveBlock then holds it there). `released` values are ones found at their bound
// with the gradient pointing inwards; the gradient is only evaluated for them. With
// release_early_, also when a held value's gradient has turned inwards: SolveBlock then lets it
// go at once instead of after the free values have converged (Unreal from the generic start held
// specular at 0 for 11 slowly converging iterations). Only without the projected line search:
// then the last Jacobian Ceres evaluated is the one at the current point, not at a candidate.
template <int kN>
class BoundWatch final : public ceres::IterationCallback {
 public:
  using Gradient = std::function<std::array<double, kN>()>;
  BoundWatch(const double* x, const std::array<double, kN>& lo, const std::array<double, kN>& hi,
             const std::array<bool, kN>& fixed, const std::array<bool, kN>& released,
             Gradient gradient)
      : x_(x),
        lo_(lo),
        hi_(hi),
        fixed_(fixed),
        released_(released),
        gradient_(std::move(gradient)) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    bool check = false;
    for (std::size_t i = 0; i < kN; ++i) {
      if (fixed_[i] || !AtBound(i)) continue;
      if (!released_[i]) return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
      check = true;
    }
    bool held = false;
    for (std::size_t i = 0; i < kN; ++i) held |= fixed_[i];
    if (!check && !(held && release_early_)) return ceres::SOLVER_CONTINUE;
    const std::array<double, kN> g = gradient_();
    for (std::size_t i = 0; i < kN; ++i) {
      if (!fixed_[i] && check && Outward(i, g)) return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
      if (fixed_[i] && release_early_ && !Outward(i, g))
        return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool release_early_ = false;
  bool AtBound(std::size_t i) const { return AtLower(i) || AtUpper(i); }
  bool AtLower(std::size_t i) const { return x_[i] <= lo_[i] + 1e-12 * (1 + std::fabs(lo_[i])); }
  bool AtUpper(std::size_t i) const { return x_[i] >= hi_[i] - 1e-12 * (1 + std::fabs(hi_[i])); }
  // The cost decreases by leaving the range at value i (d cost/dx > 0 at the lower bound).
  bool Outward(std::size_t i, const std::array<double, kN>& g) const {
    return (AtLower(i) && g[i] > 0) || (AtUpper(i) && g[i] < 0);
  }

 private:
  const double* x_;
  const std::array<double, kN>&lo_, &hi_;
  const std::array<bool, kN>&fixed_, &released_;
  Gradient gradient_;
};
// ----------------------------------------------------------------------------------------------
// Costs in doubles.

// ½ Σ r² over `samples`, or with robust_scale b > 0 the Cauchy cost ½ Σ b²·ln(1 + r²/b²).
double Cost(const std::vector<FitSample>& samples, const Material& m, FitLoss loss,
            double robust_scale = 0) {
  const double b2 = robust_scale * robust_scale;
  double sum = 0;
  for (const FitSample& s : samples) {
    const std::array<double, 3> f = models::EvaluateRgb(m.model, s.g, m.values.data());
    for (int c = 0; c < 3; ++c) {
      const double r = Residual(loss, f[c], s.m[c], s.cos_in, s.sqrt_w);
      sum += robust_scale > 0 ? b2 * std::log1p(r * r / b2) : r * r;
    }
  }
  return 0.5 * sum;
}

double MedianAbsResidual(const std::vector<FitSample>& samples, const Material& m, FitLoss loss) {
  std::vector<double> r;
  r.reserve(samples.size() * 3);
  for (const FitSample& s : samples) {
    const std::array<double, 3> f = models::EvaluateRgb(m.model, s.g, m.values.data());
    for (int c = 0; c < 3; ++c)
      r.push_back(std::fabs(Residual(loss, f[c], s.m[c], s.cos_in, s.sqrt_w)));
  }
  if (r.empty()) return 0;
  auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  return *mid;
}

// The Cauchy scale b: options.robust_scale, or 1.4826 × the median |r| at `start` (the
// normal distribution's σ from its median absolute deviation), never below 1e-12.
double RobustScale(const std::vector<FitSample>& samples, const Material& start,
                   const FitOptions& options) {
  const double b = options.robust_scale > 0
                       ? options.robust_scale
                       : 1.4826 * MedianAbsResidual(samples, start, options.loss);
  return std::max(b, 1e-12);
}

// ----------------------------------------------------------------------------------------------
// The sweep.

std::vector<double> ShapeGrid(const ParameterInfo& p) {
  if (p.name == "n") return {1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 10000, 30000};
  if (p.name == "alpha")
    return {0.005, 0.01, 0.02, 0.035, 0.05, 0.07, 0.1, 0.14, 0.2, 0.28, 0.4, 0.56, 0.8, 1.0};
  // roughness / smoothness sliders in [0, 1]
  std::vector<double> grid;
  for (int i = 0; i <= 20; ++i) grid.push_back(0.025 + 0.95 * i / 20.0);
  return grid;
}

// Bounded least squares of m ≈ a·A + b·B for (a, b) ∈ [0, 1]² from the normal-equation sums.
struct Sums {
  double aa = 0, ab = 0, bb = 0, am = 0, bm = 0, mm = 0;
};
// ½ Σ (w·(m − a·A − b·B))² from the sums.
double SumsCost(const Sums& s, double a, double b) {
  return 0.5 * (s.mm - 2 * (a * s.am + b * s.bm) + a * a * s.aa + 2 * a * b * s.ab + b * b * s.bb);
}
std::pair<double, double> SolveBox(const Sums& s, bool two) {
  auto cost = [&](double a, double b) {
    return s.mm - 2 * (a * s.am + b * s.bm) + a * a * s.aa + 2 * a * b * s.ab + b * b * s.bb;
  };
  auto clamp01 = [](double v) { return std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0); };
  if (!two) return {clamp01(s.aa > 0 ? s.am / s.aa : 0), 0.0};
  std::vector<std::pair<double, double>> candidates;
  const double det = s.aa * s.bb - s.ab * s.ab;
  if (det > 1e-300 * std::max(1.0, s.aa * s.bb)) {
    const double a = (s.am * s.bb - s.bm * s.ab) / det;
    const double b = (s.bm * s.aa - s.am * s.ab) / det;
    if (a >= 0 && a <= 1 && b >= 0 && b <= 1) return {a, b};
  }
  for (double a : {0.0, 1.0})
    candidates.push_back({a, clamp01(s.bb > 0 ? (s.bm - a * s.ab) / s.bb : 0)});
  for (double b : {0.0, 1.0})
    candidates.push_back({clamp01(s.aa > 0 ? (s.am - b * s.ab) / s.aa : 0), b});
  auto best = candidates.front();
  for (const auto& c : candidates)
    if (cost(c.first, c.second) < cost(best.first, best.second)) best = c;
  return best;
}

struct Candidate {
  Material material;
  double cost = 0;
};

Material ClampIntoRange(Material m) {
  const ModelInfo& info = DescribeModel(m.model);
  for (const ParameterInfo& p : info.parameters)
    for (int c = 0; c < p.Count(); ++c) {
      double& v = m.values[static_cast<std::size_t>(p.offset + c)];
      v = std::clamp(std::isfinite(v) ? v : p.start, p.min, p.max);
    }
  return m;
}

bool SameStart(const Material& a, const Material& b) {
  for (std::size_t i = 0; i < a.values.size(); ++i)
    if (std::fabs(a.values[i] - b.values[i]) > 1e-9 * std::max(1.0, std::fabs(a.values[i])))
      return false;
  return true;
}

// ----------------------------------------------------------------------------------------------
// One Ceres refinement.

struct Refinement {
  Material material;
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
  ceres::TerminationType termination = ceres::FAILURE;
  std::string message;
};

// One block's outcome. Each block is its own Ceres problem: the blocks share no residual (the
// legacy models' channels are independent; an engine model is a single block).
struct BlockOutcome {
  std::vector<double> x;
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
  ceres::TerminationType termination = ceres::FAILURE;
  std::string message;
};

int Rank(ceres::TerminationType t) {  // worse outcomes rank higher
  switch (t) {
    case ceres::CONVERGENCE:
      return 0;
    case ceres::NO_CONVERGENCE:
      return 1;
    default:
      return 2;
  }
}

// Everything of a fit that runs over the samples, for one model's kernel K (fit_kernels.h):
// the geometry prepared once, the sweep and the Ceres refinements.
template <class K>
struct LinearOf {
  using type = K;  // none: LinearCost is not used
};
template <class K>
requires requires { typename K::Linear; }
struct LinearOf<K> {
  using type = typename K::Linear;
};

template <class K>
class KernelFit {
 public:
  static constexpr int kN = K::kN;
  static constexpr bool kHasLinear = requires { typename K::Linear; };
  using Linear = typename LinearOf<K>::type;

  KernelFit(const FitData& data, const FitOptions& options)
      : data_(data), options_(options), info_(DescribeModel(options.model)) {
    if constexpr (kHasLinear) {
      if (options.loss == FitLoss::kNgan && !options.robust) {
        linear_.reserve(data.samples.size());
        for (const FitSample& s : data.samples)
          linear_.push_back({Linear::Prepare(s.g), s.sqrt_w * s.cos_in, s.m});
        return;  // the kernel's geometry only if the sweep needs it (PrepareKernel)
      }
    }
    PrepareKernel();
  }

  // The kernel's geometry and the loss' targets, for the sweep, Cost and CompressedCost. Not
  // thread-safe: RunFit calls it (through Sweep and Cost) before any refinement starts.
  void PrepareKernel() const {
    if (!geom_.empty()) return;
    geom_.reserve(data_.samples.size());
    loss_.reserve(data_.samples.size());
    for (const FitSample& s : data_.samples) {
      geom_.push_back(K::Prepare(s.g));
      LossSample l{s.sqrt_w, s.cos_in, {}};
      for (std::size_t c = 0; c < 3; ++c) l.target[c] = LossTarget(options_.loss, s.m[c], s.cos_in);
      loss_.push_back(l);
    }
  }

  // ½ Σ r² of `m` over every `stride`-th sample, without a robust loss.
  double Cost(const Material& m, std::size_t stride = 1) const {
    PrepareKernel();
    double sum = 0, slope;
    for (std::size_t k = 0; k < geom_.size(); k += stride) {
      const LossSample& l = loss_[k];
      double f[3];
      if constexpr (K::kLegacy) {
        for (std::size_t c = 0; c < 3; ++c) {
          double v[kN];
          for (int i = 0; i < kN; ++i) v[i] = m.values[c + 3 * static_cast<std::size_t>(i)];
          f[c] = K::Eval(geom_[k], v, nullptr);
        }
      } else {
        K::Eval(geom_[k], m.values.data(), f, nullptr);
      }
      for (std::size_t c = 0; c < 3; ++c) {
        const double r = LossResidual(options_.loss, f[c], l.target[c], l.cos_in, l.sqrt_w, &slope);
        sum += r * r;
      }
    }
    return 0.5 * sum;
  }

  // The sweep on every `stride`-th sample: candidates with their cost on those samples.
  std::vector<Candidate> Sweep(std::size_t stride) const {
    PrepareKernel();
    std::vector<Candidate> out;
    if constexpr (K::kLegacy)
      SweepLegacy(stride, &out);
    else
      SweepEngine(stride, &out);
    return out;
  }

  Refinement Refine(const Material& start, double robust_scale) const {
    const std::vector<Block> blocks = BlocksOf(start.model);
    std::vector<BlockOutcome> outcomes(blocks.size());
    // Independent blocks run on their own threads when there are threads to spare.
    const int parallel = std::min<int>(options_.threads, static_cast<int>(blocks.size()));
    if (parallel > 1) {
      ParallelChunks(blocks.size(), 1, parallel, nullptr, [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) outcomes[k] = Solve(start, blocks[k], robust_scale, 1);
      });
    } else {
      for (std::size_t b = 0; b < blocks.size(); ++b)
        outcomes[b] = Solve(start, blocks[b], robust_scale, options_.threads);
    }

    Refinement out;
    out.material = start;
    out.termination = ceres::CONVERGENCE;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const BlockOutcome& summary = outcomes[b];
      SetBlock(blocks[b], outcomes[b].x, &out.material);
      out.initial_cost += summary.initial_cost;
      out.final_cost += summary.final_cost;
      out.iterations += summary.iterations;
      if (Rank(summary.termination) >= Rank(out.termination)) {
        out.termination = summary.termination;
        out.message = (blocks.size() > 1 ? "channel " + std::to_string(b) + ": " : std::string()) +
                      summary.message;
      }
    }
    out.material = ClampIntoRange(out.material);
    return out;
  }

 private:
  // Legacy models: for each shape, kd and ks (or f0, ρs) per channel in closed form. The model
  // is affine in them, f = a·A + b·B + C, and the kernel's slopes at a = b = 0 are A and B.
  void SweepLegacy(std::size_t stride, std::vector<Candidate>* out) const {
    const bool two = kN == 3;
    const std::vector<double> grid =
        info_.shape_parameter >= 0
            ? ShapeGrid(info_.parameters[static_cast<std::size_t>(info_.shape_parameter)])
            : std::vector<double>{0.0};
    for (const double shape : grid) {
      std::array<Sums, 3> s{};
      for (std::size_t k = 0; k < geom_.size(); k += stride) {
        double v[kN] = {}, d[kN];
        v[kN - 1] = kN == 3 ? shape : 0.0;
        const double base = K::Eval(geom_[k], v, d);
        const double a = d[0], b = two ? d[1] : 0.0;
        const FitSample& x = data_.samples[k];
        const double w = x.sqrt_w * x.cos_in;
        const double wa = w * a, wb = w * b;
        for (std::size_t c = 0; c < 3; ++c) {
          const double wm = w * (x.m[c] - base);
          s[c].aa += wa * wa, s[c].ab += wa * wb, s[c].bb += wb * wb;
          s[c].am += wa * wm, s[c].bm += wb * wm, s[c].mm += wm * wm;
        }
      }
      Material m;
      m.model = options_.model;
      double cost = 0;
      for (std::size_t c = 0; c < 3; ++c) {
        const auto [a, b] = SolveBox(s[c], two);
        m.values[static_cast<std::size_t>(info_.parameters[0].offset) + c] = a;
        if (two) {
          m.values[static_cast<std::size_t>(info_.parameters[1].offset) + c] = b;
          m.values[static_cast<std::size_t>(info_.parameters[2].offset) + c] = shape;
        }
        cost += SumsCost(s[c], a, b);
      }
      out->push_back({m, options_.loss == FitLoss::kNgan ? cost : Cost(m, stride)});
    }
  }

  // Engine models: a grid over the shape slider and metallic (or a grey specular colour); the
  // base colour per channel in closed form (affine in it once the others are fixed).
  void SweepEngine(std::size_t stride, std::vector<Candidate>* out) const {
    const ParameterInfo& shape_p =
        info_.parameters[static_cast<std::size_t>(info_.shape_parameter)];
    const ParameterInfo& second = info_.parameters[1];  // metallic or specular_color
    const std::vector<double> second_grid =
        second.rgb ? std::vector<double>{0.02, 0.04, 0.08, 0.2, 0.5, 0.9}
                   : std::vector<double>{0.0, 0.5, 1.0};
    for (const double shape : ShapeGrid(shape_p)) {
      for (const double level : second_grid) {
        Material m;
        m.model = options_.model;
        for (const ParameterInfo& p : info_.parameters)
          for (int c = 0; c < p.Count(); ++c)
            m.values[static_cast<std::size_t>(p.offset + c)] = p.start;
        for (int c = 0; c < second.Count(); ++c)
          m.values[static_cast<std::size_t>(second.offset + c)] = level;
        for (int c = 0; c < shape_p.Count(); ++c)
          m.values[static_cast<std::size_t>(shape_p.offset + c)] = shape;
        Material zero = m, one = m;
        for (std::size_t c = 0; c < 3; ++c) zero.values[c] = 0, one.values[c] = 1;
        std::array<Sums, 3> s{};
        for (std::size_t k = 0; k < geom_.size(); k += stride) {
          double f0[3], f1[3];
          K::Eval(geom_[k], zero.values.data(), f0, nullptr);
          K::Eval(geom_[k], one.values.data(), f1, nullptr);
          const FitSample& x = data_.samples[k];
          const double w = x.sqrt_w * x.cos_in;
          for (std::size_t c = 0; c < 3; ++c) {
            const double wa = w * (f1[c] - f0[c]), wm = w * (x.m[c] - f0[c]);
            s[c].aa += wa * wa, s[c].am += wa * wm, s[c].mm += wm * wm;
          }
        }
        double cost = 0;
        for (std::size_t c = 0; c < 3; ++c) {
          m.values[c] = SolveBox(s[c], false).first;
          cost += SumsCost(s[c], m.values[c], 0);
        }
        // Exact for the ngan loss wherever the model is affine in the base colour (Unreal's
        // saturate(50·f0.g) is not, below f0.g = 0.02): FitMaterial recomputes the best ones.
        out->push_back({m, options_.loss == FitLoss::kNgan ? cost : Cost(m, stride)});
      }
    }
  }

  // The values of `block` from the fitter's coordinates x.
  void SetBlock(const Block& block, const std::vector<double>& x, Material* m) const {
    for (std::size_t i = 0; i < block.value_index.size(); ++i) {
      const ParameterInfo& p = ParameterOfValue(info_, block.value_index[i]);
      m->values[static_cast<std::size_t>(block.value_index[i])] =
          p.log_scale ? std::exp(x[i]) : x[i];
    }
  }

  // One block's refinement, piece by piece where the model has a kink. Unreal's
  // F90 = saturate(50·f0.g) bends at f0.g = 0.02; Levenberg-Marquardt's local model is wrong
  // across it, and from the generic start Ceres bounced across it for 37 iterations (59 without
  // the projected line search) before it reached an optimum that lies above it. So from a start
  // above the kink the block is first solved with F90 held at 1, which is the engine's formula
  // itself wherever f0.g ≥ 0.02. A result strictly above the kink is then a solution of the
  // engine's formula too (the two agree in a neighbourhood of it: same cost, gradient and
  // optimality conditions); otherwise the engine's formula is solved from that result.
  BlockOutcome Solve(const Material& start, const Block& block, double robust_scale,
                     int threads) const {
    if constexpr (kHasLinear) {
      if (Linear::kKink && !linear_.empty() && Linear::OnSmoothPiece(start.values.data())) {
        const BlockOutcome smooth = SolveBlock(start, block, robust_scale, threads, true);
        Material end = start;
        SetBlock(block, smooth.x, &end);
        if (smooth.termination != ceres::FAILURE && smooth.termination != ceres::USER_FAILURE &&
            Linear::OnSmoothPiece(end.values.data()))
          return smooth;
        BlockOutcome rest = SolveBlock(end, block, robust_scale, threads, false);
        rest.initial_cost = smooth.initial_cost;
        rest.iterations += smooth.iterations;
        return rest;
      }
    }
    return SolveBlock(start, block, robust_scale, threads);
  }

  // One block's refinement. Ceres handles bounds by projecting each step onto them; when the
  // optimum lies on a bound (metallic 0, ks 0) with the gradient pointing out of the range, the
  // projected steps' predicted decrease is mostly the part cut off, the trust region shrinks
  // and Ceres crawls along the bound until the function tolerance stops it (57 iterations for
  // URP's metallic). So a value that reaches a bound with the gradient pointing outwards is held
  // there (an active set) and Ceres resumes on the others; a held value whose gradient turns
  // inwards at the end is released and Ceres resumes again. The result satisfies the same
  // optimality conditions (zero gradient in the free values, outward at the held ones).
  BlockOutcome SolveBlock(const Material& start, const Block& block, double robust_scale,
                          int threads, bool smooth = false) const {
    BlockOutcome out;
    out.x.resize(block.value_index.size());
    std::array<bool, kN> log_scale{}, fixed{}, released{};
    std::array<double, kN> lo{}, hi{};
    for (std::size_t i = 0; i < block.value_index.size(); ++i) {
      const ParameterInfo& p = ParameterOfValue(info_, block.value_index[i]);
      const double v = start.values[static_cast<std::size_t>(block.value_index[i])];
      out.x[i] = p.log_scale ? std::log(v) : v;
      log_scale[i] = p.log_scale;
      lo[i] = p.log_scale ? std::log(p.min) : p.min;
      hi[i] = p.log_scale ? std::log(p.max) : p.max;
      out.x[i] = std::clamp(out.x[i], lo[i], hi[i]);
    }
    ceres::Problem problem;
    // One residual block per thread (CompressedCost explains why not one per sample).
    const std::size_t n = data_.samples.size();
    const std::size_t parts = static_cast<std::size_t>(std::max(1, threads));
    auto make_cost = [&](std::size_t begin, std::size_t end,
                         const std::array<bool, kN>* held) -> SummedCost<kN>* {
      if constexpr (kHasLinear)
        if (!linear_.empty())
          return new LinearCost<Linear>(&linear_, begin, end, log_scale, held, &smooth);
      return new CompressedCost<K>(&geom_, &loss_, begin, end, block.channel, options_.loss,
                                   robust_scale, log_scale, held);
    };
    for (std::size_t t = 0; t < parts; ++t) {
      const std::size_t begin = n * t / parts, end = n * (t + 1) / parts;
      if (begin == end) continue;
      problem.AddResidualBlock(make_cost(begin, end, &fixed), nullptr, out.x.data());
    }
    for (std::size_t i = 0; i < block.value_index.size(); ++i) {
      problem.SetParameterLowerBound(out.x.data(), static_cast<int>(i), lo[i]);
      problem.SetParameterUpperBound(out.x.data(), static_cast<int>(i), hi[i]);
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    so.num_threads = threads;
    so.function_tolerance = 1e-10;
    so.parameter_tolerance = 1e-10;
    so.gradient_tolerance = 1e-12;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.update_state_every_iteration = true;
    // LinearCost (engine models, ngan loss): Ceres' projected line search would evaluate the
    // Jacobian at every candidate step as well as at every accepted point; the active set below
    // handles the bounds, the plain trust-region step needs the cost only (HDRP: the same 8
    // iterations with one Jacobian evaluation each instead of two).
    const bool linear = kHasLinear && !linear_.empty();
    if (linear) so.max_num_line_search_step_size_iterations = 0;
    // The whole gradient (held values included) for the decisions between rounds.
    const std::unique_ptr<SummedCost<kN>> whole(make_cost(0, n, nullptr));
    auto gradient = [&] {
      double residuals[kN + 1], jacobian[(kN + 1) * kN];
      const double* parameters[] = {out.x.data()};
      double* jacobians[] = {jacobian};
      std::array<double, kN> g{};
      if (!whole->Evaluate(parameters, residuals, jacobians)) return g;
      for (std::size_t i = 0; i < kN; ++i)
        for (std::size_t r = 0; r <= kN; ++r) g[i] += jacobian[r * kN + i] * residuals[r];
      return g;
    };
    std::vector<const SummedCost<kN>*> costs;
    {
      std::vector<ceres::ResidualBlockId> ids;
      problem.GetResidualBlocks(&ids);
      for (ceres::ResidualBlockId id : ids)
        costs.push_back(
            static_cast<const SummedCost<kN>*>(problem.GetCostFunctionForResidualBlock(id)));
    }
    auto last_gradient = [&costs] {
      std::array<double, kN> g{};
      for (const SummedCost<kN>* c : costs)
        for (std::size_t i = 0; i < kN; ++i) g[i] += c->last_gradient_[i];
      return g;
    };
    BoundWatch<kN> watch(out.x.data(), lo, hi, fixed, released, last_gradient);
    watch.release_early_ = linear;
    so.callbacks.push_back(&watch);
    auto outward = [&](std::size_t i, const std::array<double, kN>& g) {
      return watch.Outward(i, g);
    };
    int remaining = options_.max_iterations;
    for (int round = 0; round < 2 * kN + 2 && remaining > 0; ++round) {
      so.max_num_iterations = remaining;
      ceres::Solver::Summary summary;
      ceres::Solve(so, &problem, &summary);
      if (round == 0) out.initial_cost = summary.initial_cost;
      out.final_cost = summary.final_cost;
      const int steps = std::max(1, static_cast<int>(summary.iterations.size()) - 1);
      out.iterations += steps;
      remaining -= steps;
      out.termination = summary.termination_type;
      out.message = summary.message;
      if (summary.termination_type != ceres::USER_SUCCESS) {
        if (summary.termination_type != ceres::CONVERGENCE) break;
        // Converged on the free values: release held ones the gradient now pulls inwards.
        const std::array<double, kN> g = gradient();
        bool again = false;
        for (std::size_t i = 0; i < kN; ++i)
          if (fixed[i] && !outward(i, g)) fixed[i] = false, released[i] = true, again = true;
        if (!again) break;
        continue;
      }
      // A free value reached a bound: hold it if the gradient points out, else let Ceres go on.
      // (Without the line search the Jacobian Ceres evaluated last is the current point's.)
      const std::array<double, kN> g = linear ? last_gradient() : gradient();
      for (std::size_t i = 0; i < kN; ++i)
        if (fixed[i] && watch.release_early_ && !outward(i, g))
          fixed[i] = false, released[i] = true;
        else if (!fixed[i] && watch.AtBound(i)) {
          if (outward(i, g))
            fixed[i] = true, released[i] = false;
          else
            released[i] = true;
        }
    }
    if (out.termination == ceres::USER_SUCCESS) out.termination = ceres::NO_CONVERGENCE;
    return out;
  }

  const FitData& data_;
  const FitOptions& options_;
  const ModelInfo& info_;
  mutable std::vector<typename K::Geom> geom_;
  mutable std::vector<LossSample> loss_;
  std::vector<LinearSample<Linear>> linear_;  // when LinearCost applies (engine model, ngan)
};

struct Search {
  std::optional<Refinement> best;
  int iterations = 0, starts = 0;
  double robust_scale = 0;  // the Cauchy scale used, 0 without a robust loss
};

// The multi-start: candidates from the sweep (or the given start), Ceres from the best
// options.starts distinct ones, the lowest final cost wins.
template <class K>
Search RunFit(const FitData& data, const FitOptions& options) {
  const KernelFit<K> fit(data, options);
  std::vector<Candidate> candidates;
  if (options.start) {
    candidates.push_back({ClampIntoRange(*options.start), 0});
  } else {
    // The sweep on a subsample (every k-th sample), its best few costs recomputed exactly.
    const std::size_t stride = std::max<std::size_t>(1, data.samples.size() / 15000);
    candidates = fit.Sweep(stride);
    auto by_cost = [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; };
    std::stable_sort(candidates.begin(), candidates.end(), by_cost);
    const std::size_t exact =
        std::min(candidates.size(), static_cast<std::size_t>(2 * options.starts + 2));
    for (std::size_t i = 0; i < exact; ++i)
      candidates[i].cost = fit.Cost(candidates[i].material, stride);
    std::stable_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(exact),
                     by_cost);
  }
  std::vector<Material> starts;
  for (const Candidate& c : candidates) {
    if (static_cast<int>(starts.size()) >= options.starts) break;
    bool seen = false;
    for (const Material& s : starts) seen |= SameStart(s, c.material);
    if (!seen) starts.push_back(ClampIntoRange(c.material));
  }

  const double robust_scale =
      options.robust ? RobustScale(data.samples, starts.front(), options) : 0.0;

  Search search;
  search.robust_scale = robust_scale;
  std::optional<Refinement>& best = search.best;
  for (const Material& start : starts) {
    Refinement r = fit.Refine(start, robust_scale);
    search.iterations += r.iterations;
    ++search.starts;
    if (r.termination == ceres::FAILURE || r.termination == ceres::USER_FAILURE) {
      if (!best) best = r;
      continue;
    }
    if (!best || best->termination == ceres::FAILURE || best->termination == ceres::USER_FAILURE ||
        r.final_cost < best->final_cost)
      best = std::move(r);
  }
  return search;
}

Search RunFitOf(const FitData& data, const FitOptions& options) {
  switch (options.model) {
    case Model::kLambert:
      return RunFit<kernels::LambertKernel>(data, options);
    case Model::kLafortune:
      return RunFit<kernels::LafortuneKernel>(data, options);
    case Model::kBlinnPhong:
      return RunFit<kernels::BlinnPhongKernel>(data, options);
    case Model::kGgx:
      return RunFit<kernels::GgxKernel>(data, options);
    case Model::kWard:
      return RunFit<kernels::WardKernel>(data, options);
    case Model::kUnrealDefaultLit:
      return RunFit<kernels::UnrealKernel>(data, options);
    case Model::kUnityHdrpLit:
      return RunFit<kernels::HdrpKernel>(data, options);
    case Model::kUnityHdrpLitSpecular:
      return RunFit<kernels::HdrpSpecularKernel>(data, options);
    case Model::kUnityUrpLit:
      return RunFit<kernels::UrpKernel>(data, options);
    case Model::kUnityUrpLitSpecular:
      return RunFit<kernels::UrpSpecularKernel>(data, options);
  }
  throw InvalidArgument("fit: unknown model");
}
std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

}  // namespace

std::string_view FitLossName(FitLoss loss) {
  switch (loss) {
    case FitLoss::kNgan:
      return "ngan";
    case FitLoss::kLog:
      return "log";
    case FitLoss::kCbrt:
      return "cbrt";
  }
  return "ngan";
}

FitLoss FitLossFromName(std::string_view name) {
  for (FitLoss l : {FitLoss::kNgan, FitLoss::kLog, FitLoss::kCbrt})
    if (FitLossName(l) == name) return l;
  throw InvalidArgument("unknown fit loss '" + std::string(name) + "' (known: ngan, log, cbrt)");
}

FitReport EvaluateFit(const Measurement& measurement, const Material& material,
                      const FitOptions& options) {
  const FitData data = PrepareFitData(measurement, options);
  FitReport report;
  report.model = material.model;
  report.loss = options.loss;
  report.robust = options.robust;
  report.status = "evaluated";
  report.robust_scale = options.robust ? RobustScale(data.samples, material, options) : 0.0;
  report.final_cost = report.initial_cost =
      Cost(data.samples, material, options.loss, report.robust_scale);
  FillErrors(data, material, &report);
  return report;
}

FitResult FitMaterial(const Measurement& measurement, const FitOptions& options) {
  const auto t0 = Clock::now();
  if (options.starts < 1)
    throw InvalidArgument("fit: the number of starts must be at least 1, got " +
                          std::to_string(options.starts));
  if (options.threads < 1)
    throw InvalidArgument("fit: the number of threads must be at least 1, got " +
                          std::to_string(options.threads));
  if (options.max_iterations < 1)
    throw InvalidArgument("fit: the iteration limit must be at least 1");
  if (options.start && options.start->model != options.model)
    throw InvalidArgument("fit: the start is a " + std::string(ModelName(options.start->model)) +
                          " material, the fit is of " + std::string(ModelName(options.model)));
  const FitData data = PrepareFitData(measurement, options);
  const Model model = options.model;

  Search search = RunFitOf(data, options);
  const std::optional<Refinement>& best = search.best;
  FitReport report;
  report.model = model;
  report.loss = options.loss;
  report.robust = options.robust;
  report.robust_scale = search.robust_scale;
  report.iterations = search.iterations;
  report.starts = search.starts;
  report.converged = best->termination == ceres::CONVERGENCE;
  report.status = report.converged                             ? "converged"
                  : best->termination == ceres::NO_CONVERGENCE ? "no-convergence"
                                                               : "failed";
  report.message = best->message;
  report.initial_cost = best->initial_cost;
  report.final_cost = best->final_cost;
  FillErrors(data, best->material, &report);

  // Parameters pinned at a bound the model's range does not want to stop at.
  const ModelInfo& info = DescribeModel(model);
  if (info.shape_parameter >= 0) {
    const ParameterInfo& p = info.parameters[static_cast<std::size_t>(info.shape_parameter)];
    for (int c = 0; c < p.Count(); ++c) {
      const double v = best->material.values[static_cast<std::size_t>(p.offset + c)];
      if (p.log_scale && (v <= p.min * 1.0001 || v >= p.max * 0.9999))
        report.warnings.push_back(std::string(p.name) + " ended at the end of its range (" +
                                  Format("%g", v) + "): the lobe is outside what the model spans");
    }
  }
  report.seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  FitResult result;
  result.material = best->material;
  result.material.name = measurement.metadata.sample_name;
  result.material.description =
      "fit of " + std::string(ModelName(model)) + " to " + measurement.metadata.sample_name;
  nlohmann::json extra = nlohmann::json::object();
  extra["fit"] = nlohmann::json::parse(FitReportJson(report));
  result.material.extra_json = extra.dump();
  result.report = std::move(report);
  return result;
}

std::string FitReportJson(const FitReport& report) {
  nlohmann::ordered_json j;
  j["model"] = std::string(ModelName(report.model));
  j["loss"] = std::string(FitLossName(report.loss));
  j["robust"] = report.robust;
  if (report.robust) j["robust_scale"] = report.robust_scale;
  j["status"] = report.status;
  j["message"] = report.message;
  j["initial_cost"] = report.initial_cost;
  j["final_cost"] = report.final_cost;
  j["rmse"] = report.rmse;
  j["median_relative_error"] = report.median_relative_error;
  nlohmann::ordered_json slices = nlohmann::ordered_json::array();
  for (const SliceFitError& s : report.slices)
    slices.push_back({{"theta_in_deg", s.theta_in_deg},
                      {"samples", s.samples},
                      {"rmse", s.rmse},
                      {"median_relative_error", s.median_relative_error}});
  j["slices"] = slices;
  j["iterations"] = report.iterations;
  j["starts"] = report.starts;
  j["seconds"] = report.seconds;
  j["samples_used"] = report.samples_used;
  j["excluded"] = {{"invalid", report.excluded_invalid},
                   {"saturated", report.excluded_saturated},
                   {"theta_out", report.excluded_theta_out}};
  j["representable"] = report.representable;
  j["chromaticity_error"] = report.chromaticity_error;
  j["hue_spread"] = report.hue_spread;
  j["colour_shift"] = report.colour_shift;
  j["warnings"] = report.warnings;
  j["software_version"] = SoftwareVersion();
  return j.dump();
}

}  // namespace brdf::processing
