// The IBL pack (brdf/core/ibl_pack.h): computing one material's pack on one core, against the
// bare cost of the same number of evaluations of the same source (the baseline, same run).
//   build/dev/bench/bench_ibl --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Target: at most 50 ms per material on one core (docs/benchmarks/ibl.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>

#include "brdf/core/brdf_source.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/core/models.h"
#include "brdf/sources/open.h"

namespace brdf {
namespace {

std::unique_ptr<BrdfSource> Source(int which) {
  if (which == 0)
    return std::make_unique<AnalyticBrdf>(Material::Make(
        Model::kGgx, {{0, 0, 0}, {0.962585, 0.786916, 0.40822}, {0.15, 0.15, 0.15}}, "gold"));
  // A capture's LUT (4 slices), evaluated by Lut::SampleAngles as every command does.
  return std::move(
      sources::OpenBrdf(std::string(BRDF_SOURCE_DIR) + "/data-samples/captures/gold.bpc").brdf);
}

const char* kNames[] = {"analytic GGX gold", "gold.bpc LUT"};

void BM_IblPack(benchmark::State& state) {
  const auto source = Source(static_cast<int>(state.range(0)));
  (void)ComputeIblPack(*source);  // the κ table, once per process
  for (auto _ : state) benchmark::DoNotOptimize(ComputeIblPack(*source));
  state.SetLabel(kNames[state.range(0)]);
}
BENCHMARK(BM_IblPack)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// The same 64 × 64 × 72 evaluations (light over a normal-frame grid, view per row), nothing else.
void BM_EvaluationsOnly(benchmark::State& state) {
  const auto source = Source(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    double total = 0.0;
    for (int row = 0; row < IblPack::kRows; ++row) {
      const double mu = (row + 0.5) / IblPack::kRows;
      const Vec3 v = {std::sqrt(1.0 - mu * mu), 0.0, mu};
      for (int j = 0; j < IblPack::kThetaSteps; ++j) {
        const double t = (j + 0.5) / IblPack::kThetaSteps * 0.5 * kPi;
        for (int k = 0; k < IblPack::kPhiSteps; ++k) {
          const double p = (k + 0.5) / IblPack::kPhiSteps * 2.0 * kPi;
          total += source->Eval(SphericalDirection(t, p), v)[1];
        }
      }
    }
    benchmark::DoNotOptimize(total);
  }
  state.SetLabel(kNames[state.range(0)]);
}
BENCHMARK(BM_EvaluationsOnly)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

}  // namespace
}  // namespace brdf

BENCHMARK_MAIN();
