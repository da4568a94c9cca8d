// The reference instrument's geometry and the one noise-free virtual capture of the toolchain.
//
// The reference instrument (docs/design.md §1, MiniDiff V2 class) lights the sample at
// θin = 0°, 20°, 40°, 60° (φin = 0: the light in the +x half of the xz-plane) and reads the
// detector at θout = 0°…75° and φout = 0°…359°, both in 1° steps. Every place that needs those
// numbers (the simulator's reference model, `brdf capture` defaults, `brdf import` of RGL and
// MERL files, `brdf convert` of material files) takes them from ReferenceGeometry().
//
// CaptureNoiseFree "measures" any BrdfSource on such a geometry without an instrument: each
// sample is the source's f_r (1/sr, linear RGB, not multiplied by cosθ) for light at
// (θin, φin = 0) and viewer at (θout, φout). An analytic material or a measured database then
// goes through exactly the path of a real capture (resampling, the §6 extrapolation beyond the
// last measured θout).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/measurement.h"

namespace brdf {

struct CaptureGeometry {
  std::vector<double> theta_in_deg = {0, 20, 40, 60};  // light polar angles, φin = 0
  double theta_out_max_deg = 75;                       // inclusive
  double theta_out_step_deg = 1;                       // θout = 0, step, 2·step, … ≤ max
  double phi_out_step_deg = 1;                         // φout = 0, step, … < 360

  // The θout and φout values of one slice, in capture order (θout rows, φout within a row).
  std::vector<double> ThetaOutDeg() const;
  std::vector<double> PhiOutDeg() const;
  // "theta_in 0, 20, 40, 60; theta_out 0-75; phi_out 0-359; 1 deg steps" (for metadata).
  std::string Describe() const;
  // Throws InvalidArgument naming the field: θin in [0, 90), no duplicates, at least one;
  // θout max in [0, 90); steps in [0.01, 90] (θout) and [0.01, 360] (φout).
  void Validate() const;
};

// The reference instrument's geometry (the default-constructed CaptureGeometry).
const CaptureGeometry& ReferenceGeometry();

// A noise-free capture of `source` on `geometry`: one complete slice per θin, samples in the
// order of ThetaOutDeg() × PhiOutDeg(), no σ, no flags except kFlagInvalid where the source
// holds no measured value (BrdfSource::HasValue: a MERL bin marked unmeasured). The metadata
// names the source (sample_name = source.Name()), records the geometry ("capture" extra) and
// the planned θin list ("theta_in_deg" extra, as `brdf capture` writes it). Throws
// InvalidArgument for an invalid geometry.
Measurement CaptureNoiseFree(const BrdfSource& source,
                             const CaptureGeometry& geometry = ReferenceGeometry());

// The capture plan recorded in a capture's metadata: the extra "theta_in_deg" holds the planned
// θin list ("0,20,40,60", written before the first slice), so an interrupted capture missing
// slices can be told from a complete one.
inline constexpr const char* kPlannedThetaInKey = "theta_in_deg";
// "0,20,40,60": shortest round-trip-safe decimal per angle ("%g" for whole degrees).
std::string EncodeThetaInList(const std::vector<double>& theta_in_deg);
// The planned list of `metadata`, nullopt when none is recorded. Accepts commas and/or blanks
// between the numbers. Throws FormatError naming `file` and the metadata field when the text is
// not a list of angles in [0°, 90°).
std::optional<std::vector<double>> PlannedThetaInDeg(const Metadata& metadata,
                                                     const std::string& file);

}  // namespace brdf
