// CSV point clouds: one BRDF sample per row, readable by any spreadsheet.
//
//   # brdf-toolchain point cloud
//   # sample_name=red paint
//   theta_in,phi_in,theta_out,phi_out,r,g,b,sigma_r,sigma_g,sigma_b,flags
//   20,0,35,180,0.0912,0.0311,0.0208,0.0004,0.0002,0.0002,0
//
// Angles in degrees in our frame (docs/design.md §4: z normal, directions away from the surface,
// isotropic data with φin = 0); r, g, b are f_r in 1/sr, linear Rec.709, never multiplied by
// cosθ. The header line is required; its columns may come in any order. Required columns:
// theta_in, phi_in, theta_out, phi_out, r, g, b (the names may carry a "_deg" suffix:
// theta_in_deg). Optional: sigma_r, sigma_g, sigma_b (all three: one-standard-deviation
// uncertainty, 1/sr) and flags (the SampleFlag bit mask of measurement.h, 0–15).
//
// Lines starting with '#' before the header are comments; those of the form `key=value` carry
// metadata (the Metadata field names of measurement.h, `extra.<key>` for Metadata::extra,
// `incomplete_slice=<theta_in>,<phi_in>` for a slice whose capture was interrupted; '\n' and
// '\\' escapes inside values). Validation: θin in [0, 90), θout in [0, 90], φ in [−360, 360]
// (stored wrapped to [0, 360)), finite numbers everywhere, σ ≥ 0. Negative f_r values are kept:
// a noisy measurement of a dark direction legitimately produces them.
//
// Samples are grouped into slices by (theta_in, phi_in), slices sorted by θin then φin,
// samples kept in file order. The writer prints floats in their shortest round-trip form, so
// Measurement → CSV → Measurement is bit-exact for every float field.
#pragma once

#include <string>
#include <string_view>

#include "brdf/core/measurement.h"

namespace brdf {

// Parses CSV text; `file` names it in error messages. Throws FormatError naming the file and
// line (and the column) for a missing or unknown header column, a row with the wrong number of
// fields, a non-numeric, non-finite or out-of-range value, or a file without data rows.
Measurement ParseCsv(std::string_view text, const std::string& file);
// Reads a file of at most 128 MiB (about 1.5 M rows; larger ones are refused before reading).
Measurement ReadCsv(const std::string& path);

// The CSV text of a measurement (metadata as comments, sigma columns when any slice has sigma).
std::string FormatCsv(const Measurement& measurement);
// Writes atomically: a temporary sibling renamed over `path` only when complete.
void WriteCsv(const std::string& path, const Measurement& measurement);

}  // namespace brdf
