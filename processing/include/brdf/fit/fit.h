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

#include "brdf/core/fitted_material.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/processing/extrapolation.h"

namespace brdf::processing {

// The report types live in brdf::core (brdf/core/fitted_material.h), so a fit can travel to
// the libraries above without Ceres or this header.
using brdf::FitLoss;
using brdf::FitLossFromName;
using brdf::FitLossName;
using brdf::FitReport;
using brdf::FitReportJson;
using brdf::FitStatus;
using brdf::FitStatusName;
using brdf::SliceFitError;

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

// Under-determined fits (docs/design.md §9): a sample gives one number per colour channel, and
// a channel's values depend on ParametersPerChannel(model) parameters (its share of the RGB
// ones plus every scalar one). With fewer than kSamplesPerParameter times that many usable
// samples the data does not determine the parameters (with as many numbers as unknowns a fit
// passes through them exactly, whatever the model): FitMaterial still returns the best fit but
// marks it representable = false and says "N usable samples for P parameters" in its warnings,
// and ChooseExtrapolationAuto does not use it.
inline constexpr int kSamplesPerParameter = 2;
int ParametersPerChannel(Model model);
int ParameterCount(Model model);  // every scalar, an RGB parameter counted three times
bool Underdetermined(std::size_t samples_used, Model model);
// The warning above, or an empty string when the fit is determined.
std::string UnderdeterminedWarning(std::size_t samples_used, Model model);

// The fitted material (named after the measurement's sample) and its report.
using FitResult = FittedMaterial;

// Fits options.model to `measurement`. Throws InvalidArgument for bad options and FormatError
// naming the measurement's sample name when no sample is usable.
FitResult FitMaterial(const Measurement& measurement, const FitOptions& options);

// The warning FitReport::warnings carries for a colour shift (FitReport::colour_shift, a
// property of the measurement: every model's fit of it says so) with the measurement's
// FitReport::hue_spread, naming `model`; without a model, the same sentence for several models
// at once, so that a comparison of models can say it once.
std::string ColourShiftWarning(double hue_spread, std::optional<Model> model = std::nullopt);

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
  // ChooseExtrapolationAuto: empty, or why the fit was not used (an under-determined fit); the
  // parameters are then the defaults p = 1, l = 0.5 and band_rmse equals band_rmse_clamp.
  std::string not_used;
};
AutoExtrapolationResult FitExtrapolationToModel(const Measurement& measurement,
                                                const Material& model);
// Fits GGX (default options, `threads`) and then FitExtrapolationToModel.
AutoExtrapolationResult ChooseExtrapolationAuto(const Measurement& measurement, int threads = 1);
// The sidecar record of an automatic choice: a JSON object text with the chosen p, l, θb,
// both band errors and the GGX material with its fit report.
std::string AutoExtrapolationJson(const AutoExtrapolationResult& result);

}  // namespace brdf::processing
