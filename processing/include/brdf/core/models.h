// The analytic BRDF models of DESIGN §9, written once.
//
// Each model is a templated per-channel function of the light direction l and view direction
// v (unit vectors in the local frame, both pointing away from the surface). The same code
// serves evaluation, the simulated instrument's virtual samples and Ceres fitting (T = Jet),
// so the three can never disagree. Values are f_r in 1/sr, never multiplied by cosθ; both
// directions must be above the surface (z > 0) or the value is 0.
//
// Parameter layout shared by all models (one value per RGB channel):
//   model        kd          ks          shape
//   lambert      rho         -           -
//   lafortune    kd          ks          n      kd/π + ks·(n+2)/(2π)·max(v·r, 0)^n
//   blinn-phong  kd          ks          n      kd/π + ks·(n+8)/(8π)·max(n·h, 0)^n
//   ggx          kd          f0          alpha  Cook-Torrance/Walter with Smith G, Schlick F
//   ward         rho_d       rho_s       alpha  ρd/π + ρs·exp(−tan²θh/α²)/(4πα²√(cosθi cosθo))
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/geometry.h"

namespace brdf {

using Rgb = std::array<double, 3>;

enum class Model { kLambert, kLafortune, kBlinnPhong, kGgx, kWard };

// "lambert", "lafortune", "blinn-phong", "ggx", "ward".
std::string_view ModelName(Model model);
// Inverse of ModelName; throws InvalidArgument listing the known names.
Model ModelFromName(std::string_view name);

namespace models {

template <class T>
T Lambert(const T& rho) {
  return rho * T(kInvPi);
}

template <class T>
T Lafortune(const Vec3T<T>& l, const Vec3T<T>& v, const T& kd, const T& ks, const T& n) {
  using std::pow;
  const T c = Dot(v, Reflect(l));
  const T lobe = c > T(0) ? pow(c, n) : T(0);
  return kd * T(kInvPi) + ks * (n + T(2)) * T(0.5 * kInvPi) * lobe;
}

template <class T>
T BlinnPhong(const Vec3T<T>& l, const Vec3T<T>& v, const T& kd, const T& ks, const T& n) {
  using std::pow;
  const Vec3T<T> h = Normalize(l + v);
  const T lobe = h.z > T(0) ? pow(h.z, n) : T(0);
  return kd * T(kInvPi) + ks * (n + T(8)) * T(0.125 * kInvPi) * lobe;
}

// Smith masking for one direction with the GGX distribution: G1 = 2 / (1 + √(1 + α² tan²θ)).
template <class T>
T GgxG1(const T& cos_theta, const T& alpha) {
  using std::sqrt;
  const T cos2 = cos_theta * cos_theta;
  const T tan2 = (T(1) - cos2) / cos2;
  return T(2) / (T(1) + sqrt(T(1) + alpha * alpha * tan2));
}

// GGX normal distribution. The DESIGN form α² / (π cos⁴θh (α² + tan²θh)²) is rewritten as
// α² / (π (cos²θh (α² − 1) + 1)²), which is the same expression without the tan² blow-up
// at grazing half vectors.
template <class T>
T GgxD(const T& cos_h, const T& alpha) {
  const T a2 = alpha * alpha;
  const T denom = cos_h * cos_h * (a2 - T(1)) + T(1);
  return a2 / (T(kPi) * denom * denom);
}

template <class T>
T Ggx(const Vec3T<T>& l, const Vec3T<T>& v, const T& kd, const T& f0, const T& alpha) {
  const Vec3T<T> h = Normalize(l + v);
  const T vh = Dot(v, h);
  const T one_minus = T(1) - vh;
  const T m2 = one_minus * one_minus;
  const T fresnel = f0 + (T(1) - f0) * (m2 * m2 * one_minus);
  const T g = GgxG1(l.z, alpha) * GgxG1(v.z, alpha);
  const T d = GgxD(h.z, alpha);
  return kd * T(kInvPi) + fresnel * g * d / (T(4) * l.z * v.z);
}

template <class T>
T Ward(const Vec3T<T>& l, const Vec3T<T>& v, const T& rho_d, const T& rho_s, const T& alpha) {
  using std::exp;
  using std::sqrt;
  const Vec3T<T> h = Normalize(l + v);
  const T cos2 = h.z * h.z;
  const T tan2 = (T(1) - cos2) / cos2;
  const T a2 = alpha * alpha;
  return rho_d * T(kInvPi) + rho_s * exp(-tan2 / a2) / (T(4 * kPi) * a2 * sqrt(l.z * v.z));
}

// One channel of any model; 0 when l or v is at or below the horizon.
template <class T>
T Evaluate(Model model, const Vec3T<T>& l, const Vec3T<T>& v, const T& kd, const T& ks,
           const T& shape) {
  if (!(l.z > T(0)) || !(v.z > T(0))) return T(0);
  switch (model) {
    case Model::kLambert:
      return Lambert(kd);
    case Model::kLafortune:
      return Lafortune(l, v, kd, ks, shape);
    case Model::kBlinnPhong:
      return BlinnPhong(l, v, kd, ks, shape);
    case Model::kGgx:
      return Ggx(l, v, kd, ks, shape);
    case Model::kWard:
      return Ward(l, v, kd, ks, shape);
  }
  return T(0);
}

}  // namespace models

// An analytic material: a model and its RGB parameters, in the shared layout above.
struct Material {
  Model model = Model::kLambert;
  Rgb kd{};     // lambert rho, lafortune/blinn-phong/ggx kd, ward rho_d
  Rgb ks{};     // lafortune/blinn-phong ks, ggx f0, ward rho_s
  Rgb shape{};  // lafortune/blinn-phong n, ggx/ward alpha
  std::string name;
  std::string description;
  // Members of the JSON object this material was read from that are not model parameters
  // ("fit", "source", ...), kept verbatim as a JSON object text so a rewrite preserves them.
  std::string extra_json = "{}";

  Rgb Evaluate(const Vec3& l, const Vec3& v) const {
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = models::Evaluate(model, l, v, kd[c], ks[c], shape[c]);
    return out;
  }
};

// Parses the material file form of DESIGN §9. `file` only names the source in error messages.
// Throws FormatError naming the member and the expected and found values.
Material ParseMaterialJson(std::string_view json_text, const std::string& file = "<material>");
Material LoadMaterialFile(const std::string& path);
// The canonical JSON form (2-space indent), parameter names as DESIGN §9 spells them.
std::string MaterialToJson(const Material& material);

// Human-readable reasons the parameters are not physically plausible (negative values,
// kd + ks > 1, f0 > 1, alpha ≤ 0, ...). Empty when the material conserves energy.
std::vector<std::string> PhysicalProblems(const Material& material);

}  // namespace brdf
