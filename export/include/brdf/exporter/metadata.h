// What an exported LUT says about itself, and the 2D layouts of docs/design.md §5.
//
// The same metadata goes into the JSON sidecar (sidecar.h), the KTX2 key/value data and the
// EXR header attributes (docs/design.md §7), so a texture found on its own still tells where it
// came from, how to address it and whether its content is intact.
#pragma once

#include <cstdint>
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

// How many samples of one measured slice carried the saturated flag (kFlagSaturated of
// brdf/core/measurement.h): their values are clipped at the detector's full scale, so the LUT
// texels built from them are lower bounds.
struct SaturatedCount {
  double theta_in_deg = 0;
  std::uint64_t count = 0;
};

// Relative errors of a compressed payload's texels against the float LUT it was made from, over
// one range of texels (docs/design.md §7): for texel x with reference r (the float LUT clamped
// to [0, 65504], what an unsigned texture can hold) and decoded value d,
// e = max_c |d_c − r_c| / max(max_c r_c, 10^−4·R, 2^−14), the colour's largest channel as the
// scale, with R the LUT's largest reference value: texels darker than 1/10,000 of the LUT's
// brightest (the noise of a black backing) are judged on that absolute scale, and 2^−14, the
// smallest normal half float, keeps an all-black LUT from dividing by zero.
struct ErrorStatistics {
  double max = 0, p99 = 0, median = 0;
  std::uint64_t texels = 0;  // texels in the range
};
// The certified error a compressed LUT carries in its sidecar: the statistics over the measured
// range (θout ≤ θb, where values come from the instrument) and over the filled range (θout > θb:
// extrapolated and below-horizon texels) separately, and the sizes.
struct CertifiedError {
  std::string format;  // "bc6h_ufloat"
  double theta_b_deg = 90;
  ErrorStatistics measured, filled;
  std::uint64_t bytes = 0;         // the compressed payload
  std::uint64_t rgb9e5_bytes = 0;  // the same LUT as RGB9E5, for the ratio
  // `--max-error E` that chose this representation (0: not chosen by a bound); written as
  // "max_error_bound" with "max_error_met".
  double max_error_bound = 0;
  bool max_error_met = true;
};

struct TextureMetadata {
  std::string name;    // material name, usually the input file's stem
  std::string source;  // where the values came from: input path(s), device, material file
  // Absent when the values did not need extrapolating (an analytic material evaluated
  // everywhere).
  std::optional<ExtrapolationInfo> extrapolation;
  // Saturated samples per measured slice, θin ascending. Absent when unknown (an exported LUT
  // whose sidecar did not record them); written as the sidecar's "saturated_samples".
  std::optional<std::vector<SaturatedCount>> saturated_samples;
  // Fitted analytic models (docs/design.md §9 material JSON objects, each a complete JSON text), if
  // any. Written verbatim into the sidecar's "fitted_models" array; must be valid JSON.
  std::vector<std::string> fitted_models_json;
  // What filled the directions the instrument did not measure (processing::BeyondReportJson: a
  // JSON object text), written as the sidecar's "beyond"; empty: not recorded (no fill).
  std::string beyond_json;
  // File names (no folder) of the other outputs of the same conversion ("gold.ktx2", ...),
  // recorded in the sidecar so `brdf info`/`brdf eval` can find the textures from it.
  std::vector<std::string> companion_files;
  // Empty: this build's version (BrdfToolVersion()).
  std::string tool_version;
  // Set for a compressed payload (`--compress bc6h`): written as the sidecar's "compression".
  std::optional<CertifiedError> certified_error;
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
// 0.5)/K (with θin − θin,0 in place of θin when the first slice is not at 0°). The shader code that
// applies it (tangent frame from n and l, specular frame, coordinates, fetch) is generated by
// shader_code.h; the published form u = φd/2π, v = θd/π, w = θin/θin,max is half a texel off
// on every axis.
std::string TexelCentreFormula();
// The published formula u = φd/2π, v = θd/π, w = θin/θin,max, which drops the half-texel term.
std::string PublishedFormula();
// The generated GLSL lookup for a LUT with this θin list (MeasuredBrdfShaderCode(kGlsl, ...):
// valid GLSL ES 3.00 and 4.50 after a #version line). Throws InvalidArgument for an empty list.
std::string ShaderSnippetGlsl(const std::vector<double>& theta_in_deg);

}  // namespace brdf::exporter
