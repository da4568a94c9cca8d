// An "instrument" that answers anything with fixed bytes, in chunks of varying size (each chunk
// 1 + (its first byte mod 97) bytes long), and the steps a capture asks of it up to one slice,
// for driving the host driver with hostile input: the protocol fuzz entry (protocol_fuzzer.cpp)
// and tests/device/protocol_fuzz_smoke_test.cpp.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "brdf/device/driver.h"
#include "brdf/device/transport.h"

namespace brdf::device::fuzz {

class ReplayTransport final : public Transport {
 public:
  explicit ReplayTransport(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  void Write(std::span<const std::uint8_t>) override {}
  std::size_t Read(std::span<std::uint8_t> buffer, int) override {
    if (at_ >= bytes_.size()) return 0;
    const std::size_t chunk = 1 + (bytes_[at_] % 97);
    const std::size_t n = std::min({buffer.size(), chunk, bytes_.size() - at_});
    std::copy_n(bytes_.begin() + static_cast<std::ptrdiff_t>(at_), n, buffer.begin());
    at_ += n;
    return n;
  }
  std::string Description() const override { return "replay"; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

// Connect, exposure, dark, white and one slice at the first θin the instrument offers, as a
// capture does. Throws what the driver throws (brdf::Error for anything the bytes can cause).
inline Slice MeasureOneSlice(Driver& driver) {
  const InstrumentInfo& info = driver.Connect();
  driver.SetExposure({});
  driver.MeasureDark();
  const double theta = info.geometry.theta_in_deg.empty() ? 0 : info.geometry.theta_in_deg[0];
  driver.MeasureWhite(theta);
  return driver.MeasureSlice(theta);
}

}  // namespace brdf::device::fuzz
