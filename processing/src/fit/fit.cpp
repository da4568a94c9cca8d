// FitMaterial: data preparation, the deterministic multi-start sweep, the Ceres refinement and
// the report (brdf/processing/fit.h explains the method).
#include "brdf/processing/fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "brdf/core/error.h"
#include "fit_data.h"

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

// One Ceres residual block: a chunk of samples, N fitted values (internal coordinates: the
// logarithm for log-scale parameters). channel ≥ 0: a legacy model's channel, the N values
// being that channel's (a, b, shape); channel < 0: all channels, the N values being the whole
// material layout.
template <int N>
struct ChunkCost {
  const std::vector<FitSample>* samples;
  std::size_t begin, end;
  Model model;
  int channel;
  FitLoss loss;
  std::array<bool, N> log_scale;

  template <class T>
  bool operator()(const T* x, T* r) const {
    using std::exp;
    T v[N];
    for (int i = 0; i < N; ++i) v[i] = log_scale[i] ? exp(x[i]) : x[i];
    if (channel >= 0) {
      const T zero(0);
      for (std::size_t k = begin; k < end; ++k) {
        const FitSample& s = (*samples)[k];
        T f;
        if constexpr (N == 1)
          f = models::EvaluateChannel(model, s.g, v[0], zero, zero);
        else
          f = models::EvaluateChannel(model, s.g, v[0], v[1], v[2]);
        *r++ = Residual(loss, f, s.m[channel], s.cos_in, s.sqrt_w);
      }
    } else {
      for (std::size_t k = begin; k < end; ++k) {
        const FitSample& s = (*samples)[k];
        const std::array<T, 3> f = models::EvaluateRgb(model, s.g, v);
        for (int c = 0; c < 3; ++c) *r++ = Residual(loss, f[c], s.m[c], s.cos_in, s.sqrt_w);
      }
    }
    return true;
  }
};

constexpr std::size_t kChunk = 512;

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

template <int N>
void AddBlockResiduals(ceres::Problem& problem, const std::vector<FitSample>& samples, Model model,
                       const Block& block, FitLoss loss, ceres::LossFunction* robust, double* x) {
  ChunkCost<N> proto{&samples, 0, 0, model, block.channel, loss, {}};
  const ModelInfo& info = DescribeModel(model);
  for (int i = 0; i < N; ++i)
    proto.log_scale[static_cast<std::size_t>(i)] =
        ParameterOfValue(info, block.value_index[static_cast<std::size_t>(i)]).log_scale;
  const int per_sample = block.channel >= 0 ? 1 : 3;
  for (std::size_t begin = 0; begin < samples.size(); begin += kChunk) {
    auto* functor = new ChunkCost<N>(proto);
    functor->begin = begin;
    functor->end = std::min(samples.size(), begin + kChunk);
    const int residuals = static_cast<int>(functor->end - functor->begin) * per_sample;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<ChunkCost<N>, ceres::DYNAMIC, N>(functor, residuals),
        robust, x);
  }
}

void AddResiduals(ceres::Problem& problem, const std::vector<FitSample>& samples, Model model,
                  const Block& block, FitLoss loss, ceres::LossFunction* robust, double* x) {
  switch (block.value_index.size()) {
    case 1:
      return AddBlockResiduals<1>(problem, samples, model, block, loss, robust, x);
    case 3:
      return AddBlockResiduals<3>(problem, samples, model, block, loss, robust, x);
    case 5:
      return AddBlockResiduals<5>(problem, samples, model, block, loss, robust, x);
    case 6:
      return AddBlockResiduals<6>(problem, samples, model, block, loss, robust, x);
    case 7:
      return AddBlockResiduals<7>(problem, samples, model, block, loss, robust, x);
    default:
      throw InvalidArgument("fit: model " + std::string(ModelName(model)) +
                            " has an unsupported number of values");
  }
}

// ----------------------------------------------------------------------------------------------
// Costs in doubles.

