// brdf-view's interactive budget: rebuilding the lobe after a θin change (target < 50 ms).
// The lobe samples the LUT the way a GPU does (Lut::SampleAngles) and classifies coverage; the
// baseline beside it evaluates the analytic material directly at the same vertices (what a
// viewer that ignored the LUT would do), so the ratio shows what the LUT lookup costs.
#include <benchmark/benchmark.h>

#include <cmath>

#include "brdf/core/brdf_source.h"
#include "brdf/core/models.h"
#include "brdf/viewer/lobe.h"
#include "brdf/viewer/slices.h"

namespace {

const brdf::Material& Gold() {
  static const brdf::Material m = brdf::ParseMaterialJson(
      R"({"model": "ggx", "kd": 0.0, "f0": [0.96, 0.79, 0.41], "alpha": 0.15})");
  return m;
}

const brdf::viewer::ViewSource& GoldView() {
  static const brdf::viewer::ViewSource v =
      brdf::viewer::ViewSourceFromBrdf(brdf::AnalyticBrdf(Gold()), "gold");
  return v;
}

// θin steps through measured and in-between values, as dragging the slider does.
void BM_LobeRebuild(benchmark::State& state) {
  const brdf::viewer::ViewSource& view = GoldView();
  brdf::viewer::LobeOptions options;
  options.theta_rows = static_cast<int>(state.range(0));
  options.phi_columns = static_cast<int>(state.range(1));
  int step = 0;
  for (auto _ : state) {
    options.theta_in_deg = (step++ % 61);
    benchmark::DoNotOptimize(brdf::viewer::BuildLobe(view, options).max_radius);
  }
}
BENCHMARK(BM_LobeRebuild)->Args({90, 180})->Args({180, 360})->Unit(benchmark::kMillisecond);

// Baseline: the same vertex grid evaluated directly from the analytic model.
void BM_DirectEvaluationSameGrid(benchmark::State& state) {
  const brdf::Material& gold = Gold();
  const int rows = static_cast<int>(state.range(0)), cols = static_cast<int>(state.range(1));
  int step = 0;
  for (auto _ : state) {
    const brdf::Vec3 wi = brdf::SphericalDirectionDeg(step++ % 61, 0);
    double sum = 0;
    for (int t = 0; t <= rows; ++t) {
      for (int c = 0; c < cols; ++c) {
        sum += gold.Evaluate(wi, brdf::SphericalDirectionDeg(90.0 * t / rows, 360.0 * c / cols))[1];
      }
    }
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_DirectEvaluationSameGrid)
    ->Args({90, 180})
    ->Args({180, 360})
    ->Unit(benchmark::kMillisecond);

void BM_SliceImage(benchmark::State& state) {
  const brdf::viewer::ViewSource& view = GoldView();
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        brdf::viewer::BuildSliceImage(view, 1, brdf::viewer::Channel::kLuminance).max_value);
  }
}
BENCHMARK(BM_SliceImage)->Unit(benchmark::kMillisecond);

// Opening a material for the viewer: noise-free capture at the reference geometry + BuildLut
// (part of the time to the first picture).
void BM_OpenMaterialForView(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        brdf::viewer::ViewSourceFromBrdf(brdf::AnalyticBrdf(Gold()), "gold").lut.slices());
  }
}
BENCHMARK(BM_OpenMaterialForView)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
