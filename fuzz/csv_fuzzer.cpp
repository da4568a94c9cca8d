// libFuzzer target: CSV point cloud text → Measurement → CSV → Measurement; the second read
// must succeed and give bit-identical samples (the writer prints shortest round-trip floats).
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "brdf/core/csv.h"
#include "brdf/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  brdf::Measurement m;
  try {
    m = brdf::ParseCsv(text, "fuzz.csv");
  } catch (const brdf::Error&) {
    return 0;
  }
  const brdf::Measurement again = brdf::ParseCsv(brdf::FormatCsv(m), "rewritten.csv");
  if (again.slices.size() != m.slices.size()) std::abort();
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    const auto& a = m.slices[i].samples;
    const auto& b = again.slices[i].samples;
    if (a.size() != b.size() || m.slices[i].complete != again.slices[i].complete) std::abort();
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (std::memcmp(a[k].rgb.data(), b[k].rgb.data(), sizeof a[k].rgb) != 0 ||
          std::memcmp(&a[k].theta_out_deg, &b[k].theta_out_deg, sizeof(float)) != 0 ||
          std::memcmp(&a[k].phi_out_deg, &b[k].phi_out_deg, sizeof(float)) != 0 ||
          a[k].flags != b[k].flags)
        std::abort();
    }
  }
  return 0;
}
