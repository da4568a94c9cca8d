// BC6H encoding and decoding of whole LUTs on one core (target: encode ≤ 50 ms per material,
// docs/benchmarks/bc6h.md). One benchmark per float EXR composite in $BRDF_BC6H_LUTS (a folder
// `brdf convert --exr-type float` wrote; bench/bc6h/run.sh makes one from the library materials
// and the RGL files), beside RGB9E5 packing of the same LUT as the baseline:
//   BRDF_BC6H_LUTS=DIR build/dev/bench/bench_bc6h --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
// Each composite's θin list comes from its "brdf:theta_in_deg" header attribute (4 slices for
// the default fill, 9 for `--beyond auto`).
//   BRDF_BC6H_LUTS=DIR build/dev/bench/bench_bc6h --checksums
// prints, instead of timing, one line per composite: its name, the block count and the CRC-32
// of the BC6H bytes encoded on one thread, so two builds' outputs can be compared byte for byte
// (docs/benchmarks/bc6h.md: the speed-up keeps every material's bytes).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/exr.h"
#include "brdf/exporter/packed_volume.h"

namespace {

using namespace brdf;
using namespace brdf::exporter;

struct NamedLut {
  std::string name;
  Lut lut;
};

std::vector<NamedLut>& Luts() {
  static std::vector<NamedLut> luts;
  return luts;
}

void BM_EncodeBc6h(benchmark::State& state, const Lut* lut) {
  for (auto _ : state) {
    Bc6hVolume v =
        EncodeBc6hVolume(lut->texels.data(), Lut::kWidth, Lut::kHeight, lut->slices(), 1);
    benchmark::DoNotOptimize(v.bytes.data());
  }
  state.counters["blocks"] = static_cast<double>(91 * 46 * lut->slices());
}

void BM_DecodeBc6h(benchmark::State& state, const Lut* lut) {
  const Bc6hVolume v =
      EncodeBc6hVolume(lut->texels.data(), Lut::kWidth, Lut::kHeight, lut->slices(), 1);
  for (auto _ : state) {
    std::vector<float> texels = DecodeBc6hVolume(v);
    benchmark::DoNotOptimize(texels.data());
  }
}

void BM_PackRgb9e5(benchmark::State& state, const Lut* lut) {
  for (auto _ : state) {
    PackedVolume v = PackLut(*lut);
    benchmark::DoNotOptimize(v.words.data());
  }
}

// "0, 20, 40, 60" (FormatThetaList's form) back to numbers; empty when the attribute is absent.
std::vector<double> ParseThetaList(const std::string& text) {
  std::vector<double> out;
  const char* p = text.c_str();
  while (*p != '\0') {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p) break;
    out.push_back(v);
    p = end;
    while (*p == ',' || *p == ' ') ++p;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const char* dir = std::getenv("BRDF_BC6H_LUTS");
  if (dir == nullptr) {
    std::fprintf(stderr,
                 "bench_bc6h: set BRDF_BC6H_LUTS to a folder of float EXR composites "
                 "(bench/bc6h/run.sh)\n");
    return 2;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".exr") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    const ExrFile exr = ReadExr(f.string());
    std::vector<double> theta = ParseThetaList(exr.Attribute("brdf:theta_in_deg"));
    if (theta.empty()) {
      std::fprintf(stderr,
                   "bench_bc6h: %s: no \"brdf:theta_in_deg\" attribute (expected a composite "
                   "`brdf convert --exr-type float` wrote)\n",
                   f.string().c_str());
      return 2;
    }
    Luts().push_back({f.stem().string(), LutFromComposite(exr.image, std::move(theta))});
  }
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--checksums") == 0) {
      for (const NamedLut& l : Luts()) {
        const Bc6hVolume v =
            EncodeBc6hVolume(l.lut.texels.data(), Lut::kWidth, Lut::kHeight, l.lut.slices(), 1);
        std::printf("%s %zu %08x\n", l.name.c_str(), v.BlockCount(), v.Crc32());
      }
      return 0;
    }
  for (const NamedLut& l : Luts()) {
    benchmark::RegisterBenchmark(("EncodeBc6h/" + l.name).c_str(), BM_EncodeBc6h, &l.lut)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("DecodeBc6h/" + l.name).c_str(), BM_DecodeBc6h, &l.lut)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("PackRgb9e5/" + l.name).c_str(), BM_PackRgb9e5, &l.lut)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
