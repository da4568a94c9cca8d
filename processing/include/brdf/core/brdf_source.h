// Anything that can be evaluated as a BRDF: an analytic material, a measured database file
// (RGL, MERL), an interpolated capture. The simulated scatterometer captures any BrdfSource,
// and `brdf eval` prints one. Files are opened as BrdfSources by brdf::sources::OpenBrdf
// (brdf/sources/open.h), by content.
#pragma once

#include <memory>
#include <string>

#include "brdf/core/geometry.h"
#include "brdf/core/models.h"

namespace brdf {

class BrdfSource {
 public:
  virtual ~BrdfSource() = default;

  // f_r in 1/sr, linear Rec.709 RGB, not multiplied by cosθ. `wi` points to the light, `wo`
  // to the viewer, both unit vectors in the local frame (z = normal). Zero below the horizon.
  virtual Rgb Eval(const Vec3& wi, const Vec3& wo) const = 0;

  // Short name for metadata and messages ("gold", "paper_white_rgb.bsdf").
  virtual std::string Name() const = 0;

  // False where the source holds no value for the pair (a MERL bin marked not measured), so a
  // virtual capture can flag the sample invalid instead of recording a made-up black.
  virtual bool HasValue(const Vec3& wi, const Vec3& wo) const {
    (void)wi;
    (void)wo;
    return true;
  }

  // A faster approximation of this source for integrators that evaluate it millions of times
  // (the preview's hierarchical quadrature), or null when the source has none (then use the
  // source itself). The overriding class documents what is approximated and the measured
  // error. Building one may cost up to ~0.1 s (an RGL table), so ask once per render.
  virtual std::unique_ptr<BrdfSource> QuadratureApproximation() const { return nullptr; }
};

class AnalyticBrdf final : public BrdfSource {
 public:
  explicit AnalyticBrdf(Material material) : material_(std::move(material)) {}
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override { return material_.Evaluate(wi, wo); }
  std::string Name() const override { return material_.name; }
  const Material& material() const { return material_; }

 private:
  Material material_;
};

}  // namespace brdf
