// The simulated firmware behind real USB: a umockdev testbed that presents the instrument as
// a USB device (vendor bulk interface or HID interface, usb_models.h) and answers the usbdevfs
// ioctls libusb issues (submit, reap and discard URBs, clear halt, claim interface, control
// requests for descriptors) with the bytes of a SimulatedFirmware. Real libusb, and hidapi's
// libusb backend, then talk to the firmware exactly as to hardware: enumeration by VID:PID,
// string descriptors, claiming, bulk/interrupt transfers, endpoint stalls, unplugging.
//
// Needs the process to run under umockdev's preload library (`umockdev-wrapper PROGRAM`, or
// LD_PRELOAD=libumockdev-preload.so.0); the constructor throws DeviceError otherwise. This is
// a test and demo facility, optional in the build (BRDF_BUILD_DEVICE_EMULATION): brdf links it
// for `capture --device sim --transport usb|hid`; opening real instruments, and the simulated
// one over the loopback, is brdf::device's (brdf/device/instrument_link.h).
//
// Pacing: IN transfers of the HID personality complete at most once per millisecond (an
// interrupt endpoint polled every full-speed frame, 64 KB/s), as a real device's would.
// hidapi queues only 30 input reports and drops the oldest when the application falls
// behind, so a faster device overruns a loaded host (measured: at one report per 125 µs, a
// full capture on a machine with load 9 on 2 cores lost reports); at 1 ms the host has 30 ms
// of slack. Bulk IN transfers complete as soon as the firmware has bytes (a short packet ends
// each transfer).
//
// Faults: the firmware's FaultPlan applies as on the loopback; FaultType::kEndpointHalt N
// makes the Nth IN transfer end with a stall (EPIPE). The bulk endpoint then stays halted
// until the host sends CLEAR_HALT; the HID interrupt endpoint recovers by itself after one
// stalled transfer (hidapi cannot clear a halt; its reader resubmits). When the firmware's link
// drops (FaultType::kDisconnect) every URB fails with ENODEV/ESHUTDOWN, as for an unplugged
// device.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "brdf/device/instrument_link.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"
#include "brdf/device/usb_models.h"

namespace brdf::device {

enum class UsbPersonality { kBulk, kHid };

class EmulatedUsbInstrument {
 public:
  // `config.serial` becomes the USB serial-number string. Throws DeviceError when umockdev's
  // preload library is not active, InvalidArgument for an unusable configuration.
  EmulatedUsbInstrument(SimulatorConfig config, UsbPersonality personality,
                        const UsbModel& model = UsbModels().front());
  ~EmulatedUsbInstrument();
  EmulatedUsbInstrument(const EmulatedUsbInstrument&) = delete;
  EmulatedUsbInstrument& operator=(const EmulatedUsbInstrument&) = delete;

  // The --device spec that opens this instrument (VID:PID:SERIAL).
  DeviceSpec Spec() const;
  std::uint64_t halts_cleared() const;  // CLEAR_HALT requests received
  std::uint64_t in_transfers() const;   // IN URBs completed with data
  std::uint64_t frames_sent() const;    // firmware frames
  // The firmware will send nothing more before ABORT, or ever (SimulatedFirmware::silent).
  bool firmware_silent() const;
  // Simulates pulling the cable: the device vanishes from the bus.
  void Unplug();
  // Sets the permission bits of the emulated device node (/dev/bus/usb/001/002 inside the
  // testbed): 0 gives what a user without the udev rule meets, EACCES on open. (A process with
  // CAP_DAC_OVERRIDE, e.g. root, still opens it.) Throws DeviceError when chmod fails.
  void SetNodeMode(unsigned mode);
  // The device node as the instrument's user sees it, "/dev/bus/usb/001/002".
  std::string DeviceNode() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True when umockdev's preload library is active in this process.
bool UmockdevAvailable();

// The EmulatedLinkOpener of brdf/device/instrument_link.h: the firmware of `sim` behind an
// EmulatedUsbInstrument (kUsb: the bulk personality opened through libusb, kHid: the HID one
// through hidapi), which lives as long as the link. Throws DeviceError when umockdev's preload
// library is not active or no transport opens, InvalidArgument for kLoopback.
std::unique_ptr<InstrumentLink> OpenEmulatedLink(const SimulatorConfig& sim, SimLink link);

}  // namespace brdf::device
