#include "brdf/exporter/metadata.h"

#include <algorithm>

#include <fmt/format.h>

#include "brdf/core/error.h"

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

namespace {

// A GLSL float literal ("20.0", "2.5"): GLSL ES has no implicit int → float conversion.
std::string GlslFloat(double v) {
  std::string s = fmt::format("{:g}", v);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

}  // namespace

std::string ShaderSnippetGlsl(double delta_in_deg, int slices) {
  return fmt::format(
      "// uniform sampler3D lut: RGB9E5, linear filtering, CLAMP_TO_EDGE on s, t and r\n"
      "precision highp sampler3D;  // GLSL ES has no default precision for sampler3D\n"
      "// w_d: view direction in the specular frame of theta_in, w_d = S(theta_in) * w_out\n"
      "vec3 BrdfLut(sampler3D lut, float theta_in_deg, vec3 w_d) {{\n"
      "  float theta_d = degrees(acos(clamp(w_d.z, -1.0, 1.0)));\n"
      "  float phi_d = degrees(atan(w_d.y, w_d.x));\n"
      "  if (phi_d < 0.0) phi_d += 360.0;\n"
      "  vec3 uvw = vec3((phi_d + 0.5) / 361.0, (theta_d + 0.5) / 181.0,\n"
      "                  (theta_in_deg / {} + 0.5) / {}.0);\n"
      "  // published form, half a texel off: vec3(phi_d / 360.0, theta_d / 180.0, "
      "theta_in_deg / {})\n"
      "  return texture(lut, uvw).rgb;  // f_r in 1/sr, not multiplied by cos(theta)\n"
      "}}\n",
      GlslFloat(delta_in_deg > 0 ? delta_in_deg : 1.0), slices,
      GlslFloat(delta_in_deg > 0 ? delta_in_deg * std::max(slices - 1, 1) : 1.0));
}

}  // namespace brdf::exporter
