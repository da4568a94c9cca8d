// Fitting analytic BRDF models (brdf/core/models.h) to a measurement, with Ceres.
//
// FitMaterial takes a measured point cloud and returns the material of the requested model
// that best matches it under the chosen loss, together with a FitReport saying how good the
// match is overall and for every incidence slice. Parameters stay inside their ranges
// (ParameterInfo::min/max, the engine UI ranges for engine models), so an engine fit can be
// typed into the engine as it is.
//
// How (docs/design.md §9): samples flagged invalid or saturated, non-finite values, samples at
// or below the horizon and samples beyond `max_theta_out_deg` are excluded and counted. Each
// remaining sample carries the solid angle of its cell on the measurement grid (estimated per
// slice from its θout rows and the number of φout samples in each), normalised to sum 1.
// A deterministic multi-start first sweeps the lobe shape (n, α, roughness, smoothness; for
// engine models also metallic or a grey specular level) on a subsample and solves the colour
// parameters of every candidate in closed form by linear least squares; Ceres (bounded
// Levenberg-Marquardt) then refines the best `starts` candidates on all samples, and the
// lowest final cost wins. The legacy models' RGB channels are independent and are refined as
// three independent problems. The derivatives are written out per model and checked against
// Ceres' automatic ones in the tests; a value that reaches a bound with the gradient pointing
// out of its range is held there while the others converge (and released if the gradient
// turns), so optima on a bound (metallic 0, ks 0) are reached in a few steps.
//
// Losses (r = residual of one sample and channel, w = its solid-angle weight, c = cosθin,
// f = model, m = measurement, both f_r in 1/sr):
//   ngan  r = √w·c·(f − m)                            Ngan, Durand & Matusik 2005 (default)
//   log   r = √w·(ln(1 + c·f) − ln(1 + c·m))          as bbm and Löw et al. 2012 use for peaks
//   cbrt  r = √w·(∛(c·f + ε) − ∛(c·m + ε)), ε = 1e-6  Forés et al. 2012 (ε keeps ∛'s slope finite)
// The cost is ½·Σ ρ(r²) with ρ the identity, or with `robust` Cauchy's ρ(s) = b²·ln(1 + s/b²)
// whose scale b is `robust_scale`, or when that is 0, 1.4826 × the median |r| at the start.
//
// Only std and Eigen types here: Ceres stays inside the brdf_fit library.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/processing/extrapolation.h"

namespace brdf::processing {

enum class FitLoss { kNgan, kLog, kCbrt };
// "ngan", "log", "cbrt"; FitLossFromName throws InvalidArgument listing them.
std::string_view FitLossName(FitLoss loss);
FitLoss FitLossFromName(std::string_view name);

struct FitOptions {
  Model model = Model::kGgx;
  FitLoss loss = FitLoss::kNgan;
  bool robust = false;
  double robust_scale = 0;  // Cauchy scale b in residual units; 0: chosen from the data
  // Samples with θout above this are left out (counted in FitReport::excluded_theta_out).
  // Unset: everything measured.
  std::optional<double> max_theta_out_deg;
  int starts = 2;            // candidates of the sweep refined on all samples (≥ 1)
  int threads = 1;           // Ceres' threads for residuals and Jacobians (≥ 1)
  int max_iterations = 100;  // per refinement
  // A start of the same model instead of the sweep (its values are clamped into range).
  std::optional<Material> start;
};

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
};

struct FitResult {
  // The fitted material; its extra_json holds {"fit": FitReportJson(report)}, so
  // MaterialToJson writes a docs/design.md §9 material file with the report under "fit".
  Material material;
  FitReport report;
};

// Fits options.model to `measurement`. Throws InvalidArgument for bad options and FormatError
// naming the measurement's sample name when no sample is usable.
FitResult FitMaterial(const Measurement& measurement, const FitOptions& options);

// The warning FitReport::warnings carries for a colour shift (FitReport::colour_shift, a
// property of the measurement: every model's fit of it says so) with the measurement's
// FitReport::hue_spread, naming `model`; without a model, the same sentence for several models
// at once, so that a comparison of models can say it once.
std::string ColourShiftWarning(double hue_spread, std::optional<Model> model = std::nullopt);

// The report as a JSON object text (compact).
std::string FitReportJson(const FitReport& report);

// The error `material` has on `measurement` under `options` (loss, exclusions, robust), without
// fitting: the same numbers FitMaterial reports for its result (status kEvaluated). With
// `robust` and robust_scale 0 the scale is chosen at `material` as FitMaterial chooses it at
// its start.
FitReport EvaluateFit(const Measurement& measurement, const Material& material,
                      const FitOptions& options);

// --extrapolate auto (docs/design.md §6): the Bézier p and l whose extrapolated band follows
// the fall-off of `model` (a fit to the measurement) between θb and 90°, by least squares over
// that band: for every slice, φout and θ ∈ (θb, 90°] in 1° steps, f(θb)·((1 − α) + α·p) is
// compared with model(θ), f(θb) taken from the model too, errors in 1/sr summed over channels.
// p is solved in closed form for each l on a 0.01 grid (then clamped to p ≥ 0), the best l
// refined by golden section. θb is the largest θout of the measurement; the φout and θin sets
// are the measurement's.
struct AutoExtrapolationResult {
  ExtrapolationParams params;
  double theta_b_deg = 0;
  double band_rmse = 0;          // RMS error over the band with params, 1/sr
  double band_rmse_clamp = 0;    // the same with p = 1 (clamping), for comparison
  std::optional<FitResult> fit;  // the GGX fit used, when ChooseExtrapolationAuto made it
};
AutoExtrapolationResult FitExtrapolationToModel(const Measurement& measurement,
                                                const Material& model);
// Fits GGX (default options, `threads`) and then FitExtrapolationToModel.
AutoExtrapolationResult ChooseExtrapolationAuto(const Measurement& measurement, int threads = 1);
// The sidecar record of an automatic choice: a JSON object text with the chosen p, l, θb,
// both band errors and the GGX material with its fit report.
std::string AutoExtrapolationJson(const AutoExtrapolationResult& result);

}  // namespace brdf::processing
