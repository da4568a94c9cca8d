// libFuzzer target for the KTX2 reader (BRDF_BUILD_FUZZERS=ON with clang). Any input must either
// parse or throw brdf::Error; a crash, hang, sanitizer report or other exception is a bug.
// Seed corpus: tests/export/corpus/*.ktx2; run by the fuzz_readers test (fuzz/run_fuzzers.sh).
#include <cstddef>
#include <cstdint>

#include "brdf/core/error.h"
#include "brdf/exporter/ktx2.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    brdf::exporter::ParseKtx2(data, size, "fuzz.ktx2");
  } catch (const brdf::Error&) {
  }
  return 0;
}
