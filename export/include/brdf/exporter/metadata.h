// What an exported LUT says about itself, and the 2D layouts of docs/design.md §5.
//
// The same metadata goes into the JSON sidecar (sidecar.h), the KTX2 key/value data and the
// EXR header attributes (docs/design.md §7), so a texture found on its own still tells where it
// came from, how to address it and whether its content is intact.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace brdf::exporter {

// Grazing extrapolation parameters of docs/design.md §6 used to fill θout between θb and 90°.
struct ExtrapolationInfo {
  double p = 1.0;           // value factor at 90° (1 = clamping)
  double l = 0.5;           // Bézier control abscissa in [0, 1] (0.5 = linear ramp)
  double theta_b_deg = 75;  // the last measured θout of the data
};

struct TextureMetadata {
  std::string name;    // material name, usually the input file's stem
  std::string source;  // where the values came from: input path(s), device, material file
  // Absent when the values did not need extrapolating (an analytic material evaluated
  // everywhere).
  std::optional<ExtrapolationInfo> extrapolation;
  // Fitted analytic models (docs/design.md §9 material JSON objects, each a complete JSON text), if
  // any. Written verbatim into the sidecar's "fitted_models" array; must be valid JSON.
  std::vector<std::string> fitted_models_json;
  // File names (no folder) of the other outputs of the same conversion ("gold.ktx2", ...),
  // recorded in the sidecar so `brdf info`/`brdf eval` can find the textures from it.
  std::vector<std::string> companion_files;
  // Empty: this build's version (BrdfToolVersion()).
  std::string tool_version;
};

// "brdf-toolchain <version>" of this build (the KTXwriter value).
std::string BrdfToolWriter();
// "<version>" of this build, e.g. "0.1.0".
std::string BrdfToolVersion();

// A grid of cells, row-major, top-left first: cell n is at column n mod columns,
// row n div columns.
struct GridLayout {
  int columns = 1, rows = 1;
  int CellColumn(int n) const { return n % columns; }
  int CellRow(int n) const { return n / columns; }
};

// C = ceil(√count) columns and R = ceil(count / C) rows (docs/design.md §5: 4 slices → 2 × 2, 3 → 2
// × 2, 5 → 3 × 2). Computed in integers, so perfect squares are exact. Throws InvalidArgument for
// count < 1.
GridLayout SquareishGrid(int count);

// The texel conventions of docs/design.md §5, in words, for sidecars, manifests and shader
// snippets. Centre-exact (ours): u = (φd/1° + 0.5)/361, v = (θd/1° + 0.5)/181, w = (θin/Δin +
// 0.5)/K (with θin − θin,0 in place of θin when the first slice is not at 0°). In a shader
// (ShaderSnippetGlsl), with ω_d = S(θin)·ω_out the view direction in the specular frame:
//   float theta_d = degrees(acos(clamp(w_d.z, -1.0, 1.0)));
//   float phi_d = degrees(atan(w_d.y, w_d.x)); if (phi_d < 0.0) phi_d += 360.0;
//   vec3 f = texture(lut, vec3((phi_d + 0.5) / 361.0, (theta_d + 0.5) / 181.0,
//                              (theta_in_deg / DELTA_IN_DEG + 0.5) / K)).rgb;
// The sampler uses linear filtering and CLAMP_TO_EDGE on all three axes; f is f_r in 1/sr
// (multiply by cosθout and the light for radiance). The published form
//   vec3(phi_d / 360.0, theta_d / 180.0, theta_in_deg / THETA_IN_MAX_DEG)
// is half a texel off on every axis.
std::string TexelCentreFormula();
// The published formula u = φd/2π, v = θd/π, w = θin/θin,max, which drops the half-texel term.
std::string PublishedFormula();
// The GLSL lookup above as one text (DELTA_IN_DEG and K filled in).
std::string ShaderSnippetGlsl(double delta_in_deg, int slices);

}  // namespace brdf::exporter
