// .bpc write and read throughput for one full reference capture: 4 θin slices × 76 θout ×
// 360 φout = 109,440 samples with σ (about 4.8 MB). Target: well under 10 ms per read.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/file_util.h"

namespace {

brdf::Measurement FullCapture() {
  brdf::Measurement m;
  m.metadata.sample_name = "bench";
  for (int i = 0; i < 4; ++i) {
    brdf::Slice s;
    s.theta_in_deg = 20.0 * i;
    s.has_sigma = true;
    s.samples.reserve(76 * 360);
    for (int t = 0; t <= 75; ++t) {
      for (int p = 0; p < 360; ++p) {
        brdf::Sample x;
        x.theta_in_deg = static_cast<float>(s.theta_in_deg);
        x.theta_out_deg = static_cast<float>(t);
        x.phi_out_deg = static_cast<float>(p);
        const float v = 0.3f + 0.001f * static_cast<float>(t * 360 + p);
        x.rgb = {v, 0.9f * v, 0.8f * v};
        x.sigma = {0.01f * v, 0.01f * v, 0.01f * v};
        s.samples.push_back(x);
      }
    }
    m.slices.push_back(std::move(s));
  }
  return m;
}

const brdf::Measurement& Capture() {
  static const brdf::Measurement m = FullCapture();
  return m;
}

std::string BenchPath(const char* name) {
  return (std::filesystem::temp_directory_path() /
          ("brdf_bench_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

void BM_BpcEncode(benchmark::State& state) {
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string out = brdf::EncodeBpc(Capture());
    bytes = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
}
BENCHMARK(BM_BpcEncode)->Unit(benchmark::kMillisecond);

// Whole-file write: encode, temporary file, fsync, rename (WriteBpc).
void BM_BpcWriteAtomic(benchmark::State& state) {
  const std::string path = BenchPath("write.bpc");
  for (auto _ : state) brdf::WriteBpc(path, Capture());
  state.SetBytesProcessed(
      static_cast<std::int64_t>(state.iterations() * std::filesystem::file_size(path)));
  std::filesystem::remove(path);
}
BENCHMARK(BM_BpcWriteAtomic)->Unit(benchmark::kMillisecond);

// A capture as the instrument writes it: header, one synced chunk per slice, end chunk.
void BM_BpcAppendCapture(benchmark::State& state) {
  const std::string path = BenchPath("append.bpc");
  for (auto _ : state) {
    brdf::BpcAppender a = brdf::BpcAppender::Create(path, Capture().metadata);
    for (const brdf::Slice& s : Capture().slices) a.AppendSlice(s);
    a.Finish(Capture().metadata);
  }
  state.SetBytesProcessed(
      static_cast<std::int64_t>(state.iterations() * std::filesystem::file_size(path)));
  std::filesystem::remove(path);
}
BENCHMARK(BM_BpcAppendCapture)->Unit(benchmark::kMillisecond);

// Read from a file (page cache warm): the figure the 10 ms target is about.
void BM_BpcRead(benchmark::State& state) {
  const std::string path = BenchPath("read.bpc");
  brdf::WriteBpc(path, Capture());
  for (auto _ : state) {
    brdf::BpcReadResult r = brdf::ReadBpc(path);
    benchmark::DoNotOptimize(r.measurement.slices.data());
  }
  state.SetBytesProcessed(
      static_cast<std::int64_t>(state.iterations() * std::filesystem::file_size(path)));
  std::filesystem::remove(path);
}
BENCHMARK(BM_BpcRead)->Unit(benchmark::kMillisecond);

// Parse only (bytes already in memory): CRCs, framing and sample decoding.
void BM_BpcParse(benchmark::State& state) {
  const std::string bytes = brdf::EncodeBpc(Capture());
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  for (auto _ : state) {
    brdf::BpcReadResult r = brdf::ParseBpc(data, bytes.size(), "bench.bpc");
    benchmark::DoNotOptimize(r.measurement.slices.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes.size()));
}
BENCHMARK(BM_BpcParse)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
