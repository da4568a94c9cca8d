// Angle lists in messages of brdf::sources ("0, 20, 40, 60").
#pragma once

#include <string>
#include <vector>

#include "brdf/core/text_format.h"

namespace brdf::sources::detail {

// "%g" (brdf/core/text_format.h): the spelling of angles in capture metadata.
inline std::string Deg(double v) { return ShortNumberText(v); }

inline std::string DegList(const std::vector<double>& values) {
  return ShortNumberListText(values);
}

}  // namespace brdf::sources::detail
