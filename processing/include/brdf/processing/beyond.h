// Filling what the instrument cannot measure (docs/design.md §5, "Beyond the measured slices").
//
// A capture measures the light at θin = 0, Δin, …, θL (0–60° for the reference instrument) and
// the view up to θb (75°). ExtendBeyondMeasured turns the measured LUT into one that also
// carries, with the same Δin, slices θL + Δin, … up to max_theta_in_deg (80° by default), and a
// new θout band (θout > θb) in every slice. Every texel the measurement fixed (θout ≤ θb in a
// measured slice) keeps its bits; the rest is filled:
//
//  - θout band of a measured slice θk, texel at (θout, φout):
//      f = f(θk, θb, φout) · M(θk, θout, φout) / M(θk, θb, φout)
//    where f(θk, θb, φout) is what the §6 band with p = 1 holds there (the texel's own value),
//    so the fill joins the measured value at θb.
//  - a new slice θt, texel (θd, φd) with view (θout, φout) = S(θt)·ω_d:
//      θout ≤ θL − 5°: reciprocity, f(θt → θout) = f(θout → θt) read from the measured slices
//                      (their band when θt > θb) at relative azimuth −φout;
//      θout ≥ θL + 5°: the slice below at the same specular-frame texel times
//                      M(θt, θout, φout) / M(θt − Δin, θout', φout') (θout', φout' that texel's
//                      view in the slice below), so a glossy peak keeps its measured shape and
//                      takes the model's change with θin;
//      in between linear in θout, so the two meet without a step.
//  M is the fill model: a docs/design.md §9 `ggx`, `ward` or `lafortune` material (one shape
//  parameter for the three channels) fitted to the measured texels by relative least squares
//  (FitFillModel), the family whose fill validates best (below);
//  kHold uses M ≡ 1 (the measured values carried on unchanged, reciprocity still applied).
//  Ratios are limited to [1/16, 16]; directions at or below the horizon read the model at
//  89.5°. Then, per filled slice and channel, the directional albedo ∫ f cosθout dω is
//  computed over the texels and the filled part scaled down when the total exceeds 1.
//
// Validation (leave the last slice out): the same fill built from slices 0 … K−2 alone (the
// model fitted to those), read at the measured slice θL's texels with θout ≤ θb, against that
// slice. kModel validates each family this way and keeps the best; kAuto also validates kHold
// and uses whichever is better: lower p90 relative error, then lower median. With fewer than
// three slices nothing is validated and kModel (GGX) is used.
//
// Slices inserted between measured ones (subdivisions > 1), at θ between measured θa < θb with
// t = (θ − θa)/(θb − θa), texel (θd, φd): (1 − t)·f(θa)·M(θ)/M(θa) + t·f(θb)·M(θ)/M(θb), each
// M at that slice's own view of the texel (linear at equal (θd, φd) for kHold).
//
// Memory: a LUT of K slices becomes ⌊max_theta_in_deg/Δ⌋ + 1 slices, Δ = Δin/subdivisions (the
// reference instrument, 4 slices = 1,045,456 bytes of RGB9E5: 5 slices, 1,306,820 bytes, with
// subdivisions 1; 9 slices, 2,352,276 bytes, with 2, the toolchain's default).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/core/models.h"

