#include "brdf/core/error.h"
#include "brdf/device/cancel.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"

namespace brdf::device {

void LoopbackTransport::Write(std::span<const std::uint8_t> bytes) {
  if (!firmware_.link_up())
    throw DeviceError(Description() + ": the instrument disconnected (write failed)");
  firmware_.Receive(bytes);
}

std::size_t LoopbackTransport::Read(std::span<std::uint8_t> buffer, int /*timeout_ms*/) {
  const std::size_t n = firmware_.Transmit(buffer);
  if (n == 0 && !firmware_.link_up())
    throw DeviceError(Description() + ": the instrument disconnected (read failed)");
  // A held firmware answers nothing until ABORT, which the host sends once it is cancelled.
  if (n == 0 && firmware_.held() && cancel_ != nullptr) cancel_->Wait(-1);
  return n;
}

std::string LoopbackTransport::Description() const {
  return "loopback to simulated " + firmware_.config().model.model + " " +
         firmware_.config().serial;
}

}  // namespace brdf::device
