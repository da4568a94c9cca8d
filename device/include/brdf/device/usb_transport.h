// Transports to real instruments: libusb (vendor-specific bulk interface) and hidapi (HID
// reports). They only move bytes (transport.h); framing, retries and everything else is the
// driver's. libusb and hidapi stay inside device/src: nothing here needs their headers.
//
// Faults as the driver sees them:
//   - unplugged (LIBUSB_ERROR_NO_DEVICE, hidapi read/write failure): Write/Read throw
//     DeviceError "… disconnected …";
//   - read timeout: Read returns 0 after timeout_ms;
//   - cancel (Transport::SetCancel): neither libusb's synchronous transfers nor hidapi's
//     hid_read_timeout can be woken, so with a cancel set a Read waits in steps of at most
//     kCancelStepMs and returns 0 at the first step that ends with the cancel raised: a cancel
//     ends a waiting read within kCancelStepMs (plus the scheduling of the thread), never later
//     than the read's own timeout. Bytes that arrive meanwhile are returned as usual (a step
//     that times out keeps what its transfer received).
//   - stalled bulk endpoint (LIBUSB_ERROR_PIPE): the USB transport clears the halt
//     (libusb_clear_halt) and repeats the transfer, up to kMaxHaltRetries times, then throws.
//     hidapi does not expose clear-halt; its reader thread resubmits a stalled interrupt
//     transfer by itself, so a transient stall costs nothing but time.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "brdf/device/transport.h"
#include "brdf/device/usb_models.h"

namespace brdf::device {

inline constexpr int kMaxHaltRetries = 3;
inline constexpr int kCancelStepMs = 50;

enum class AccessProblem {
  kNone,
  kPermission,  // the device node is not writable for this user: the udev rule is missing
  kBusy,        // another program (or a kernel driver) holds the interface
  kOther,
};

struct FoundInstrument {
  DeviceSpec::Kind kind = DeviceSpec::Kind::kUsb;  // kUsb or kHid
  std::uint16_t vendor_id = 0, product_id = 0;
  std::string model;             // from the model table
  std::string serial;            // the USB serial-number string; empty when it could not be read
  std::string bus_path;          // "bus 001 device 002" (USB) or hidapi's path ("1-1:1.0")
  std::string firmware_version;  // from IDENTIFY when `identify` was asked and it answered
  AccessProblem problem = AccessProblem::kNone;
  // What went wrong in one line of the user's terms; for kPermission it names the device node
  // and the remedy (UdevRemedy()).
  std::string problem_detail;
  std::string device_node;  // "/dev/bus/usb/001/002" or "/dev/hidraw3"; empty when unknown
};

// What a user whose account may not open the instrument's device node does, in one clause:
// copy the shipped udev rule (installed by `cmake --install` into <prefix>/lib/udev/rules.d;
// udev reads /etc/udev/rules.d), reload udev and plug the instrument in again.
std::string UdevRemedy();

// Every instrument of the model table on USB (bulk personality) and HID. With `identify`, each
// accessible one is opened and asked IDENTIFY for its firmware version. Never throws for a
// device it cannot open: that is a FoundInstrument with a problem.
std::vector<FoundInstrument> ListInstruments(bool identify);

// Opens the first instrument `spec` (kUsb or kHid) matches. Throws DeviceError when none is
// found (naming what was looked for), when it cannot be opened (with AccessProblem in the
// message's terms), InvalidArgument for a kSim spec.
std::unique_ptr<Transport> OpenUsbTransport(const DeviceSpec& spec);
std::unique_ptr<Transport> OpenHidTransport(const DeviceSpec& spec);

// Counters a transport keeps for tests and the log.
struct TransportStats {
  std::uint64_t transfers_in = 0, transfers_out = 0;
  std::uint64_t halts_cleared = 0;
};
// Stats of a transport made by OpenUsbTransport / OpenHidTransport (zeros for others).
TransportStats StatsOf(const Transport& transport);

}  // namespace brdf::device
