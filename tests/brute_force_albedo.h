// A test oracle: the directional albedo E(μ) = ∫ f_r cosθl dω of any BrdfSource for the view
// (θv = acos μ, φ = 0), by the midpoint rule in (cosθl, φl) over the normal frame: a grid of its
// own, unlike the IBL pack's (brdf/core/ibl_pack.h), used by the pack's and the preview's tests.
#pragma once

#include <cmath>

#include "brdf/core/brdf_source.h"

namespace brdf::testing {

inline Rgb BruteForceAlbedo(const BrdfSource& source, double mu, int cos_steps, int phi_steps) {
  const Vec3 v = {std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu};
  Rgb e = {0, 0, 0};
  const double weight = (1.0 / cos_steps) * (2.0 * kPi / phi_steps);
  for (int a = 0; a < cos_steps; ++a) {
    const double z = (a + 0.5) / cos_steps, s = std::sqrt(1.0 - z * z);
    for (int b = 0; b < phi_steps; ++b) {
      const double phi = (b + 0.5) * 2.0 * kPi / phi_steps;
      const Rgb f = source.Eval({s * std::cos(phi), s * std::sin(phi), z}, v);
      for (int c = 0; c < 3; ++c) e[c] += f[c] * z * weight;
    }
  }
  return e;
}

}  // namespace brdf::testing
