// Resampling + grazing extrapolation of one capture of the reference instrument's size
// (4 θin × 76 θout × 360 φout = 109,440 samples) into the 4 × 361 × 181 LUT of docs/design.md §5.
// Target: under 20 ms per capture on one core.
//   build/bench/bench_processing --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "brdf/core/geometry.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/processing/measurement_brdf.h"
#include "brdf/processing/resample.h"

namespace {

using brdf::processing::BuildLut;
using brdf::processing::ExtrapolationParams;
using brdf::processing::ResampleOptions;

brdf::Material Ggx() {
  brdf::Material m;
  m.model = brdf::Model::kGgx;
  m.SetParameter(0, {0.1, 0.15, 0.2});
  m.SetParameter(1, {0.9, 0.6, 0.3});
  m.SetParameter(2, {0.3, 0.3, 0.3});
  return m;
}

brdf::Sample MakeSample(double ti, double to, double po, const brdf::Material& m) {
  brdf::Sample s;
  s.theta_in_deg = static_cast<float>(ti);
  s.theta_out_deg = static_cast<float>(to);
  s.phi_out_deg = static_cast<float>(po);
  const brdf::Rgb f =
      m.Evaluate(brdf::SphericalDirectionDeg(ti, 0.0), brdf::SphericalDirectionDeg(to, po));
  for (int c = 0; c < 3; ++c) s.rgb[c] = static_cast<float>(f[c]);
  return s;
}

// The instrument grid (regular-grid path).
const brdf::Measurement& GridCapture() {
  static const brdf::Measurement meas = [] {
    brdf::Measurement m;
    const brdf::Material mat = Ggx();
    for (double ti : {0.0, 20.0, 40.0, 60.0}) {
      brdf::Slice slice;
      slice.theta_in_deg = ti;
      for (int a = 0; a <= 75; ++a)
        for (int b = 0; b < 360; ++b) slice.samples.push_back(MakeSample(ti, a, b, mat));
      m.slices.push_back(std::move(slice));
    }
    return m;
  }();
  return meas;
}

// The same number of samples at random directions (scattered path).
const brdf::Measurement& ScatteredCapture() {
  static const brdf::Measurement meas = [] {
    brdf::Measurement m;
    const brdf::Material mat = Ggx();
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> uz(std::cos(brdf::DegToRad(75.0)), 1.0), up(0.0, 360.0);
    for (double ti : {0.0, 20.0, 40.0, 60.0}) {
      brdf::Slice slice;
      slice.theta_in_deg = ti;
      for (int n = 0; n < 76 * 360; ++n)
        slice.samples.push_back(MakeSample(ti, brdf::RadToDeg(std::acos(uz(rng))), up(rng), mat));
      m.slices.push_back(std::move(slice));
    }
    return m;
  }();
  return meas;
}

void Run(benchmark::State& state, const brdf::Measurement& meas, bool parallel) {
  ResampleOptions options;
  options.parallel = parallel;
  const ExtrapolationParams params{0.2, 0.3};
  for (auto _ : state) {
    brdf::Lut lut = BuildLut(meas, params, options);
    benchmark::DoNotOptimize(lut.texels.data());
  }
  state.counters["samples"] = static_cast<double>(meas.SampleCount());
  state.counters["texels/s"] = benchmark::Counter(
      4.0 * 361 * 181 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_ResampleGridSingleThread(benchmark::State& state) { Run(state, GridCapture(), false); }
void BM_ResampleGridDefault(benchmark::State& state) { Run(state, GridCapture(), true); }
void BM_ResampleScatteredSingleThread(benchmark::State& state) {
  Run(state, ScatteredCapture(), false);
}
void BM_ResampleScatteredDefault(benchmark::State& state) { Run(state, ScatteredCapture(), true); }

BENCHMARK(BM_ResampleGridSingleThread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ResampleGridDefault)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ResampleScatteredSingleThread)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ResampleScatteredDefault)->Unit(benchmark::kMillisecond)->UseRealTime();

// Point evaluation of a capture through its LUT, as `brdf eval`, the preview and the viewer
// do it (processing::MeasurementAsBrdf).
void BM_MeasurementAsBrdfEval(benchmark::State& state) {
  const brdf::LutBrdf brdf = brdf::processing::MeasurementAsBrdf(GridCapture());
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (auto _ : state) {
    const auto f = brdf.lut().SampleAngles(60.0 * u(rng), 85.0 * u(rng), 360.0 * u(rng));
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_MeasurementAsBrdfEval);

}  // namespace

BENCHMARK_MAIN();
