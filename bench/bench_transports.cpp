// One full reference capture (4 × 76 × 360 = 109,440 samples, GGX gold, noise on) over each
// transport, against the firmware's own time to produce the same frames (no host at all), and
// the frame decoder's throughput against a USB 2.0 high-speed link. libusb and hidapi run
// through umockdev: start this program under umockdev-wrapper (it stops with a message
// otherwise).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/models.h"
#include "brdf/device/driver.h"
#include "brdf/device/protocol.h"
#include "brdf/device/simulator.h"
#include "brdf/device/usb_transport.h"
#include "brdf/device_emulation/emulated_usb.h"

namespace {

using namespace brdf;
using namespace brdf::device;

SimulatorConfig GoldConfig() {
  Material m = Material::Make(
      Model::kGgx, {Rgb{0, 0, 0}, Rgb{0.962585, 0.786916, 0.408220}, Rgb{0.15, 0.15, 0.15}});
  m.name = "gold";
  SimulatorConfig c;
  c.sample = std::make_shared<AnalyticBrdf>(m);
  return c;
}

void RunCapture(Transport& link) {
  Driver driver(link);
  CapturePlan plan;
  plan.theta_in_deg = {0, 20, 40, 60};
  CaptureCallbacks callbacks;
  callbacks.on_slice = [](const Slice& s, const SliceReport&) {
    benchmark::DoNotOptimize(s.samples.data());
  };
  Capture(driver, plan, callbacks);
}

// The firmware's own scan: every frame of the same capture produced and encoded, drained by a
// byte pump that decodes nothing.
void BM_FirmwareOwnScan(benchmark::State& state) {
  std::vector<std::uint8_t> buffer(64 * 1024);
  for (auto _ : state) {
    SimulatedFirmware fw(GoldConfig());
    std::uint8_t seq = 0;
    auto ask = [&](MessageType t, std::vector<std::uint8_t> payload) {
      fw.Receive(EncodeFrame({static_cast<std::uint8_t>(t), seq++, std::move(payload)}));
      for (std::size_t n; (n = fw.Transmit(buffer)) > 0;) benchmark::DoNotOptimize(buffer.data());
    };
    ask(MessageType::kIdentify, {});
    ask(MessageType::kGetGeometry, {});
    ask(MessageType::kSetExposure, EncodeExposure({}));
    ask(MessageType::kMeasureDark, {});
    for (float t : {0.f, 20.f, 40.f, 60.f}) ask(MessageType::kMeasureWhite, EncodeThetaIn(t));
    for (float t : {0.f, 20.f, 40.f, 60.f}) ask(MessageType::kMeasureSlice, EncodeThetaIn(t));
  }
}
BENCHMARK(BM_FirmwareOwnScan)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CaptureLoopback(benchmark::State& state) {
  for (auto _ : state) {
    SimulatedFirmware fw(GoldConfig());
    LoopbackTransport link(fw);
    RunCapture(link);
  }
}
BENCHMARK(BM_CaptureLoopback)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CaptureOverUsb(benchmark::State& state) {
  const auto personality = static_cast<UsbPersonality>(state.range(0));
  if (!UmockdevAvailable()) {
    state.SkipWithError("run under umockdev-wrapper");
    return;
  }
  for (auto _ : state) {
    EmulatedUsbInstrument emu(GoldConfig(), personality);
    std::unique_ptr<Transport> link = personality == UsbPersonality::kBulk
                                          ? OpenUsbTransport(emu.Spec())
                                          : OpenHidTransport(emu.Spec());
    RunCapture(*link);
  }
}
// 0: libusb bulk, 1: hidapi reports.
BENCHMARK(BM_CaptureOverUsb)
    ->Arg(0)
    ->Arg(1)
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The host's share alone: the same capture with the instrument's bytes recorded from a
// loopback capture once and replayed in the chunks the driver asked for, so no firmware runs
// while the driver decodes, checks and calibrates. Loopback CPU minus firmware CPU measures
// the same share, but as the difference of two noisy figures on a shared machine.
class ReplayTransport final : public Transport {
 public:
  explicit ReplayTransport(const std::vector<std::vector<std::uint8_t>>& chunks)
      : chunks_(chunks) {}
  void Write(std::span<const std::uint8_t>) override {}
  std::size_t Read(std::span<std::uint8_t> buffer, int) override {
    if (next_ == chunks_.size()) return 0;
    const std::vector<std::uint8_t>& c = chunks_[next_++];
    std::copy(c.begin(), c.end(), buffer.begin());
    return c.size();
  }
  std::string Description() const override { return "replay"; }

 private:
  const std::vector<std::vector<std::uint8_t>>& chunks_;
  std::size_t next_ = 0;
};

void BM_DriverOnRecordedStream(benchmark::State& state) {
  SimulatedFirmware fw(GoldConfig());
  LoopbackTransport loopback(fw);
  RecordingTransport recording(loopback);
  RunCapture(recording);
  for (auto _ : state) {
    ReplayTransport replay(recording.received());
    RunCapture(replay);
  }
}
BENCHMARK(BM_DriverOnRecordedStream)->Unit(benchmark::kMillisecond)->UseRealTime();

// Frames of the whole capture, found and CRC-checked from one byte stream.
void BM_DecodeCaptureStream(benchmark::State& state) {
  std::vector<std::uint8_t> stream, buffer(64 * 1024);
  {
    SimulatedFirmware fw(GoldConfig());
    std::uint8_t seq = 0;
    for (float t : {0.f, 20.f, 40.f, 60.f}) {
      fw.Receive(EncodeFrame(
          {static_cast<std::uint8_t>(MessageType::kMeasureSlice), seq++, EncodeThetaIn(t)}));
      for (std::size_t n; (n = fw.Transmit(buffer)) > 0;)
        stream.insert(stream.end(), buffer.begin(),
                      buffer.begin() + static_cast<std::ptrdiff_t>(n));
    }
  }
  std::size_t frames = 0;
  for (auto _ : state) {
    FrameReader reader;
    for (std::size_t at = 0; at < stream.size(); at += 16384) {
      const std::size_t n = std::min<std::size_t>(16384, stream.size() - at);
      reader.Append(std::span<const std::uint8_t>(stream.data() + at, n));
      for (DecodeResult r = reader.Next(); r.status == DecodeStatus::kComplete; r = reader.Next())
        ++frames;
    }
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
  state.counters["stream_bytes"] = static_cast<double>(stream.size());
  benchmark::DoNotOptimize(frames);
}
BENCHMARK(BM_DecodeCaptureStream)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
