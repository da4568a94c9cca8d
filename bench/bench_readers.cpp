// Read time per text format for a typical file:
//   Zemax BSDF    the shared Imaging Sphere file (13 incidences × 19 × 11)
//   CSV           a capture of the reference instrument's size: 4 θin × 76 θout × 360 φout
//                 = 109,440 rows, written once from an analytic GGX material
//   LightTools    a MiniDiff-sized RGB export: 4 AOI × 3 channels × 360 azimuths × 76 radial
//   gonio         the shared in-plane spectral table (329 rows × 35 bands)
// Run: build/bench/bench_readers --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "brdf/core/csv.h"
#include "brdf/core/geometry.h"
#include "brdf/core/gonio.h"
#include "brdf/core/lighttools.h"
#include "brdf/core/models.h"
#include "brdf/core/zemax.h"

namespace brdf {
namespace {

const std::string kShared = BRDF_SHARED_DATA_DIR;
const std::string kZemax = kShared + "/zemax-imaging-sphere/test_13_planesymmetric_btdf_zemax.bsdf";
const std::string kGonio = kShared + "/goniometer-csv/test_brdf_viewer_2D_data.csv";

Material Ggx() {
  Material m;
  m.model = Model::kGgx;
  m.SetParameter(0, {0.3, 0.15, 0.05});
  m.SetParameter(1, {0.04, 0.04, 0.04});
  m.SetParameter(2, {0.2, 0.2, 0.2});
  return m;
}

std::string TempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "brdf_bench_readers";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

const std::string& CsvCapture() {
  static const std::string path = [] {
    const Material mat = Ggx();
    Measurement m;
    for (double tin : {0.0, 20.0, 40.0, 60.0}) {
      Slice s;
      s.theta_in_deg = tin;
      const Vec3 l = SphericalDirectionDeg(tin, 0);
      for (int t = 0; t <= 75; ++t) {
        for (int p = 0; p < 360; ++p) {
          Sample smp;
          smp.theta_in_deg = static_cast<float>(tin);
          smp.theta_out_deg = static_cast<float>(t);
          smp.phi_out_deg = static_cast<float>(p);
          const Rgb f = mat.Evaluate(l, SphericalDirectionDeg(t, p));
          for (int c = 0; c < 3; ++c) smp.rgb[c] = static_cast<float>(f[c]);
          s.samples.push_back(smp);
        }
      }
      m.slices.push_back(std::move(s));
    }
    const std::string p = TempPath("capture.csv");
    WriteCsv(p, m);
    return p;
  }();
  return path;
}

const std::string& LightToolsExport() {
  static const std::string path = [] {
    const Material mat = Ggx();
    LightToolsBsdf lt;
    lt.spectral = LightToolsSpectral::kRgb;
    for (int a = 0; a < 360; ++a) lt.scatter_azimuth_deg.push_back(a);
    for (int r = 0; r <= 75; ++r) lt.scatter_radial_deg.push_back(r);
    for (double aoi : {0.0, 20.0, 40.0, 60.0}) {
      const Vec3 l = SphericalDirectionDeg(aoi, 0);
      for (int c = 0; c < 3; ++c) {
        LightToolsBlock b;
        b.aoi_deg = aoi;
        b.channel = c;
        for (double az : lt.scatter_azimuth_deg)
          for (double rad : lt.scatter_radial_deg)
            b.values.push_back(mat.Evaluate(l, SphericalDirectionDeg(rad, az))[c]);
        lt.blocks.push_back(std::move(b));
      }
    }
    const std::string p = TempPath("minidiff_rgb.bsdf");
    WriteLightToolsBsdf(p, lt);
    return p;
  }();
  return path;
}

void BM_ReadZemax(benchmark::State& state) {
  for (auto _ : state) {
    Measurement m = LoadZemaxBsdf(kZemax, ZemaxImportOptions{true});
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_ReadZemax)->Unit(benchmark::kMillisecond);

void BM_ZemaxTisIntegration(benchmark::State& state) {
  const ZemaxBsdf z = ReadZemaxBsdf(kZemax);
  for (auto _ : state) {
    auto tis = IntegrateZemaxTis(z);
    benchmark::DoNotOptimize(tis);
  }
}
BENCHMARK(BM_ZemaxTisIntegration)->Unit(benchmark::kMillisecond);

void BM_ReadCsvCapture(benchmark::State& state) {
  const std::string& path = CsvCapture();
  std::size_t rows = 0;
  for (auto _ : state) {
    Measurement m = ReadCsv(path);
    rows = m.SampleCount();
    benchmark::DoNotOptimize(m);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rows));
  state.counters["rows"] = static_cast<double>(rows);
}
BENCHMARK(BM_ReadCsvCapture)->Unit(benchmark::kMillisecond);

void BM_WriteCsvCapture(benchmark::State& state) {
  const Measurement m = ReadCsv(CsvCapture());
  for (auto _ : state) {
    std::string text = FormatCsv(m);
    benchmark::DoNotOptimize(text);
  }
}
BENCHMARK(BM_WriteCsvCapture)->Unit(benchmark::kMillisecond);

void BM_ReadLightTools(benchmark::State& state) {
  const std::string& path = LightToolsExport();
  for (auto _ : state) {
    Measurement m = LoadLightToolsBsdf(path);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_ReadLightTools)->Unit(benchmark::kMillisecond);

void BM_ReadGonio(benchmark::State& state) {
  for (auto _ : state) {
    Measurement m = LoadGonioTable(kGonio);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_ReadGonio)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace brdf

BENCHMARK_MAIN();
