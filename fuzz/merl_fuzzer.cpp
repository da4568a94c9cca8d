// libFuzzer target for the MERL `.binary` reader and the SHA-256 digest table parser: any
// input must be refused with a brdf::FormatError (a valid MERL file is 35 MB, beyond any
// fuzzing input), the bin lookup must stay inside the table for any direction pair, and the
// table parser must accept or refuse any text cleanly.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

#include "brdf/core/error.h"
#include "brdf/core/merl.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    brdf::MerlBrdf::FromBytes(std::span(data, size), "fuzz.binary");
    __builtin_trap();  // cannot be a whole valid file at fuzzing sizes
  } catch (const brdf::FormatError&) {
  }
  if (size >= 48) {
    double v[6];
    std::memcpy(v, data, sizeof v);
    const brdf::Vec3 wi{v[0], v[1], v[2]}, wo{v[3], v[4], v[5]};
    const brdf::MerlBin bin = brdf::MerlBinOf(wi, wo);
    if (bin.theta_half < 0 || bin.theta_half >= brdf::kMerlThetaHalfBins || bin.theta_diff < 0 ||
        bin.theta_diff >= brdf::kMerlThetaDiffBins || bin.phi_diff < 0 ||
        bin.phi_diff >= brdf::kMerlPhiDiffBins || bin.Index() >= brdf::kMerlBinsPerChannel)
      __builtin_trap();
  }
  try {
    const auto table = brdf::ParseMerlDigestTable(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.tsv");
    for (const auto& d : table)
      if (d.sha256.size() != 64 || d.material.empty()) __builtin_trap();
  } catch (const brdf::FormatError&) {
  }
  return 0;
}
