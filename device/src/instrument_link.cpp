#include "brdf/device/instrument_link.h"

#include <string>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/device/usb_transport.h"

namespace brdf::device {
namespace {

class RealLink final : public InstrumentLink {
 public:
  explicit RealLink(std::unique_ptr<Transport> t) : transport_(std::move(t)) {}
  Transport& transport() override { return *transport_; }

 private:
  std::unique_ptr<Transport> transport_;
};

class LoopbackLink final : public InstrumentLink {
 public:
  explicit LoopbackLink(const SimulatorConfig& c) : firmware_(c), loop_(firmware_) {}
  Transport& transport() override { return loop_; }

 private:
  SimulatedFirmware firmware_;
  LoopbackTransport loop_;
};

}  // namespace

SimLink ParseSimLink(std::string_view text) {
  if (text == "loopback") return SimLink::kLoopback;
  if (text == "usb") return SimLink::kUsb;
  if (text == "hid") return SimLink::kHid;
  throw InvalidArgument("expected loopback, usb or hid, got '" + std::string(text) + "'");
}

std::unique_ptr<InstrumentLink> OpenInstrumentLink(const DeviceSpec& spec,
                                                   const SimulatorConfig& sim, SimLink link,
                                                   EmulatedLinkOpener emulated) {
  switch (spec.kind) {
    case DeviceSpec::Kind::kUsb:
      return std::make_unique<RealLink>(OpenUsbTransport(spec));
    case DeviceSpec::Kind::kHid:
      return std::make_unique<RealLink>(OpenHidTransport(spec));
    case DeviceSpec::Kind::kSim:
      break;
  }
  if (link == SimLink::kLoopback) {
    for (const Fault& f : sim.faults.faults)
      if (f.type == FaultType::kEndpointHalt)
        throw InvalidArgument("an endpoint halt needs a USB or HID link, not the loopback");
    return std::make_unique<LoopbackLink>(sim);
  }
  if (emulated == nullptr)
    throw InvalidArgument(
        "the simulated instrument over emulated USB or HID needs the umockdev emulation, which "
        "this program was built without");
  return emulated(sim, link);
}

}  // namespace brdf::device