// ½ Σ r² over `samples` (every k-th with `stride`), without a robust loss.
double Cost(const std::vector<FitSample>& samples, const Material& m, FitLoss loss,
            std::size_t stride = 1) {
  double sum = 0;
  for (std::size_t k = 0; k < samples.size(); k += stride) {
    const FitSample& s = samples[k];
    const std::array<double, 3> f = models::EvaluateRgb(m.model, s.g, m.values.data());
    for (int c = 0; c < 3; ++c) {
      const double r = Residual(loss, f[c], s.m[c], s.cos_in, s.sqrt_w);
      sum += r * r;
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

// Legacy models: for each shape, kd and ks (or f0, ρs) per channel in closed form (the model
// is affine in them: f = a·A + b·B + C, the basis from three evaluations).
void SweepLegacy(const std::vector<FitSample>& sub, Model model, FitLoss loss,
                 std::vector<Candidate>* out) {
  const ModelInfo& info = DescribeModel(model);
  const bool two = info.parameters.size() > 1;
  const std::vector<double> grid =
      info.shape_parameter >= 0
          ? ShapeGrid(info.parameters[static_cast<std::size_t>(info.shape_parameter)])
          : std::vector<double>{0.0};
  for (const double shape : grid) {
    Material m;
    m.model = model;
    for (int c = 0; c < 3; ++c) {
      Sums s;
      for (const FitSample& x : sub) {
        const double base = models::EvaluateChannel(model, x.g, 0.0, 0.0, shape);
        const double a = models::EvaluateChannel(model, x.g, 1.0, 0.0, shape) - base;
        const double b = two ? models::EvaluateChannel(model, x.g, 0.0, 1.0, shape) - base : 0.0;
        const double w = x.sqrt_w * x.cos_in;
        const double wa = w * a, wb = w * b, wm = w * (x.m[c] - base);
        s.aa += wa * wa, s.ab += wa * wb, s.bb += wb * wb;
        s.am += wa * wm, s.bm += wb * wm, s.mm += wm * wm;
      }
      const auto [a, b] = SolveBox(s, two);
      m.values[static_cast<std::size_t>(info.parameters[0].offset + c)] = a;
      if (two) {
        m.values[static_cast<std::size_t>(info.parameters[1].offset + c)] = b;
        m.values[static_cast<std::size_t>(info.parameters[2].offset + c)] = shape;
      }
    }
    out->push_back({m, Cost(sub, m, loss)});
  }
}

// Engine models: a grid over the shape slider and metallic (or a grey specular colour); the
// base colour per channel in closed form (affine in it once the others are fixed).
void SweepEngine(const std::vector<FitSample>& sub, Model model, FitLoss loss,
                 std::vector<Candidate>* out) {
  const ModelInfo& info = DescribeModel(model);
  const ParameterInfo& shape_p = info.parameters[static_cast<std::size_t>(info.shape_parameter)];
  const ParameterInfo& second = info.parameters[1];  // metallic or specular_color
  const std::vector<double> second_grid = second.rgb
                                              ? std::vector<double>{0.02, 0.04, 0.08, 0.2, 0.5, 0.9}
                                              : std::vector<double>{0.0, 0.5, 1.0};
  for (const double shape : ShapeGrid(shape_p)) {
    for (const double level : second_grid) {
      Material m;
      m.model = model;
      for (const ParameterInfo& p : info.parameters)
        for (int c = 0; c < p.Count(); ++c)
          m.values[static_cast<std::size_t>(p.offset + c)] = p.start;
      for (int c = 0; c < second.Count(); ++c)
        m.values[static_cast<std::size_t>(second.offset + c)] = level;
      for (int c = 0; c < shape_p.Count(); ++c)
        m.values[static_cast<std::size_t>(shape_p.offset + c)] = shape;
      Material zero = m, one = m;
      for (int c = 0; c < 3; ++c)
        zero.values[static_cast<std::size_t>(c)] = 0, one.values[static_cast<std::size_t>(c)] = 1;
      std::array<Sums, 3> s{};
      for (const FitSample& x : sub) {
        const auto f0 = models::EvaluateRgb(model, x.g, zero.values.data());
        const auto f1 = models::EvaluateRgb(model, x.g, one.values.data());
        const double w = x.sqrt_w * x.cos_in;
        for (int c = 0; c < 3; ++c) {
          const double wa = w * (f1[c] - f0[c]), wm = w * (x.m[c] - f0[c]);
          s[c].aa += wa * wa, s[c].am += wa * wm, s[c].mm += wm * wm;
        }
      }
      for (int c = 0; c < 3; ++c)
        m.values[static_cast<std::size_t>(c)] = SolveBox(s[c], false).first;
      out->push_back({m, Cost(sub, m, loss)});
    }
  }
}

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

// One block's problem: its own Ceres problem, since the blocks share no residual (the legacy
// models' channels are independent; an engine model is a single block). Separate problems keep
// each Jacobian dense and three times smaller than one joint problem would make it.
struct BlockOutcome {
  std::vector<double> x;
  ceres::Solver::Summary summary;
};

BlockOutcome SolveBlock(const std::vector<FitSample>& samples, const Material& start,
                        const Block& block, const FitOptions& options, double robust_scale,
                        int threads) {
  const ModelInfo& info = DescribeModel(start.model);
  BlockOutcome out;
  out.x.resize(block.value_index.size());
  for (std::size_t i = 0; i < block.value_index.size(); ++i) {
    const ParameterInfo& p = ParameterOfValue(info, block.value_index[i]);
    const double v = start.values[static_cast<std::size_t>(block.value_index[i])];
    out.x[i] = p.log_scale ? std::log(v) : v;
  }
  ceres::Problem problem;
  ceres::LossFunction* robust = robust_scale > 0 ? new ceres::CauchyLoss(robust_scale) : nullptr;
  AddResiduals(problem, samples, start.model, block, options.loss, robust, out.x.data());
  for (std::size_t i = 0; i < block.value_index.size(); ++i) {
    const ParameterInfo& p = ParameterOfValue(info, block.value_index[i]);
    problem.SetParameterLowerBound(out.x.data(), static_cast<int>(i),
                                   p.log_scale ? std::log(p.min) : p.min);
    problem.SetParameterUpperBound(out.x.data(), static_cast<int>(i),
                                   p.log_scale ? std::log(p.max) : p.max);
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = options.max_iterations;
  so.num_threads = threads;
  so.function_tolerance = 1e-10;
  so.parameter_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solve(so, &problem, &out.summary);
  return out;
}

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

Refinement Refine(const std::vector<FitSample>& samples, const Material& start,
                  const FitOptions& options, double robust_scale) {
  const ModelInfo& info = DescribeModel(start.model);
  const std::vector<Block> blocks = BlocksOf(start.model);
  std::vector<BlockOutcome> outcomes(blocks.size());
  // Independent blocks run on their own threads when there are threads to spare.
  const int parallel = std::min<int>(options.threads, static_cast<int>(blocks.size()));
  if (parallel > 1) {
    std::vector<std::thread> workers;
    std::atomic<std::size_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    for (int t = 0; t < parallel; ++t)
      workers.emplace_back([&] {
        for (std::size_t b; (b = next++) < blocks.size();) {
          try {
            outcomes[b] = SolveBlock(samples, start, blocks[b], options, robust_scale, 1);
          } catch (...) {
            const std::lock_guard<std::mutex> lock(error_mutex);
            error = std::current_exception();
          }
        }
      });
    for (std::thread& w : workers) w.join();
    if (error) std::rethrow_exception(error);
  } else {
    for (std::size_t b = 0; b < blocks.size(); ++b)
      outcomes[b] = SolveBlock(samples, start, blocks[b], options, robust_scale, options.threads);
  }

  Refinement out;
  out.material = start;
  out.termination = ceres::CONVERGENCE;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const ceres::Solver::Summary& summary = outcomes[b].summary;
    for (std::size_t i = 0; i < blocks[b].value_index.size(); ++i) {
      const ParameterInfo& p = ParameterOfValue(info, blocks[b].value_index[i]);
      out.material.values[static_cast<std::size_t>(blocks[b].value_index[i])] =
          p.log_scale ? std::exp(outcomes[b].x[i]) : outcomes[b].x[i];
    }
    out.initial_cost += summary.initial_cost;
    out.final_cost += summary.final_cost;
    out.iterations += static_cast<int>(summary.iterations.size());
    if (Rank(summary.termination_type) >= Rank(out.termination)) {
      out.termination = summary.termination_type;
      out.message = (blocks.size() > 1 ? "channel " + std::to_string(b) + ": " : std::string()) +
                    summary.message;
    }
  }
  out.material = ClampIntoRange(out.material);
  return out;
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
  report.final_cost = report.initial_cost = Cost(data.samples, material, options.loss);
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

  // Candidates: the given start, or the sweep on a subsample (every k-th sample).
  std::vector<Candidate> candidates;
  if (options.start) {
    candidates.push_back({ClampIntoRange(*options.start), 0});
  } else {
    const std::size_t stride = std::max<std::size_t>(1, data.samples.size() / 15000);
    std::vector<FitSample> sub;
    for (std::size_t k = 0; k < data.samples.size(); k += stride) sub.push_back(data.samples[k]);
    if (models::ChannelsIndependent(model))
      SweepLegacy(sub, model, options.loss, &candidates);
    else
      SweepEngine(sub, model, options.loss, &candidates);
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  }
  std::vector<Material> starts;
  for (const Candidate& c : candidates) {
    if (static_cast<int>(starts.size()) >= options.starts) break;
    bool seen = false;
    for (const Material& s : starts) seen |= SameStart(s, c.material);
    if (!seen) starts.push_back(ClampIntoRange(c.material));
  }

  double robust_scale = 0;
  if (options.robust) {
    robust_scale = options.robust_scale > 0
                       ? options.robust_scale
                       : 1.4826 * MedianAbsResidual(data.samples, starts.front(), options.loss);
    robust_scale = std::max(robust_scale, 1e-12);
  }

  FitReport report;
  report.model = model;
  report.loss = options.loss;
  report.robust = options.robust;
  std::optional<Refinement> best;
  for (const Material& start : starts) {
    Refinement r = Refine(data.samples, start, options, robust_scale);
    report.iterations += r.iterations;
    ++report.starts;
    if (r.termination == ceres::FAILURE || r.termination == ceres::USER_FAILURE) {
      if (!best) best = r;
      continue;
    }
    if (!best || best->termination == ceres::FAILURE || best->termination == ceres::USER_FAILURE ||
        r.final_cost < best->final_cost)
      best = std::move(r);
  }
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
