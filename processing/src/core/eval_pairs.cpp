#include "brdf/core/eval_pairs.h"

#include <array>

#include "brdf/core/geometry.h"
#include "brdf/core/lut.h"
#include "brdf/core/lut_brdf.h"

namespace brdf {

void EvalAnglePairsDeg(const BrdfSource& source, std::size_t count, const double* theta_in,
                       const double* phi_in, const double* theta_out, const double* phi_out,
                       double* rgb) {
  if (const auto* lut_brdf = dynamic_cast<const LutBrdf*>(&source)) {
    const Lut& lut = lut_brdf->lut();
    for (std::size_t i = 0; i < count; ++i) {
      const double ti = theta_in[i], to = theta_out[i];
      double* f = rgb + 3 * i;
      if (!(ti >= 0.0 && ti <= 90.0 && to >= 0.0 && to <= 90.0)) {
        f[0] = f[1] = f[2] = 0.0;
        continue;
      }
      // Only φout − φin matters; the LUT stores the light at φin = 0. A light at the normal
      // has no azimuth (LutBrdf::Eval: φout alone).
      const double phi = ti > 0.0 ? WrapDeg360(phi_out[i] - phi_in[i]) : WrapDeg360(phi_out[i]);
      const std::array<float, 3> v = lut.SampleAngles(ti, to, phi);
      f[0] = v[0];
      f[1] = v[1];
      f[2] = v[2];
    }
    return;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const Rgb v = source.Eval(SphericalDirectionDeg(theta_in[i], phi_in[i]),
                              SphericalDirectionDeg(theta_out[i], phi_out[i]));
    rgb[3 * i] = v[0];
    rgb[3 * i + 1] = v[1];
    rgb[3 * i + 2] = v[2];
  }
}

}  // namespace brdf
