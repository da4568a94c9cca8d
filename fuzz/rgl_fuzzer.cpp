// libFuzzer target for the RGL `.bsdf` reader: any input must either load or be refused with
// a brdf::FormatError, and a loaded material must evaluate to finite values >= 0.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/rgl.h"

namespace {

// Direction pairs that reach the evaluator's corner cases: normal incidence, the exact
// mirror direction (half vector at the pole), grazing angles, opposite azimuths.
const std::vector<std::pair<brdf::Vec3, brdf::Vec3>>& Pairs() {
  static const auto pairs = [] {
    std::vector<std::pair<brdf::Vec3, brdf::Vec3>> p;
    const double thetas[] = {0.0, 5.0, 30.0, 60.0, 84.0, 89.9};
    for (const double ti : thetas)
      for (const double to : thetas)
        for (const double dphi : {0.0, 90.0, 180.0, 250.0})
          p.emplace_back(brdf::SphericalDirectionDeg(ti, 10.0),
                         brdf::SphericalDirectionDeg(to, 10.0 + dphi));
    return p;
  }();
  return pairs;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const brdf::TensorFile tf =
        brdf::TensorFile::Parse(std::vector<std::uint8_t>(data, data + size), "fuzz.bsdf");
    const brdf::RglBrdf material = brdf::RglBrdf::FromTensorFile(tf, "fuzz.bsdf");
    for (const auto& [wi, wo] : Pairs()) {
      for (const double v : material.Eval(wi, wo))
        if (!std::isfinite(v) || v < 0.0) __builtin_trap();
    }
  } catch (const brdf::FormatError&) {
    // The expected outcome for malformed input.
  }
  return 0;
}
