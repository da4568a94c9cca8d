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
#include <bit>
#include <cmath>
#include <cstdint>

#include "brdf/core/models.h"

namespace brdf::processing::detail {

// Whether EvaluateFillModel takes its shared-shape path for this material.
inline bool IsOneShapeFillModel(const Material& material) {
  const double* p = material.values.data();
  const Model model = material.model;
  return p[6] == p[7] && p[7] == p[8] &&
         (model == Model::kGgx || model == Model::kWard || model == Model::kLafortune);
}

// The three families at one geometry above the horizon, p = the material's values (shape p[6]).
// GGX with its light-side masking g1_l = models::GgxG1(g.n_dot_l, α²) given: a slice's light is
// one direction, so a row of texels shares it (EvaluateFillModelAt computes it once per value).
inline std::array<double, 3> GgxFill(const double* p, const ShadingGeometry& g, double g1_l) {
  // models::Ggx: kd/π + F·G·D / (4 n·l n·v), F = f0 + (1 − f0)(1 − v·h)⁵.
  std::array<double, 3> out;
  const double a2 = p[6] * p[6];
  const double fresnel_weight = models::Pow5(1.0 - g.v_dot_h);
  const double shadowing = g1_l * models::GgxG1(g.n_dot_v, a2);
  const double d = models::GgxD(g.n_dot_h, a2);
  const double denom = 4.0 * g.n_dot_l * g.n_dot_v;
  for (int c = 0; c < 3; ++c) {
    const double fresnel = p[3 + c] + (1.0 - p[3 + c]) * fresnel_weight;
    out[c] = p[c] * kInvPi + fresnel * shadowing * d / denom;
  }
  return out;
}
inline std::array<double, 3> WardFill(const double* p, const ShadingGeometry& g) {
  // models::Ward: ρd/π + ρs·exp(−tan²θh/α²) / (4π α² √(n·l n·v)).
  std::array<double, 3> out;
  const double cos2 = g.n_dot_h * g.n_dot_h;
  const double tan2 = (1.0 - cos2) / cos2;
  const double a2 = p[6] * p[6];
  const double lobe = std::exp(-tan2 / a2);
  const double denom = 4 * kPi * a2 * std::sqrt(g.n_dot_l * g.n_dot_v);
  for (int c = 0; c < 3; ++c) out[c] = p[c] * kInvPi + p[3 + c] * lobe / denom;
  return out;
}
inline std::array<double, 3> LafortuneFill(const double* p, const ShadingGeometry& g) {
  // models::Lafortune: kd/π + ks (n + 2)/(2π) · max(v·r, 0)ⁿ.
  std::array<double, 3> out;
  const double shape = p[6];
  const double lobe = g.v_dot_r > 0 ? std::pow(g.v_dot_r, shape) : 0.0;
  for (int c = 0; c < 3; ++c)
    out[c] = p[c] * kInvPi + p[3 + c] * (shape + 2.0) * (0.5 * kInvPi) * lobe;
  return out;
}

inline std::array<double, 3> EvaluateFillModel(const Material& material, const ShadingGeometry& g) {
  const double* p = material.values.data();
  if (!IsOneShapeFillModel(material)) return models::EvaluateRgb(material.model, g, p);
  if (!g.AboveHorizon()) return {0.0, 0.0, 0.0};
  switch (material.model) {
    case Model::kGgx:
      return GgxFill(p, g, models::GgxG1(g.n_dot_l, p[6] * p[6]));
    case Model::kWard:
      return WardFill(p, g);
    default:
      return LafortuneFill(p, g);
  }
}

// EvaluateFillModel(material, g[k]) into out[k] for k < n where skip(k) is false (out[k] is left
// as it is where it is true): the fill's grids evaluate a row of texels at a time, and the
// material's checks and the family's branch are made once for the row.
template <class Skip>
void EvaluateFillModelAt(const Material& material, const ShadingGeometry* g, int n,
                         std::array<double, 3>* out, const Skip& skip) {
  const double* p = material.values.data();
  const auto each = [&](const auto& eval) {
    for (int k = 0; k < n; ++k) {
      if (skip(k)) continue;
      out[k] = g[k].AboveHorizon() ? eval(p, g[k]) : std::array<double, 3>{0.0, 0.0, 0.0};
    }
  };
  if (!IsOneShapeFillModel(material)) {
    for (int k = 0; k < n; ++k)
      if (!skip(k)) out[k] = models::EvaluateRgb(material.model, g[k], p);
    return;
  }
  switch (material.model) {
    case Model::kGgx: {
      // GgxG1(n·l) again only when n·l changes (its bits: the same input, the same double).
      const double a2 = p[6] * p[6];
      std::uint64_t l_bits = 0;
      double g1_l = 0;
      bool have = false;
      each([&](const double* q, const ShadingGeometry& at) {
        const std::uint64_t bits = std::bit_cast<std::uint64_t>(at.n_dot_l);
        if (!have || bits != l_bits)
          g1_l = models::GgxG1(at.n_dot_l, a2), l_bits = bits, have = true;
        return GgxFill(q, at, g1_l);
      });
      break;
    }
    case Model::kWard:
      each(WardFill);
      break;
    default:
      each(LafortuneFill);
      break;
  }
}

}  // namespace brdf::processing::detail
