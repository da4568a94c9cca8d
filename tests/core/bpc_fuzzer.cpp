// libFuzzer target for the .bpc reader (DESIGN §8): any bytes must give a result or a
// FormatError, never a crash, hang or unbounded allocation. Build with
// -DBRDF_BUILD_FUZZERS=ON and clang; run: bpc_fuzzer -max_total_time=60 CORPUS_DIR
#include <cstddef>
#include <cstdint>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const brdf::BpcReadResult r = brdf::ParseBpc(data, size, "fuzz.bpc");
    // Everything returned must be internally consistent.
    if (r.valid_bytes > size) __builtin_trap();
    if (r.slice_indices.size() != r.measurement.slices.size()) __builtin_trap();
    for (const brdf::BpcProblem& p : r.problems)
      if (p.offset + p.size > size || p.message.empty()) __builtin_trap();
  } catch (const brdf::FormatError&) {
  }
  return 0;
}
