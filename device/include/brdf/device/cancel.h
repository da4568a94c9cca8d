// The cancel of a capture: raised by a signal handler (Ctrl-C, SIGTERM, SIGHUP) or another
// thread, seen by the driver between frames and by a transport's read while it waits.
//
// A flag alone would be seen only when a read returns; CancelSignal also wakes a wait. Raise()
// sets the flag and writes to an eventfd, both async-signal-safe, so a read waiting in poll(2)
// on that descriptor (Wait) returns at once: the loopback's read of a held simulated firmware
// (FaultType::kHold in simulator.h) waits on it with no timeout at all. libusb's synchronous
// transfers and hidapi's hid_read_timeout cannot wait on a descriptor; their reads wait in steps
// of kCancelStepMs and look at raised() between steps (usb_transport.h). The bound a session
// gives a cancel is in capture_session.h.
#pragma once

#include <atomic>

namespace brdf::device {

class CancelSignal {
 public:
  // Throws brdf::DeviceError when the kernel refuses an eventfd (out of descriptors).
  CancelSignal();
  ~CancelSignal();
  CancelSignal(const CancelSignal&) = delete;
  CancelSignal& operator=(const CancelSignal&) = delete;

  // Async-signal-safe; raising twice is raising once.
  void Raise() noexcept;
  bool raised() const noexcept { return raised_.load(); }
  // Lowers the signal before a new session; not while a session runs.
  void Reset() noexcept;
  // Waits until the signal is raised or `timeout_ms` passed (negative: no limit); returns
  // raised(). An interrupted poll (EINTR) waits again for the time left.
  bool Wait(int timeout_ms) const;

 private:
  std::atomic<bool> raised_{false};
  int fd_ = -1;  // eventfd, readable once raised
};

}  // namespace brdf::device
