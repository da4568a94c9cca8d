// The probe lighting of an engine on the CPU, for `brdf preview --ibl engine`: the map's
// irradiance by order-2 spherical harmonics and its GGX-prefiltered radiance by filtered
// importance sampling of a mip pyramid, the two lookups the split sum of brdf/core/ibl_pack.h
// multiplies with the pack's diffuse and specular parts. Private to brdf_preview.
#pragma once

#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/core/models.h"
#include "brdf/preview/preview.h"

namespace brdf::preview::detail {

class SplitSumLighting {
 public:
  // Number of GGX samples per prefiltered lookup (a fixed Hammersley set).
  static constexpr int kSamples = 256;

  explicit SplitSumLighting(const EnvironmentMap& map);

  // Ē(n) = (1/π)∫ L(ω) max(n·ω, 0) dω from the map's SH projection up to ℓ = 2 (Ramamoorthi &
  // Hanrahan 2001: Â_0 = π, Â_1 = 2π/3, Â_2 = π/4), as Unity's and three.js's ambient SH do.
  // `n` in the map's frame. Exactly L under a uniform map of radiance L.
  Rgb Irradiance(const Vec3& n) const;
  // P(α, R) = ∫ L(l) K_α(R·l) dω with the kernel of brdf/core/ibl_pack.h, estimated as the
  // engines' probe filters do (Karis 2013, with Křivánek & Colbert 2008's filtered importance
  // sampling): kSamples half vectors h drawn from D_α(h)·cosθh about R (Hammersley points),
  // l = 2(R·h)h − R, each weighted by max(R·l, 0), each read from the mip level whose texel
  // solid angle matches the sample's share 1/(kSamples·pdf(l)), +1 level, bilinear within
  // levels and linear between them; the weighted mean. `r` in the map's frame.
  Rgb Prefiltered(double alpha, const Vec3& r) const;

 private:
  struct Level {
    int width = 0, height = 0;
    std::vector<float> rgb;
  };
  Rgb Bilinear(const Level& level, double phi, double theta) const;
  Rgb Lookup(const Vec3& w, double lod) const;

  std::vector<Level> levels_;
  double texel_solid_angle_ = 0.0;  // level 0, the map's mean
  double sh_[9][3] = {};
};

}  // namespace brdf::preview::detail
