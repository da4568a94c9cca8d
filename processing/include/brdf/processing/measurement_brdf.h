// A captured measurement evaluated as a continuous BRDF without the LUT's 1° texel grid (the
// viewer, comparisons against exported LUTs). `brdf eval` does not use it: it evaluates
// captures through the float LUT (brdf::sources::OpenBrdf), which interpolates between θin in
// the specular frame; this class still interpolates at fixed ω_out (see below).
//
// MeasurementBrdf interpolates the point cloud exactly as BuildLut (resample.h) does: within a
// slice the same regular-grid or scattered interpolation over (θout, φout), the docs/design.md §6
// extrapolation between θb and 90°. Across incidence angles it uses the slice whose θin equals
// the light's polar angle (within 1e-6°), otherwise it interpolates linearly in θin between the
// two neighbouring slices; outside the measured θin range it uses the nearest slice (no
// extrapolation in θin). Unlike BuildLut it accepts any set of distinct θin values.
//
// The material is assumed isotropic: only φout − φin matters. Directions are unit vectors in
// the local frame (z = normal) pointing away from the surface; `wi` towards the light, `wo`
// towards the viewer. Values are f_r in 1/sr, linear RGB, not multiplied by cosθ, and 0 when
// either direction is at or below the horizon (the BrdfSource contract). The object is
// immutable after construction and safe to evaluate from many threads; copies share the data.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/measurement.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/processing/resample.h"

namespace brdf::processing {

class MeasurementBrdf final : public BrdfSource {
 public:
  // Builds the per-slice interpolators (the same validation as BuildLut except the uniform
  // θin requirement: distinct finite θin in [0°, 90°), a valid sample in every slice).
  // `name` defaults to the measurement's sample name. Throws InvalidArgument.
  explicit MeasurementBrdf(const Measurement& measurement, const ExtrapolationParams& params = {},
                           const ResampleOptions& options = {}, std::string name = {});

  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  std::string Name() const override;

  // The same value from angles in degrees, light at (θin, φin = 0), viewer at (θout, φout).
  // θout beyond 90° returns the horizon value (the LUT's edge extension), not 0.
  Rgb EvalAngles(double theta_in_deg, double theta_out_deg, double phi_out_deg) const;

  double theta_b_deg() const;
  std::vector<double> theta_in_deg() const;  // ascending

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  std::string name_;
};

}  // namespace brdf::processing
