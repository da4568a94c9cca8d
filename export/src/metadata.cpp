#include "brdf/exporter/metadata.h"

#include <algorithm>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/exporter/shader_code.h"

namespace brdf::exporter {

std::string BrdfToolVersion() { return BRDF_VERSION_STRING; }
std::string BrdfToolWriter() { return std::string("brdf-toolchain ") + BRDF_VERSION_STRING; }

GridLayout SquareishGrid(int count) {
  if (count < 1)
    throw InvalidArgument("grid layout: need at least one cell, got " + std::to_string(count));
  int columns = 1;
  while (columns * columns < count) ++columns;  // smallest C with C² ≥ count: ceil(√count)
  const int rows = (count + columns - 1) / columns;
  return {columns, rows};
}

std::string TexelCentreFormula() {
  return "u = (phi_d/1deg + 0.5)/361, v = (theta_d/1deg + 0.5)/181, "
         "w = ((theta_in - theta_in_0)/delta_in + 0.5)/K; clamp-to-edge, trilinear; texel (i, j, "
         "k) "
         "holds f at exactly phi_d = i deg, theta_d = j deg, theta_in = theta_in_0 + k*delta_in "
         "(texel centres); column 360 repeats column 0; row 0 is theta_d = 0 (top)";
}

std::string PublishedFormula() {
  return "u = phi_d/(2 pi), v = theta_d/pi, w = theta_in/theta_in_max (drops the half-texel "
         "term: addresses texel edges, off by half a texel from the centre-exact formula)";
}

std::string ShaderSnippetGlsl(const std::vector<double>& theta_in_deg) {
  return MeasuredBrdfShaderCode(ShaderLanguage::kGlsl, LutShaderLayout(theta_in_deg));
}

}  // namespace brdf::exporter
