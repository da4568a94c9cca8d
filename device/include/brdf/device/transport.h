// Transports move bytes between the host and an instrument; they know nothing of frames.
//
// The driver (driver.h) speaks the protocol of protocol.h over any Transport. Real instruments
// connect over USB bulk endpoints (libusb) or USB HID reports (hidapi); the simulated
// instrument connects in-process through LoopbackTransport. A transport that carries fixed-size
// reports (HID: 64 bytes) packs the byte stream into them itself: the protocol finds frames
// in any chunking, so nothing above the transport depends on report sizes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace brdf::device {

class CancelSignal;
class SimulatedFirmware;

class Transport {
 public:
  virtual ~Transport() = default;

  // Sends all of `bytes`. Throws brdf::DeviceError when the link is gone.
  virtual void Write(std::span<const std::uint8_t> bytes) = 0;

  // Receives between 1 and buffer.size() bytes into `buffer`, waiting at most `timeout_ms`
  // for the first one; returns 0 when nothing arrived in that time (the caller decides
  // whether that is a timeout). Throws brdf::DeviceError when the link is gone.
  virtual std::size_t Read(std::span<std::uint8_t> buffer, int timeout_ms) = 0;

  // Says what the transport is connected to, for messages: "loopback to SIM-000001".
  virtual std::string Description() const = 0;

  // The session's cancel (cancel.h), or null: once it is raised, a Read waiting for the
  // instrument returns 0 early (USB and HID within kCancelStepMs of usb_transport.h, the
  // loopback at once) instead of waiting out its timeout. The default ignores it: such a Read
  // returns by its timeout, and the driver honours the cancel then. `cancel` must outlive the
  // transport's use of it (the driver sets it for a session and clears it after).
  virtual void SetCancel(const CancelSignal* cancel) { (void)cancel; }
};

// Connects the host to a SimulatedFirmware in the same process and thread: Write hands the
// bytes to the firmware, Read pulls the bytes the firmware has to send (it produces streamed
// frames on demand, so a slice is never buffered whole). Runs on virtual time: when the
// firmware has nothing to send, Read returns 0 at once, exactly what a real transport returns
// after waiting `timeout_ms`. A fault injected into the firmware (FaultPlan) shows here as a
// DeviceError (disconnect) or as Read returning 0 (stall). The one exception to virtual time is
// a held firmware (FaultType::kHold): with a cancel set, Read then waits for the cancel, in real
// time and without a limit, so that a test can interrupt a capture at a chosen frame whatever
// the machine's load; without a cancel a hold reads as a timeout.
class LoopbackTransport final : public Transport {
 public:
  // `firmware` must outlive the transport.
  explicit LoopbackTransport(SimulatedFirmware& firmware) : firmware_(firmware) {}

  void Write(std::span<const std::uint8_t> bytes) override;
  std::size_t Read(std::span<std::uint8_t> buffer, int timeout_ms) override;
  std::string Description() const override;
  void SetCancel(const CancelSignal* cancel) override { cancel_ = cancel; }

 private:
  SimulatedFirmware& firmware_;
  const CancelSignal* cancel_ = nullptr;
};

// Forwards to another transport and keeps every chunk of bytes the instrument sent, in order
// and as delivered: a session recorded for a benchmark to replay, or for a test to decode and
// recompute from the raw readings.
class RecordingTransport final : public Transport {
 public:
  // `link` must outlive the recorder.
  explicit RecordingTransport(Transport& link) : link_(link) {}

  void Write(std::span<const std::uint8_t> bytes) override { link_.Write(bytes); }
  std::size_t Read(std::span<std::uint8_t> buffer, int timeout_ms) override {
    const std::size_t n = link_.Read(buffer, timeout_ms);
    if (n > 0)
      received_.emplace_back(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }
  std::string Description() const override { return link_.Description(); }
  void SetCancel(const CancelSignal* cancel) override { link_.SetCancel(cancel); }

  const std::vector<std::vector<std::uint8_t>>& received() const { return received_; }

 private:
  Transport& link_;
  std::vector<std::vector<std::uint8_t>> received_;
};

}  // namespace brdf::device
