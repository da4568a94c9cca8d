// Fuzz entry for everything that parses bytes from the other end of the link: the frame
// decoder, every payload decoder, the host driver fed a hostile instrument, and the simulated
// firmware fed a hostile host. Built as a libFuzzer target with BRDF_BUILD_FUZZERS (clang);
// protocol_fuzz_smoke_test runs the same entry on generated inputs in every build. Seeds:
// fuzz/corpus/protocol (make_protocol_corpus.py).
//
// Contract checked: no crash, no hang, no unbounded allocation; failures are brdf::Error.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/device/driver.h"
#include "brdf/device/protocol.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"
#include "replay_transport.h"

namespace {

using namespace brdf;
using namespace brdf::device;

using fuzz::ReplayTransport;

void DecodePayload(const Frame& f) {
  try {
    switch (static_cast<MessageType>(f.type)) {
      case MessageType::kIdentity:
        DecodeIdentity(f.payload);
        break;
      case MessageType::kGeometry:
        DecodeGeometry(f.payload);
        break;
      case MessageType::kSetExposure:
        DecodeExposure(f.payload);
        break;
      case MessageType::kMeasureWhite:
      case MessageType::kMeasureSlice:
        DecodeThetaIn(f.payload);
        break;
      case MessageType::kAck:
        DecodeAck(f.payload);
        break;
      case MessageType::kDark:
        DecodeDark(f.payload);
        break;
      case MessageType::kWhite:
        DecodeWhite(f.payload);
        break;
      case MessageType::kSliceBegin:
        DecodeSliceBegin(f.payload);
        break;
      case MessageType::kRowData:
        DecodeRowData(f.payload);
        break;
      case MessageType::kSliceEnd:
        DecodeSliceEnd(f.payload);
        break;
      case MessageType::kError:
        DecodeError(f.payload);
        break;
      default:
        break;
    }
  } catch (const DeviceError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);

  FrameReader reader;
  reader.Append(bytes);
  for (DecodeResult r = reader.Next(); r.status != DecodeStatus::kNeedMore; r = reader.Next())
    if (r.status == DecodeStatus::kComplete) DecodePayload(r.frame);

  {
    ReplayTransport link(bytes);
    Driver driver(link, DriverOptions{});
    try {
      fuzz::MeasureOneSlice(driver);
    } catch (const Error&) {
    }
  }

  {
    static const auto sample = std::make_shared<AnalyticBrdf>(Material{});
    SimulatorConfig c;
    c.sample = sample;
    c.model.theta_out_step_deg = 15;
    c.model.phi_out_step_deg = 30;
    SimulatedFirmware fw(c);
    try {
      fw.Receive(bytes);
      std::uint8_t out[4096];
      std::size_t total = 0;
      for (std::size_t n; total < (1u << 20) && (n = fw.Transmit(out)) > 0;) total += n;
    } catch (const Error&) {
    }
  }
  return 0;
}
