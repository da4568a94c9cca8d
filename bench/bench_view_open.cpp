// brdf-view opening a capture: sources::OpenForView (one read, one resampling; the LUT serves
// the lobes and the preview) beside the path brdf-view took before, reproduced with the same
// library calls (PrepareMeasurement and its own resampling for the lobes, then OpenBrdf reading
// and resampling the capture again for the preview). Both in one run, so the ratio holds on a
// busy machine (docs/benchmarks/open.md).
#include <benchmark/benchmark.h>

#include <optional>
#include <string>

#include "brdf/sources/open.h"
#include "brdf/viewer/view_source.h"

namespace {

const std::string kCapture = std::string(BRDF_SOURCE_DIR) + "/data-samples/captures/gold.bpc";

void BM_OpenForView(benchmark::State& state) {
  for (auto _ : state) {
    brdf::sources::OpenedForView opened = brdf::sources::OpenForView(kCapture);
    const brdf::viewer::ViewSource view = brdf::viewer::ViewSourceFromResampled(
        *opened.measurement, std::move(opened.lut), *opened.resample_report, "gold");
    benchmark::DoNotOptimize(view.lut.texels.data());
    benchmark::DoNotOptimize(opened.brdf.get());
  }
}
BENCHMARK(BM_OpenForView)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ReadAndResampleTwice(benchmark::State& state) {
  using brdf::sources::FileKind;
  for (auto _ : state) {
    const brdf::sources::PreparedMeasurement p =
        brdf::sources::PrepareMeasurement(kCapture, FileKind::kCapture, std::nullopt);
    const brdf::viewer::ViewSource view =
        brdf::viewer::ViewSourceFromMeasurement(p.measurement, p.extrapolation.params, "gold");
    const brdf::sources::OpenedSource opened = brdf::sources::OpenBrdf(kCapture);
    benchmark::DoNotOptimize(view.lut.texels.data());
    benchmark::DoNotOptimize(opened.brdf.get());
  }
}
BENCHMARK(BM_ReadAndResampleTwice)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
