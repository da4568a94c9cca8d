// Angle lists in messages of brdf::sources ("0, 20, 40, 60").
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace brdf::sources::internal {

inline std::string Deg(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

inline std::string DegList(const std::vector<double>& values) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : ", ") + Deg(v);
  return out;
}

}  // namespace brdf::sources::internal
