// RGL and MERL readers: load time per file and evaluation throughput.
//   build/bench/bench_rgl --benchmark_filter=Rgl   (or Merl, Sha256)
// Evaluation target: at least 5 M RGL evaluations per second per core.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <filesystem>
#include <memory>

#include "brdf/core/brdf_source.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/merl.h"
#include "brdf/core/models.h"
#include "brdf/core/rgl.h"
#include "brdf/core/sha256.h"

namespace brdf {
namespace {

// $BRDF_DATA_DIR (as the tests read it), else the folder configured at build time.
const std::string kRglDir = [] {
  const char* env = std::getenv("BRDF_DATA_DIR");
  return std::string(env && *env ? env : BRDF_SHARED_DATA_DIR) + "/rgl/";
}();

struct Pair {
  Vec3 wi, wo;
};

// Cosine-distributed directions on both sides, up to 85°: the mix a renderer or a virtual
// capture asks for.
std::vector<Pair> RandomPairs(std::size_t n) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double s2max = std::pow(std::sin(DegToRad(85.0)), 2);
  auto dir = [&] {
    const double r = std::sqrt(u(rng) * s2max), phi = 2 * kPi * u(rng);
    return Vec3{r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - r * r)};
  };
  std::vector<Pair> pairs(n);
  for (Pair& p : pairs) p = {dir(), dir()};
  return pairs;
}

