// Export costs for one LUT of K = 4 slices (361 × 181 texels, a GGX α = 0.3 material):
// RGB9E5 encoding, KTX2 / DDS / EXR / PNG / sidecar writing (atomic: temporary file, fsync,
// rename), KTX2 reading, and the whole ExportLut. Files go to a temporary folder.
//   build/bench/bench_export --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <unistd.h>
#include <filesystem>
#include <string>

#include "brdf/core/geometry.h"
#include "brdf/core/lut.h"
#include "brdf/core/models.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/exr.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/lut_export.h"
#include "brdf/exporter/rgb9e5.h"
#include "brdf/exporter/sidecar.h"

namespace {

using namespace brdf;
using namespace brdf::exporter;

const Lut& GgxLut() {
  static const Lut lut = [] {
    Material m;
    m.model = Model::kGgx;
    m.SetParameter(0, {0.2, 0.15, 0.1});
    m.SetParameter(1, {0.9, 0.6, 0.3});
    m.SetParameter(2, {0.3, 0.3, 0.3});
    Lut l;
    l.Resize(4);
    l.theta_in_deg = {0, 20, 40, 60};
    for (int k = 0; k < 4; ++k) {
      const SpecularFrame frame = SpecularFrame::FromThetaInDeg(l.theta_in_deg[k]);
      const Vec3 light = SphericalDirectionDeg(l.theta_in_deg[k], 0);
      for (int j = 0; j < Lut::kHeight; ++j)
        for (int i = 0; i < Lut::kWidth; ++i) {
          Vec3 v = frame.FromSpecular(SphericalDirectionDeg(j, i));
          v.z = std::max(v.z, 1e-3);
          const Rgb f = m.Evaluate(light, Normalize(v));
          for (int c = 0; c < 3; ++c) l.Texel(k, j, i)[c] = static_cast<float>(f[c]);
        }
    }
    return l;
  }();
  return lut;
}

const std::string& Dir() {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() /
                   ("brdf-bench-export-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir;
}

TextureMetadata Meta() {
  TextureMetadata m;
  m.name = "ggx";
  m.source = "bench_export";
  return m;
}

void BM_PackLutRgb9e5(benchmark::State& state) {
  const Lut& lut = GgxLut();
  for (auto _ : state) benchmark::DoNotOptimize(PackLut(lut));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(lut.texels.size() / 3));
}
BENCHMARK(BM_PackLutRgb9e5)->Unit(benchmark::kMillisecond);

void BM_EncodeKtx2InMemory(benchmark::State& state) {
  const PackedVolume packed = PackLut(GgxLut());
  const std::string sidecar = SidecarJson(packed, GgxLut().theta_in_deg, Meta());
  for (auto _ : state) benchmark::DoNotOptimize(EncodeKtx2(packed, {{"brdf.sidecar", sidecar}}));
}
BENCHMARK(BM_EncodeKtx2InMemory)->Unit(benchmark::kMillisecond);

void BM_WriteKtx2(benchmark::State& state) {  // encode + write, from the float LUT
  for (auto _ : state) WriteKtx2(Dir() + "/ggx.ktx2", GgxLut(), Meta());
}
BENCHMARK(BM_WriteKtx2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteDds(benchmark::State& state) {  // encode + write
  for (auto _ : state) WriteDds(Dir() + "/ggx.dds", GgxLut());
}
BENCHMARK(BM_WriteDds)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteExrFloat(benchmark::State& state) {
  for (auto _ : state)
    WriteExrComposite(Dir() + "/ggx.exr", GgxLut(), Meta(), ExrPixelType::kFloat);
}
BENCHMARK(BM_WriteExrFloat)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteExrHalf(benchmark::State& state) {
  for (auto _ : state)
    WriteExrComposite(Dir() + "/ggx_half.exr", GgxLut(), Meta(), ExrPixelType::kHalf);
}
BENCHMARK(BM_WriteExrHalf)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteExrFloatUncompressed(benchmark::State& state) {
  for (auto _ : state)
    WriteExrComposite(Dir() + "/ggx_raw.exr", GgxLut(), Meta(),
                      {ExrPixelType::kFloat, ExrCompression::kNone});
}
BENCHMARK(BM_WriteExrFloatUncompressed)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ToneMapForPng(benchmark::State& state) {
  const FloatImage image = CompositeImage(GgxLut());
  for (auto _ : state) benchmark::DoNotOptimize(ToneMapForPng(image));
}
BENCHMARK(BM_ToneMapForPng)->Unit(benchmark::kMillisecond);

void BM_WritePng(benchmark::State& state) {
  for (auto _ : state) WritePngComposite(Dir() + "/ggx.png", GgxLut());
}
BENCHMARK(BM_WritePng)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ReadKtx2(benchmark::State& state) {
  WriteKtx2(Dir() + "/read.ktx2", GgxLut(), Meta());
  for (auto _ : state) benchmark::DoNotOptimize(ReadKtx2(Dir() + "/read.ktx2"));
}
BENCHMARK(BM_ReadKtx2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ExportLutAllFormats(benchmark::State& state) {
  for (auto _ : state) ExportLut(Dir(), GgxLut(), Meta());
}
BENCHMARK(BM_ExportLutAllFormats)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  GgxLut();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::filesystem::remove_all(Dir());
  return 0;
}