namespace brdf::processing {

enum class BeyondMethod {
  kClamp,  // no extra slice, §6 band as given: the LUT as it was (nearest slice beyond θL)
  kHold,   // extra slices by reciprocity and the held measured values (no model)
  kModel,  // extra slices and band by the fitted model used as a ratio on measured values
  kAuto,   // kHold or kModel, whichever validates better on this capture
};
// "clamp", "hold", "model", "auto".
std::string_view BeyondMethodName(BeyondMethod method);
// Throws InvalidArgument quoting `text` and listing the names.
BeyondMethod ParseBeyondMethod(std::string_view text);

// What the toolchain's commands use unless told otherwise (`--beyond`): kAuto, the method that
// validates best (docs/benchmarks/blindspot.md). Library callers that leave BeyondOptions as it
// is get kClamp, the LUT exactly as BuildLut made it before the fill existed; the commands take
// sources::DefaultResampleOptions().
inline constexpr BeyondMethod kDefaultBeyondMethod = BeyondMethod::kAuto;
inline constexpr int kDefaultBeyondSubdivisions = 2;

struct BeyondOptions {
  BeyondMethod method = BeyondMethod::kClamp;
  double max_theta_in_deg = 80.0;  // extra slices k·Δin ≤ this (in (θL, 90°])
  // The result's θin step is Δin/subdivisions (≥ 1): with 2, slices at odd multiples of Δin/2
  // are inserted between the measured ones (see Densify below) and the extrapolation proceeds
  // in steps of Δin/2. Linear filtering along θin then spans 10° instead of 20°, which is what
  // lets a grazing highlight that grows sixfold from 60° to 80° be followed.
  int subdivisions = 1;

  // Throws InvalidArgument naming the bad option.
  void Validate() const;
};

// The fill model: a docs/design.md §9 material (ggx, ward or lafortune).
struct FillModel {
  Material material;
  double median_relative_error = 0;  // over the texels fitted
  std::size_t texels = 0;            // fitted

  std::array<double, 3> Eval(double theta_in_deg, double theta_out_deg, double phi_out_deg) const;
};

// `family` (kGgx, kWard or kLafortune) fitted to the texels of `lut` with θout ≤ theta_b_deg (a
// strided subset, denser near the specular peak): each is linear in its two reflectances
// (kd, f0 / ρd, ρs / kd, ks) for a fixed shape (α, α, n), so for each shape of a log-spaced
// grid those are solved in [0, 1] per channel by least squares weighted by 1/(f + ε)² (ε = 2 %
// of the mean value), then the shape (one for the three channels) refined by golden section.
// Throws InvalidArgument for an empty LUT.
FillModel FitFillModel(const Lut& lut, double theta_b_deg, Model family = Model::kGgx);

// The record of a fill for a sidecar or manifest: {"method", "requested", "measured_theta_in",
// "extrapolated_theta_in", "subdivisions", "leave_last_slice_out": {...} or null, "model": {...}
// or null, "max_albedo"}.
struct BeyondReport;
std::string BeyondReportJson(const BeyondReport& report);

// Leave-last-slice-out error of one method: relative error |Σrgb(fill) − Σrgb(measured)| /
// max(Σrgb(measured), 10⁻³·max) over the last measured slice's texels with θout ≤ θb.
struct LeaveLastSliceOut {
  double theta_in_deg = 0;  // the slice left out
  double median = 0, p90 = 0;
  std::size_t texels = 0;
};

struct BeyondReport {
  BeyondMethod requested = BeyondMethod::kClamp;
  BeyondMethod used = BeyondMethod::kClamp;  // kClamp, kHold or kModel
  std::vector<double> measured_theta_in_deg;
  std::vector<double> extrapolated_theta_in_deg;  // empty with kClamp
  std::vector<double> inserted_theta_in_deg;      // between measured slices (subdivisions > 1)
  int subdivisions = 1;
  std::optional<FillModel> model;  // kModel
  // Of the method used, and of both candidates (kAuto); absent with fewer than three slices.
  std::optional<LeaveLastSliceOut> validation, validation_hold, validation_model;
  double max_albedo = 0;           // largest directional albedo of a filled slice, after scaling
  int albedo_scaled_channels = 0;  // slice-channels whose filled part was scaled down
};

// The LUT with the blind spots filled as described above. `measured` must have uniform θin
// k·Δin with Δin > 0 (otherwise, and with kClamp, it is returned unchanged and report->used is
// kClamp). `theta_b_deg` is the last measured θout (ResampleReport::theta_b_deg).
Lut ExtendBeyondMeasured(const Lut& measured, double theta_b_deg, const BeyondOptions& options,
                         BeyondReport* report = nullptr);

}  // namespace brdf::processing
