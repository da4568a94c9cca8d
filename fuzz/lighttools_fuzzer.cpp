// libFuzzer target: LightTools BSDF text → LightToolsBsdf → Measurement, and the writer's
// output read back (whatever the reader accepts, the writer must reproduce).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "brdf/core/error.h"
#include "brdf/core/lighttools.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  brdf::LightToolsBsdf lt;
  try {
    lt = brdf::ParseLightToolsBsdf(text, "fuzz.bsdf");
  } catch (const brdf::Error&) {
    return 0;
  }
  try {
    brdf::LightToolsToMeasurement(lt, "fuzz.bsdf", brdf::LightToolsImportOptions{true});
  } catch (const brdf::FormatError&) {
    // Missing or repeated channel blocks, nothing to import: expected outcomes.
  }
  const brdf::LightToolsBsdf again =
      brdf::ParseLightToolsBsdf(brdf::FormatLightToolsBsdf(lt), "rewritten.bsdf");
  if (again.blocks.size() != lt.blocks.size()) std::abort();
  // Values pass through 9 significant digits.
  for (std::size_t i = 0; i < lt.blocks.size(); ++i) {
    const auto& a = lt.blocks[i].values;
    const auto& b = again.blocks[i].values;
    if (a.size() != b.size()) std::abort();
    for (std::size_t k = 0; k < a.size(); ++k)
      if (std::fabs(a[k] - b[k]) > 1e-8 * std::fabs(a[k]) + 1e-300) std::abort();
  }
  return 0;
}
