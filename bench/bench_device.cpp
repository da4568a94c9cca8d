// Simulated scatterometer throughput: a full reference capture (4 × 76 × 360 = 109,440
// samples) of a GGX material with detector noise on, through the real protocol, loopback
// transport and host calibration; plus the two halves separately.
#include <benchmark/benchmark.h>

#include <memory>

#include "brdf/core/brdf_source.h"
#include "brdf/core/models.h"
#include "brdf/device/driver.h"
#include "brdf/device/protocol.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"

namespace {

using namespace brdf;
using namespace brdf::device;

// Glossy gold (f0 from Johnson & Christy n, k; see data-samples/materials/gold.json).
Material Gold() {
  Material m;
  m.model = Model::kGgx;
  m.SetParameter(0, {0, 0, 0});
  m.SetParameter(1, {0.962585, 0.786916, 0.408220});
  m.SetParameter(2, {0.15, 0.15, 0.15});
  m.name = "gold";
  return m;
}

SimulatorConfig GoldConfig(double noise) {
  SimulatorConfig c;
  c.sample = std::make_shared<AnalyticBrdf>(Gold());
  c.noise_level = noise;
  return c;
}

void BM_FullSimulatedCapture(benchmark::State& state) {
  const double noise = static_cast<double>(state.range(0));
  std::size_t samples = 0;
  for (auto _ : state) {
    SimulatedFirmware fw(GoldConfig(noise));
    LoopbackTransport link(fw);
    Driver driver(link);
    CapturePlan plan;
    plan.theta_in_deg = {0, 20, 40, 60};
    plan.metadata.sample_name = "bench";
    CaptureCallbacks callbacks;
    callbacks.on_slice = [&](const Slice& s, const SliceReport&) {
      samples += s.samples.size();
      benchmark::DoNotOptimize(s.samples.data());
    };
    Capture(driver, plan, callbacks);
  }
  state.counters["samples/s"] =
      benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FullSimulatedCapture)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// The firmware alone: produce and encode every frame of one 27,360-sample slice.
void BM_FirmwareSliceStream(benchmark::State& state) {
  SimulatedFirmware fw(GoldConfig(1));
  std::vector<std::uint8_t> request =
      EncodeFrame({static_cast<std::uint8_t>(MessageType::kMeasureSlice), 0, EncodeThetaIn(40)});
  std::vector<std::uint8_t> buffer(64 * 1024);
  std::size_t bytes = 0;
  for (auto _ : state) {
    fw.Receive(request);
    for (std::size_t n; (n = fw.Transmit(buffer)) > 0;) bytes += n;
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes));
}
BENCHMARK(BM_FirmwareSliceStream)->Unit(benchmark::kMillisecond);

// The decoder alone: frames of a whole slice, found and CRC-checked from a byte stream.
void BM_DecodeSliceStream(benchmark::State& state) {
  SimulatedFirmware fw(GoldConfig(1));
  fw.Receive(
      EncodeFrame({static_cast<std::uint8_t>(MessageType::kMeasureSlice), 0, EncodeThetaIn(40)}));
  std::vector<std::uint8_t> stream, buffer(64 * 1024);
  for (std::size_t n; (n = fw.Transmit(buffer)) > 0;)
    stream.insert(stream.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
  for (auto _ : state) {
    FrameReader reader;
    reader.Append(stream);
    std::size_t frames = 0;
    for (DecodeResult r = reader.Next(); r.status != DecodeStatus::kNeedMore; r = reader.Next())
      frames += r.status == DecodeStatus::kComplete;
    benchmark::DoNotOptimize(frames);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
}
BENCHMARK(BM_DecodeSliceStream)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
