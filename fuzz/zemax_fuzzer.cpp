// libFuzzer target: Zemax BSDF text → ZemaxBsdf → Measurement, TIS integration, and the
// writer's output read back (whatever the reader accepts, the writer must reproduce).
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "brdf/core/error.h"
#include "brdf/core/zemax.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  brdf::ZemaxBsdf z;
  try {
    z = brdf::ParseZemaxBsdf(text, "fuzz.bsdf");
  } catch (const brdf::Error&) {
    return 0;
  }
  brdf::ZemaxToMeasurement(z, "fuzz.bsdf", brdf::ZemaxImportOptions{true});
  // The quadrature costs 64,800 lookups per incidence: keep it to small tables.
  if (z.sample_rotation_deg.size() * z.angle_of_incidence_deg.size() <= 2)
    brdf::IntegrateZemaxTis(z);
  const brdf::ZemaxBsdf again = brdf::ParseZemaxBsdf(brdf::FormatZemaxBsdf(z), "rewritten.bsdf");
  // Values pass through 8 significant digits; the table's shape must match exactly.
  if (again.values.size() != z.values.size()) std::abort();
  for (std::size_t c = 0; c < z.values.size(); ++c)
    if (again.values[c].size() != z.values[c].size()) std::abort();
  if (again.angle_of_incidence_deg != z.angle_of_incidence_deg) std::abort();
  return 0;
}
