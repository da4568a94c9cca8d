// libFuzzer target for the DDS reader (BRDF_BUILD_FUZZERS=ON with clang). Any input must either
// parse or throw brdf::Error. Seed corpus: tests/export/corpus/*.dds.
#include <cstddef>
#include <cstdint>

#include "brdf/core/error.h"
#include "brdf/exporter/dds.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    brdf::exporter::ParseDds(data, size, "fuzz.dds");
  } catch (const brdf::Error&) {
  }
  return 0;
}