void BM_RglLoad(benchmark::State& state, const std::string& file) {
  for (auto _ : state) benchmark::DoNotOptimize(RglBrdf::Load(kRglDir + file));
  state.SetLabel(file);
}
BENCHMARK_CAPTURE(BM_RglLoad, paper_white, std::string("paper_white_rgb.bsdf"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RglLoad, cg_sunflower_64, std::string("cg_sunflower_rgb.bsdf"))
    ->Unit(benchmark::kMillisecond);

void BM_RglEval(benchmark::State& state, const std::string& file) {
  const RglBrdf brdf = RglBrdf::Load(kRglDir + file);
  const std::vector<Pair> pairs = RandomPairs(1 << 14);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & (pairs.size() - 1)];
    benchmark::DoNotOptimize(brdf.Eval(p.wi, p.wo));
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(file);
}
BENCHMARK_CAPTURE(BM_RglEval, paper_white, std::string("paper_white_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEval, chm_mint, std::string("chm_mint_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEval, cg_sunflower_64, std::string("cg_sunflower_rgb.bsdf"));
// The material of the preview benchmark (bench/preview/).
BENCHMARK_CAPTURE(BM_RglEval, cc_ibiza_sunset, std::string("cc_ibiza_sunset_rgb.bsdf"));

// The exact evaluator and its tabulated form (RglTabulatedBrdf, what `brdf preview` integrates)
// on the same random pairs, side by side:
//   build/bench/bench_rgl --benchmark_filter='RglEvalExact|RglEvalTabulated'
void BM_RglEvalExact(benchmark::State& state, const std::string& file) { BM_RglEval(state, file); }
void BM_RglEvalTabulated(benchmark::State& state, const std::string& file) {
  const RglBrdf exact = RglBrdf::Load(kRglDir + file);
  const std::unique_ptr<RglTabulatedBrdf> brdf = exact.Tabulate(RglTabulationSettings{});
  const std::vector<Pair> pairs = RandomPairs(1 << 14);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & (pairs.size() - 1)];
    benchmark::DoNotOptimize(brdf->Eval(p.wi, p.wo));
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(file + ", " + std::to_string(brdf->table_bytes() >> 10) + " KiB table");
}
// Building the table (QuadratureApproximation's cost, paid once per preview).
void BM_RglTabulate(benchmark::State& state, const std::string& file) {
  const RglBrdf exact = RglBrdf::Load(kRglDir + file);
  for (auto _ : state) benchmark::DoNotOptimize(exact.Tabulate(RglTabulationSettings{}));
  state.SetLabel(file);
}
BENCHMARK_CAPTURE(BM_RglEvalExact, cc_ibiza_sunset, std::string("cc_ibiza_sunset_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEvalTabulated, cc_ibiza_sunset, std::string("cc_ibiza_sunset_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEvalExact, chm_light_blue, std::string("chm_light_blue_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEvalTabulated, chm_light_blue, std::string("chm_light_blue_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEvalExact, paper_white, std::string("paper_white_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglEvalTabulated, paper_white, std::string("paper_white_rgb.bsdf"));
BENCHMARK_CAPTURE(BM_RglTabulate, cc_ibiza_sunset, std::string("cc_ibiza_sunset_rgb.bsdf"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_RglTabulate, chm_light_blue, std::string("chm_light_blue_rgb.bsdf"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A virtual capture at the reference instrument's geometry (docs/design.md §1): θin ∈ {0, 20, 40,
// 60}°, θout 0…75° and φout 0…359° at 1° steps: 4 × 76 × 360 = 109,440 evaluations.
void BM_RglVirtualCapture(benchmark::State& state) {
  const RglBrdf brdf = RglBrdf::Load(kRglDir + "chm_mint_rgb.bsdf");
  std::vector<Vec3> outs;
  for (int t = 0; t <= 75; ++t)
    for (int p = 0; p < 360; ++p) outs.push_back(SphericalDirectionDeg(t, p));
  for (auto _ : state) {
    double sum = 0;
    for (int k = 0; k < 4; ++k) {
      const Vec3 wi = SphericalDirectionDeg(20.0 * k, 0.0);
      for (const Vec3& wo : outs) sum += brdf.Eval(wi, wo)[1];
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * 4 * static_cast<std::int64_t>(outs.size()));
}
BENCHMARK(BM_RglVirtualCapture)->Unit(benchmark::kMillisecond);

// MERL: a synthetic file (no genuine one ships) written once from a GGX material.
const std::string& MerlFile() {
  static const std::string path = [] {
    const std::string p =
        (std::filesystem::temp_directory_path() / "bench_rgl_synthetic.binary").string();
    Material m;
    m.model = Model::kGgx;
    m.SetParameter(0, {0.1, 0.2, 0.3});
    m.SetParameter(1, {0.04, 0.04, 0.04});
    m.SetParameter(2, {0.2, 0.2, 0.2});
    WriteMerlBinary(p, AnalyticBrdf(m));
    return p;
  }();
  return path;
}

void BM_MerlLoad(benchmark::State& state) {
  const std::string& path = MerlFile();
  for (auto _ : state) benchmark::DoNotOptimize(MerlBrdf::Load(path));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(kMerlFileBytes));
}
BENCHMARK(BM_MerlLoad)->Unit(benchmark::kMillisecond);

void BM_MerlEval(benchmark::State& state) {
  const MerlBrdf brdf = MerlBrdf::Load(MerlFile());
  const std::vector<Pair> pairs = RandomPairs(1 << 14);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & (pairs.size() - 1)];
    benchmark::DoNotOptimize(brdf.Eval(p.wi, p.wo));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_MerlEval);

void BM_MerlWrite(benchmark::State& state) {
  Material m;
  m.model = Model::kGgx;
  m.SetParameter(0, {0.1, 0.2, 0.3});
  m.SetParameter(1, {0.04, 0.04, 0.04});
  m.SetParameter(2, {0.2, 0.2, 0.2});
  const AnalyticBrdf source(m);
  for (auto _ : state) benchmark::DoNotOptimize(EncodeMerlBinary(source));
}
BENCHMARK(BM_MerlWrite)->Unit(benchmark::kMillisecond);

void BM_Sha256(benchmark::State& state) {
  const std::string data(1 << 24, 'x');
  for (auto _ : state) benchmark::DoNotOptimize(Sha256Hex(data));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(data.size()));
}
BENCHMARK(BM_Sha256)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace brdf

BENCHMARK_MAIN();
