// Resampling a measurement point cloud into the exported LUT of docs/design.md §5.
//
// BuildLut turns a Measurement (one slice of samples per incidence angle θin) into K
// equirectangular slices of 361 × 181 texels in the specular frame of each θin. Texel (i, j)
// of slice k holds f_r (1/sr, linear RGB, not multiplied by cosθ) at exactly
// (θd, φd) = (j·1°, i·1°); the outgoing direction is ω_out = S(θin,k)·ω_d (SpecularFrame in
// brdf/core/geometry.h), with the light at (θin,k, φin = 0). Per texel:
//   θout ≤ θb        interpolated from the slice's samples at (θout, φout);
//   θb < θout ≤ 90°  docs/design.md §6 extrapolation of the interpolated value at (θb, φout);
//   θout > 90°       the value at θout = 90° with the same φout (edge extension); at the
//                    nadir, where every φout meets, the mean of those values over φout.
// θb is the largest θout among the valid samples of the whole measurement. Column 360 is a
// copy of column 0, so the seam filters without wrap addressing.
//
// Interpolation within a slice (see docs/resampling.md for the full account):
//  - Regular-grid fast path. When the valid samples sit on a lattice θout = j·Δθ (starting at
//    the pole), φout = φ0 + i·Δφ with Δφ = 360°/Nφ (full circle), values are bilinear in
//    (θout, φout) with φ wrapping across the seam. All samples at the pole θout = 0 are one
//    direction: they are averaged into a single pole value, so the surface has no pole
//    artefact. Lattice nodes with no valid sample (a blind spot, kFlagInvalid samples) are
//    filled by the scattered method below before interpolation, as long as at least half of
//    the nodes are measured.
//  - Scattered path, for anything else (random directions, irregular steps, large gaps): a
//    moving-least-squares fit on the unit sphere. The k nearest valid samples (chord distance,
//    found through a uniform 3D cell grid) are weighted with a Wendland C2 kernel whose radius
//    is the k-th neighbour's distance, a linear function is fitted in the tangent plane of the
//    query direction, and the result is limited to the range of the neighbours' values (no
//    overshoot, never negative for non-negative data). The radius adapts to the local density,
//    so gaps are filled from whichever samples surround them and no texel is left empty. Being
//    built on 3D directions, it has no seam and no pole.
// Samples flagged kFlagInvalid are ignored entirely (their angles and values may be garbage).
// Saturated, below-noise-floor and interpolated samples are used as they are.
//
// Slices with φin ≠ 0 are rotated to φin = 0 (isotropic materials: φout − φin is what counts).
// A negative θout is read as the mirrored direction (|θout|, φout + 180°), as in-plane
// goniometers report it.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/core/measurement.h"
#include "brdf/processing/beyond.h"
#include "brdf/processing/extrapolation.h"

namespace brdf::processing {

enum class InterpolationMethod {
  kRegularGrid,  // bilinear on the detected (θout, φout) lattice
  kScattered,    // moving least squares on the sphere
};
// "regular-grid", "scattered".
std::string_view InterpolationMethodName(InterpolationMethod method);

struct ResampleOptions {
  // false forces the scattered method on every slice (to compare methods, or for tests).
  bool allow_regular_grid = true;
  // true spreads texel rows over TBB worker threads (respecting any enclosing task_arena);
  // false computes everything on the calling thread.
  bool parallel = true;
  // k of the scattered method: how many nearest samples each fit uses, in [4, 64].
  int neighbours = 16;
  // false accepts any set of distinct θin in [0°, 90°) (evaluation of imported tables such as a
  // Zemax file measured at 10°, 30°, 50°): LUT slice k is then the k-th smallest measured θin,
  // and Lut::SampleAngles interpolates between neighbouring slices the same way. Such a LUT is
  // for evaluation only; the exported textures need θin,k = k·Δin.
  bool require_uniform_theta_in = true;
  // What fills the directions the instrument did not measure (light beyond the last slice,
  // view beyond θb): ExtendBeyondMeasured (beyond.h) after resampling, so the LUT carries
  // extra slices k·Δin up to beyond.max_theta_in_deg. kClamp builds the LUT as before (the
  // measured slices only, §6 band). Not applied to a θin list that is not k·Δin.
  BeyondOptions beyond;
  // The rule of values no surface has (kMaxFrCosPerSr below, docs/design.md §4) is for
  // measured values (captures, tables). false for a virtual capture of an evaluable file (a
  // material, RGL or MERL file, an exported LUT): its values are the model's own, exactly, and a
  // lobe sharper than the LUT's 1° texels may exceed the limit; the textures then clip it, with
  // the warning of sources::ClipNote. Finite values and angles are required either way.
  bool check_measured_values = true;

