// One model's fit over prepared samples (private to brdf_fit): the sweep, the Ceres refinements
// with bounds held as an active set, and the multi-start, for a model's kernel K
// (fit_kernels.h). RunLegacyModelFit and RunEngineModelFit instantiate it for every model.
#pragma once

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/models.h"
#include "brdf/core/parallel.h"
#include "brdf/fit/fit.h"
#include "fit_data.h"
#include "loss.h"
#include "parameter_layout.h"
#include "search.h"
#include "summed_cost.h"
#include "sweep.h"

namespace brdf::processing::detail {

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
    // Two residual blocks, whatever the thread count (CompressedCost explains why not one per
    // sample). The split is fixed so the sums are too: Ceres adds its threads' partial costs
    // and gradients, and with two blocks every assignment of blocks to threads adds the same two
    // numbers (a + b = b + a exactly), so the result does not depend on --jobs. More blocks
    // would let more threads help but make the sum's order depend on scheduling.
    const std::size_t n = data_.samples.size();
    constexpr std::size_t parts = 2;
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

}  // namespace brdf::processing::detail
