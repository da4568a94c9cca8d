// A fitted material as a value: the model and its parameters (Material, brdf/core/models.h)
// and the diagnostics of the fit that produced them (FitReport), as brdf::fit returns them and
// the engine hand-off and the tools pass them on. JSON only at the file boundary: the material
// file of docs/design.md §9 with the report under "fit" (FittedMaterialToJson), read back by
// ParseFittedMaterialJson, the one parser of that form.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/models.h"

namespace brdf {

enum class FitLoss { kNgan, kLog, kCbrt };
// "ngan", "log", "cbrt"; FitLossFromName throws InvalidArgument listing them.
std::string_view FitLossName(FitLoss loss);
FitLoss FitLossFromName(std::string_view name);

// How a fit ended. Files carry FitStatusName's text ("converged", "no-convergence", "failed",
// "evaluated").
enum class FitStatus {
  kConverged,      // Ceres reached a tolerance
  kNoConvergence,  // the iteration limit was reached; the result is still the best found
  kFailed,         // no usable result
  kEvaluated,      // no fit: EvaluateFit's report of a given material
};
std::string_view FitStatusName(FitStatus status);

// Error of the fitted material against the measurement over the samples used.
struct SliceFitError {
  double theta_in_deg = 0;
  std::size_t samples = 0;
  double rmse = 0;  // √(mean over samples and channels of (f − m)²), 1/sr, unweighted
  // Median over samples and channels of |f − m| / max(m, 1e-3 1/sr).
  double median_relative_error = 0;
};

// What a fit did and how good the result is (like Ceres' summary, as a value).
struct FitReport {
  Model model = Model::kGgx;
  FitLoss loss = FitLoss::kNgan;
  bool robust = false;
  // The Cauchy scale b the robust loss used (FitOptions::robust_scale, or the one chosen from
  // the data), in residual units; 0 without `robust`. final_cost is ½·Σ b²·ln(1 + r²/b²).
  double robust_scale = 0;
  FitStatus status = FitStatus::kFailed;
  std::string message;                      // Ceres' termination message of the winning refinement
  double initial_cost = 0, final_cost = 0;  // in the loss above, at the winning start and end
  double rmse = 0;                          // over all slices, as SliceFitError::rmse
  double median_relative_error = 0;
  std::vector<SliceFitError> slices;  // ascending θin
  int iterations = 0;                 // Ceres iterations, summed over every refinement
  int starts = 0;                     // refinements run
  double seconds = 0;                 // wall time of the whole fit, sweep included
  std::size_t samples_used = 0;
  std::size_t excluded_invalid = 0;    // flagged invalid or not finite
  std::size_t excluded_saturated = 0;  // flagged saturated (and not invalid)
  std::size_t excluded_theta_out = 0;  // beyond max_theta_out_deg or at/below the horizon
  // False when the data has a feature the model cannot represent; `warnings` says which.
  bool representable = true;
  // Largest difference in rg chromaticity between measurement and fit over the (θin, θh)
  // bins (θh edges 0, 2, 5, 10, 20, 35, 60, 90°) that carry at least 2 % of a slice's
  // luminance. Warned above 0.05.
  double chromaticity_error = 0;
  // How far the measured chromaticities of those bins stray from one straight line in the rg
  // plane (mixtures of two colours, a diffuse and a specular one, lie on a line). Above 0.02
  // the hue changes with angle in a way no model here represents: colour_shift, warned.
  double hue_spread = 0;
  bool colour_shift = false;
  std::vector<std::string> warnings;
  // The brdf-toolchain version that made the fit (SoftwareVersion() at the time).
  std::string software_version;
};

// A material and the fit that produced it. Material::extra_json holds the file's other
// members (never "fit": the report is `report`).
struct FittedMaterial {
  Material material;
  FitReport report;
};

// The report as a compact JSON object text, members in a fixed order (the "fit" member of a
// fitted material file).
std::string FitReportJson(const FitReport& report);

// The material file of docs/design.md §9 for `fitted` (MaterialToJson) with the report under
// "fit".
std::string FittedMaterialToJson(const FittedMaterial& fitted);

// Reads a fitted material file: ParseMaterialJson, and the member "fit", which must be an
// object with a "status" FitStatusName knows and a numeric "rmse"; the other report members
// are read when present (a missing one keeps FitReport's default) and must have their type.
// Throws FormatError naming `file`, the member, what was expected and what was found.
FittedMaterial ParseFittedMaterialJson(std::string_view json_text, const std::string& file);

}  // namespace brdf