  // Throws InvalidArgument naming the bad option.
  void Validate() const;
};

// What BuildLut did to one slice.
struct SliceResampleReport {
  double theta_in_deg = 0;
  InterpolationMethod method = InterpolationMethod::kScattered;
  std::size_t valid_samples = 0;    // used
  std::size_t invalid_samples = 0;  // skipped (kFlagInvalid)
  double max_theta_out_deg = 0;     // largest θout among this slice's valid samples
  // Regular grid only: lattice steps, and nodes that had no valid sample and were filled by
  // the scattered method (a blind spot, invalid samples).
  double grid_step_theta_deg = 0, grid_step_phi_deg = 0;
  std::size_t filled_nodes = 0;
};

struct ResampleReport {
  double theta_b_deg = 0;   // last measured polar angle, start of the extrapolated band
  double delta_in_deg = 0;  // Δin (0 for a single slice)
  ExtrapolationParams extrapolation;
  std::vector<SliceResampleReport> slices;  // ascending θin, one per measured slice
  BeyondReport beyond;                      // what filled the blind spots
};

// Values no surface has (docs/design.md §4, "Values no surface has"): a sample not flagged
// invalid is refused (kBadSamples, like a NaN) when a channel's f_r·max(cosθout, cos 89°) exceeds
// kMaxFrCosPerSr, or when f_r is negative beyond noise around zero: below −max(allowance, 5σ),
// the allowance being kNegativeFractionOfPeak of the slice's largest plausible value, at least
// kNegativeFloorPerSr (σ the sample's own, when recorded).
inline constexpr double kMaxFrCosPerSr = 1e5;
inline constexpr double kMinBoundCos = 0.017452406437283512;  // cos 89°
inline constexpr double kNegativeFloorPerSr = 1e-3;
inline constexpr double kNegativeFractionOfPeak = 0.01;
inline constexpr double kNegativeSigmas = 5.0;

// One reason BuildLut refuses a measurement (or, for kDegenerateRange, would build a LUT with no
// angular information).
struct LutInputProblem {
  enum class Kind {
    kNoSlices,
    kThetaInOutOfRange,  // θin not in [0°, 90°) or φin not finite
    kDuplicateThetaIn,
    kThetaInNotUniform,  // not k·Δin from 0° (only when options.require_uniform_theta_in)
    kBadSamples,         // samples not flagged invalid with unusable angles or values
    kNoValidSample,      // a slice whose every sample is flagged invalid
    kDegenerateRange,    // every valid sample at θout = 0: nothing to interpolate over
  };
  Kind kind = Kind::kNoSlices;
  int slice = -1;                // index into measurement.slices; -1 for the whole
  double theta_in_deg = 0;       // of `slice`
  std::size_t sample_count = 0;  // kBadSamples: how many samples of the slice
  std::size_t first_sample = 0;  // kBadSamples: index of the first one
  std::string message;  // one sentence without the file name: "slice 2 (θin = 40°): 3 samples
                        // with red value not a finite number (first: sample 17)"
};

// Every problem of `measurement` that BuildLut(measurement, params, options) refuses, in slice
// order, bad samples summarised per slice and defect. BuildLut itself throws the first of these,
// so `brdf info`, `convert` and `eval` can never disagree about a file. Also reports
// kDegenerateRange, which BuildLut refuses too: a LUT extrapolated from the pole alone is not a
// measurement.
std::vector<LutInputProblem> FindLutInputProblems(const Measurement& measurement,
                                                  const ResampleOptions& options = {});
// The θin-list part of FindLutInputProblems alone (kThetaInOutOfRange, kDuplicateThetaIn,
// kThetaInNotUniform; kNoSlices for no slice), without the samples' checks: for a caller that
// has checked the samples already with other θin rules (sources::AssessCapture asks whether the
// slices it accepted are k·Δin).
std::vector<LutInputProblem> FindThetaInProblems(const Measurement& measurement,
                                                 const ResampleOptions& options = {});

// Builds the LUT of docs/design.md §5 from `measurement` with the §6 extrapolation `params`.
// Requirements (InvalidArgument otherwise, naming the sample and what is wrong):
//  - at least one slice; the θin values, in any order, are k·Δin for k = 0…K−1 (uniform,
//    starting at 0°, no duplicates; within 1e-3°); LUT slice k is θin = k·Δin exactly;
//  - every slice has at least one valid sample; valid samples have finite values a surface can
//    have (kMaxFrCosPerSr above), finite φout and θout ∈ [−90°, 90°]; some valid sample has
//    θout > 0.
// (FindLutInputProblems lists every violation; BuildLut throws InvalidArgument with the first.)
// `report`, when not null, receives θb, the methods used and sample counts.
Lut BuildLut(const Measurement& measurement, const ExtrapolationParams& params = {},
             const ResampleOptions& options = {}, ResampleReport* report = nullptr);

}  // namespace brdf::processing
