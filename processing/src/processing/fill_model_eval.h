// The blind-spot fill's model evaluation (beyond.cpp): models::EvaluateRgb of a fill model, whose
// three channels share one shape parameter (FitFillModel's ggx, ward and lafortune materials).
//
// The fill evaluates its model at every texel of every slice it touches, several million times
// per capture, and models::EvaluateRgb computes each channel on its own: GGX's distribution and
// shadowing, Ward's exponential and Lafortune's power three times for one shape. Here the terms
// that depend on the shape and geometry alone are computed once, and each channel then does the
// same operations in the same order as models::Ggx, Ward and Lafortune (brdf/core/models.h), so
// the results are the same doubles (tests/processing/fill_model_eval_test.cpp compares them bit
// for bit). Any other material goes to models::EvaluateRgb.
#pragma once

#include <array>
#include <cmath>

#include "brdf/core/models.h"

namespace brdf::processing::detail {

inline std::array<double, 3> EvaluateFillModel(const Material& material, const ShadingGeometry& g) {
  const double* p = material.values.data();
  const bool one_shape = p[6] == p[7] && p[7] == p[8];
  const Model model = material.model;
  if (!one_shape || !(model == Model::kGgx || model == Model::kWard || model == Model::kLafortune))
    return models::EvaluateRgb(model, g, p);
  std::array<double, 3> out{0.0, 0.0, 0.0};
  if (!g.AboveHorizon()) return out;
  const double shape = p[6];
  switch (model) {
    case Model::kGgx: {
      // models::Ggx: kd/π + F·G·D / (4 n·l n·v), F = f0 + (1 − f0)(1 − v·h)⁵.
      const double a2 = shape * shape;
      const double fresnel_weight = models::Pow5(1.0 - g.v_dot_h);
      const double shadowing = models::GgxG1(g.n_dot_l, a2) * models::GgxG1(g.n_dot_v, a2);
      const double d = models::GgxD(g.n_dot_h, a2);
      const double denom = 4.0 * g.n_dot_l * g.n_dot_v;
      for (int c = 0; c < 3; ++c) {
        const double fresnel = p[3 + c] + (1.0 - p[3 + c]) * fresnel_weight;
        out[c] = p[c] * kInvPi + fresnel * shadowing * d / denom;
      }
      break;
    }
    case Model::kWard: {
      // models::Ward: ρd/π + ρs·exp(−tan²θh/α²) / (4π α² √(n·l n·v)).
      const double cos2 = g.n_dot_h * g.n_dot_h;
      const double tan2 = (1.0 - cos2) / cos2;
      const double a2 = shape * shape;
      const double lobe = std::exp(-tan2 / a2);
      const double denom = 4 * kPi * a2 * std::sqrt(g.n_dot_l * g.n_dot_v);
      for (int c = 0; c < 3; ++c) out[c] = p[c] * kInvPi + p[3 + c] * lobe / denom;
      break;
    }
    default: {
      // models::Lafortune: kd/π + ks (n + 2)/(2π) · max(v·r, 0)ⁿ.
      const double lobe = g.v_dot_r > 0 ? std::pow(g.v_dot_r, shape) : 0.0;
      for (int c = 0; c < 3; ++c)
        out[c] = p[c] * kInvPi + p[3 + c] * (shape + 2.0) * (0.5 * kInvPi) * lobe;
      break;
    }
  }
  return out;
}

}  // namespace brdf::processing::detail
