// Opening an instrument: the one factory behind `brdf capture --device`.
//
// A DeviceSpec (usb_models.h) names a real instrument on USB (vendor bulk interface, libusb) or
// HID (hidapi), or the simulated one. A real instrument opens through usb_transport.h; the
// simulated firmware (simulator.h) is connected in-process over the loopback transport, or,
// for tests and demos, behind real libusb or hidapi through umockdev. That last kind of link is
// the only part that needs umockdev, so it lives in brdf::device_emulation
// (brdf/device_emulation/emulated_usb.h, optional in the build: BRDF_BUILD_DEVICE_EMULATION)
// and is handed to OpenInstrumentLink as an EmulatedLinkOpener; brdf::device itself never links
// umockdev.
#pragma once

#include <memory>
#include <string_view>

#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"
#include "brdf/device/usb_models.h"

namespace brdf::device {

// How the simulated instrument is connected: in-process, or behind real libusb or hidapi
// through umockdev (emulated).
enum class SimLink { kLoopback, kUsb, kHid };
// "loopback", "usb", "hid"; throws InvalidArgument otherwise.
SimLink ParseSimLink(std::string_view text);

// An open connection to an instrument: the transport and whatever must live as long as it
// (the simulated firmware, its emulated USB device).
class InstrumentLink {
 public:
  virtual ~InstrumentLink() = default;
  virtual Transport& transport() = 0;
};

// Connects a simulated instrument built from `sim` over an emulated link (`link` is kUsb or
// kHid). brdf::device_emulation provides the one implementation, OpenEmulatedLink.
using EmulatedLinkOpener = std::unique_ptr<InstrumentLink> (*)(const SimulatorConfig& sim,
                                                               SimLink link);

// Opens what `spec` names: a real instrument over USB or HID, or (kSim) a simulated one built
// from `sim` and connected over `link` (`sim` and `link` are ignored for a real instrument).
// An emulated link (kUsb, kHid) goes through `emulated`. Throws DeviceError when no instrument
// answers to the spec or the emulation cannot start; InvalidArgument for a bad configuration
// (an endpoint-halt fault on the loopback, which has no endpoints) and for an emulated link
// when `emulated` is null (a program built without brdf::device_emulation).
std::unique_ptr<InstrumentLink> OpenInstrumentLink(const DeviceSpec& spec,
                                                   const SimulatorConfig& sim, SimLink link,
                                                   EmulatedLinkOpener emulated = nullptr);

}  // namespace brdf::device
