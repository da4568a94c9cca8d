// libFuzzer target: goniometer table text → GonioTable → Measurement.
#include <cstdint>
#include <string_view>

#include "brdf/core/error.h"
#include "brdf/core/gonio.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    brdf::GonioToMeasurement(brdf::ParseGonioTable(text, "fuzz.csv"), "fuzz.csv");
  } catch (const brdf::Error&) {
  }
  return 0;
}
