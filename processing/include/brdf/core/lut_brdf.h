// A LUT of docs/design.md §5 as a BrdfSource: the one evaluation path of measured data. A
// capture or table (resampled into the float LUT by processing::MeasurementAsBrdf, the path of
// `brdf convert`) and an exported texture (decoded RGB9E5 texels) are both evaluated here, so
// `brdf eval`, `brdf preview`, `brdf-view` and the fitter's comparisons agree about a file.
#pragma once

#include <string>
#include <utility>

#include "brdf/core/brdf_source.h"
#include "brdf/core/lut.h"

namespace brdf {

// Eval is Lut::SampleAngles: reciprocity beyond the measured θin range, then the texture lookup
// a GPU makes (trilinear in the specular frame, clamp-to-edge). The light's azimuth is folded
// into φout (isotropic LUT, light stored at φin = 0). `wi` points to the light, `wo` to the
// viewer (unit vectors, z = normal); f_r in 1/sr, not multiplied by cosθ; zero when either
// direction is at or below the horizon (the BrdfSource contract). Immutable, thread-safe.
class LutBrdf final : public BrdfSource {
 public:
  LutBrdf(Lut lut, std::string name) : lut_(std::move(lut)), name_(std::move(name)) {}
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  std::string Name() const override { return name_; }
  const Lut& lut() const { return lut_; }

 private:
  Lut lut_;
  std::string name_;
};

}  // namespace brdf
