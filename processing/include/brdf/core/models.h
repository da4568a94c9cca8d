// The analytic BRDF models of docs/design.md §9 and the engines' own shading models, each
// written once.
//
// Every model is a templated function of the shading geometry (the cosines between the light
// direction l, the view direction v, the normal n = z and the half vector h; plain doubles) and
// of the model's parameters (type T: double for evaluation and the simulator, ceres::Jet for
// the fitter's automatic derivatives), so evaluation, the simulated instrument and Ceres can
// never disagree. Values are f_r in 1/sr, linear RGB, never multiplied by cosθ; both
// directions must be above the surface (z > 0) or the value is 0.
//
// Parameters. A model has a fixed list of named parameters (ParameterInfo below), each either
// RGB (three values) or a scalar; a Material stores them flat in that order ("values").
//   model                  parameters                          f_r
//   lambert                rho                                 ρ/π
//   lafortune              kd, ks, n                           kd/π + ks·(n+2)/(2π)·max(v·r, 0)^n
//   blinn-phong            kd, ks, n                           kd/π + ks·(n+8)/(8π)·max(n·h, 0)^n
//   ggx                    kd, f0, alpha                       Cook-Torrance/Walter, Smith G,
//   Schlick F ward                   rho_d, rho_s, alpha                 ρd/π +
//   ρs·exp(−tan²θh/α²)/(4πα²√(cosθi cosθo)) unreal-defaultlit      base_color, metallic, specular,
//   roughness   (UE DefaultLit, below) unity-hdrp-lit         base_color, metallic, smoothness
//   (HDRP Lit, metallic) unity-hdrp-lit-specular base_color, specular_color, smoothness     (HDRP
//   Lit, specular colour) unity-urp-lit          base_color, metallic, smoothness            (URP
//   Lit, metallic) unity-urp-lit-specular base_color, specular_color, smoothness      (URP Lit,
//   specular setup)
// In the legacy models (lambert … ward) every RGB channel is independent: kd, ks and the lobe
// shape (n or alpha) may differ per channel. The engine models have one roughness for all
// channels, as the engines do.
//
// Ranges. Every parameter has a closed range (ParameterInfo::min/max) that a material file must
// respect (ParseMaterialJson refuses anything else, so α = 1e300 or a negative f0 never
// reaches the formulas) and that the fitter uses as bounds. For the engine models the ranges
// are the engine UI's, so a fitted value can be typed in as it is.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/geometry.h"

namespace brdf {

using Rgb = std::array<double, 3>;

enum class Model {
  kLambert,
  kLafortune,
  kBlinnPhong,
  kGgx,
  kWard,
  kUnrealDefaultLit,
  kUnityHdrpLit,
  kUnityHdrpLitSpecular,
  kUnityUrpLit,
  kUnityUrpLitSpecular,
};

// "lambert", "lafortune", "blinn-phong", "ggx", "ward", "unreal-defaultlit", "unity-hdrp-lit",
// "unity-hdrp-lit-specular", "unity-urp-lit", "unity-urp-lit-specular".
std::string_view ModelName(Model model);
// Inverse of ModelName; throws InvalidArgument listing the known names.
Model ModelFromName(std::string_view name);
// Every model, in the order above.
std::span<const Model> AllModels();

// The most values any model has (lafortune, blinn-phong, ggx, ward: 3 × RGB).
inline constexpr int kMaxModelValues = 9;

// One named parameter of a model.
struct ParameterInfo {
  std::string_view name;    // material-file member ("kd", "base_color")
  bool rgb = true;          // three values (red, green, blue) or one
  double min = 0, max = 1;  // closed valid range (also the fitter's bounds)
  double start = 0.5;       // the fitter's default start
  // The fitter searches this parameter in log space (exponents and widths spanning decades).
  bool log_scale = false;
  // What the engine's material editor calls it ("Base Color"); empty for non-engine models.
  std::string_view engine_label;
  int offset = 0;  // index of the first value in Material::values
  int Count() const { return rgb ? 3 : 1; }
};

struct ModelInfo {
  Model model;
  std::string_view name;
  std::string_view engine;  // "Unreal Engine", "Unity HDRP", "Unity URP"; empty otherwise
  std::vector<ParameterInfo> parameters;
  int value_count = 0;  // Σ parameters' Count()
  // Indices into `parameters` of the lobe's shape (n, alpha, roughness, smoothness) and of the
  // diffuse colour; -1 when absent. The fitter sweeps the shape and reports the rest.
  int shape_parameter = -1;
};
const ModelInfo& DescribeModel(Model model);

// The shading geometry a model needs, all cosines of unit vectors (double: the directions are
// data, never fitted). h = normalize(l + v), r = (−l.x, −l.y, l.z) the mirror of l.
struct ShadingGeometry {
  double n_dot_l = 0, n_dot_v = 0, n_dot_h = 0, v_dot_h = 0, l_dot_v = 0, v_dot_r = 0;

  // `l` points to the light, `v` to the viewer, both unit vectors away from the surface.
  static ShadingGeometry Of(const Vec3& l, const Vec3& v) {
    ShadingGeometry g;
    g.n_dot_l = l.z;
    g.n_dot_v = v.z;
    g.l_dot_v = Dot(l, v);
    g.v_dot_r = Dot(v, Reflect(l));
    const Vec3 sum = l + v;
    const double len = std::sqrt(Dot(sum, sum));
    if (len > 0) {
      g.n_dot_h = sum.z / len;
      g.v_dot_h = Dot(v, sum) / len;
    }
    return g;
  }
  bool AboveHorizon() const { return n_dot_l > 0 && n_dot_v > 0; }
};

namespace models {

template <class T>
T Pow5(const T& x) {
  const T x2 = x * x;
  return x2 * x2 * x;
}

// GGX (Trowbridge-Reitz) normal distribution with α² = a2. The design form
// α² / (π cos⁴θh (α² + tan²θh)²) written as α² / (π (cos²θh (α² − 1) + 1)²): the same function
// without the tan² blow-up at grazing half vectors.
template <class T>
T GgxD(double cos_h, const T& a2) {
  const T denom = cos_h * cos_h * (a2 - T(1)) + T(1);
  return a2 / (T(kPi) * denom * denom);
}

// Separable Smith masking for one direction with the GGX distribution:
// G1 = 2 / (1 + √(1 + α² tan²θ)).
template <class T>
T GgxG1(double cos_theta, const T& a2) {
  using std::sqrt;
  const double cos2 = cos_theta * cos_theta;
  const double tan2 = (1.0 - cos2) / cos2;
  return T(2) / (T(1) + sqrt(T(1) + a2 * tan2));
}

template <class T>
T Lambert(const T& rho) {
  return rho * T(kInvPi);
}

template <class T>
T Lafortune(const ShadingGeometry& g, const T& kd, const T& ks, const T& n) {
  using std::pow;
  const T lobe = g.v_dot_r > 0 ? T(pow(g.v_dot_r, n)) : T(0);
  return kd * T(kInvPi) + ks * (n + T(2)) * T(0.5 * kInvPi) * lobe;
}

template <class T>
T BlinnPhong(const ShadingGeometry& g, const T& kd, const T& ks, const T& n) {
  using std::pow;
  const T lobe = g.n_dot_h > 0 ? T(pow(g.n_dot_h, n)) : T(0);
  return kd * T(kInvPi) + ks * (n + T(8)) * T(0.125 * kInvPi) * lobe;
}

template <class T>
T Ggx(const ShadingGeometry& g, const T& kd, const T& f0, const T& alpha) {
  const T a2 = alpha * alpha;
  const T fresnel = f0 + (T(1) - f0) * Pow5(1.0 - g.v_dot_h);
  const T shadowing = GgxG1(g.n_dot_l, a2) * GgxG1(g.n_dot_v, a2);
  return kd * T(kInvPi) + fresnel * shadowing * GgxD(g.n_dot_h, a2) / (4.0 * g.n_dot_l * g.n_dot_v);
}

template <class T>
T Ward(const ShadingGeometry& g, const T& rho_d, const T& rho_s, const T& alpha) {
  using std::exp;
  const double cos2 = g.n_dot_h * g.n_dot_h;
  const double tan2 = (1.0 - cos2) / cos2;
  const T a2 = alpha * alpha;
  return rho_d * T(kInvPi) +
         rho_s * exp(-tan2 / a2) / (T(4 * kPi) * a2 * std::sqrt(g.n_dot_l * g.n_dot_v));
}

// The engine models give direct lighting by one punctual light as the engines evaluate it,
// written from the engines' public shader sources (the functions named are where each term
// lives). Terms the engines add outside the BRDF (energy compensation from pre-integrated
// tables, specular occlusion, wrapped diffuse) are not part of a punctual light's BRDF and are
// left out.

// Unreal Engine, DefaultLit shading model (Engine/Shaders/Private/ShadingModels.ush,
// DefaultLitBxDF; terms from BRDF.ush):
//   DiffuseColor = BaseColor·(1 − Metallic), Diffuse_Lambert = DiffuseColor/π;
//   SpecularColor = ComputeF0(Specular, BaseColor, Metallic) = lerp(0.08·Specular, BaseColor,
//   Metallic); a2 = Roughness⁴ (α = Roughness²); D_GGX(a2, NoH) = a2 / (π d²),
//   d = (NoH·a2 − NoH)·NoH + 1; Vis_SmithJointApprox(a2, NoV, NoL) = 0.5 / (NoL·(NoV(1 − a) + a)
//   + NoV·(NoL(1 − a) + a)), a = √a2; F_Schlick(SpecularColor, VoH) = saturate(50·F0.g)·Fc +
//   (1 − Fc)·F0, Fc = (1 − VoH)⁵; NoV = saturate(|n·v| + 1e-5).
//   f_r = Diffuse_Lambert + D·Vis·F.
// The floor a2 ≥ 1e-12 is ours (a roughness of exactly 0 would make D 0/0 at the peak).
// p = {base r, g, b, metallic, specular, roughness}.
template <class T>
std::array<T, 3> UnrealDefaultLit(const ShadingGeometry& g, const T* p) {
  using std::sqrt;
  const T& metallic = p[3];
  const T& specular = p[4];
  const T& roughness = p[5];
  const double no_v = std::min(1.0, std::fabs(g.n_dot_v) + 1e-5);
  const double no_l = g.n_dot_l;
  T a2 = roughness * roughness * roughness * roughness;
  if (a2 < T(1e-12)) a2 = T(1e-12);
  const T a = sqrt(a2);
  const T d = (g.n_dot_h * a2 - g.n_dot_h) * g.n_dot_h + T(1);
  const T dist = a2 / (T(kPi) * d * d);
  const T vis = T(0.5) / (no_l * (no_v * (T(1) - a) + a) + no_v * (no_l * (T(1) - a) + a));
  const double fc = Pow5(1.0 - g.v_dot_h);
  std::array<T, 3> f0;
  for (int c = 0; c < 3; ++c) f0[c] = T(0.08) * specular * (T(1) - metallic) + p[c] * metallic;
  T f90 = T(50) * f0[1];
  if (f90 > T(1)) f90 = T(1);
  if (f90 < T(0)) f90 = T(0);
  std::array<T, 3> out;
  for (int c = 0; c < 3; ++c) {
    const T fresnel = f90 * fc + (1.0 - fc) * f0[c];
    out[c] = p[c] * (T(1) - metallic) * T(kInvPi) + dist * vis * fresnel;
  }
  return out;
}

// Unity HDRP Lit (com.unity.render-pipelines.high-definition Runtime/Material/Lit/Lit.hlsl,
// ConvertSurfaceDataToBSDFData and BSDF(); terms from com.unity.render-pipelines.core
// ShaderLibrary/BSDF.hlsl and CommonMaterial.hlsl):
//   perceptualRoughness = 1 − smoothness, α = perceptualRoughness²
//   (PerceptualRoughnessToRoughness); metallic: diffuseColor = ComputeDiffuseColor = baseColor·(1 −
//   metallic), fresnel0 = ComputeFresnel0(baseColor, metallic, 0.04) = lerp(0.04, baseColor,
//   metallic); specular colour: fresnel0 = specularColor, diffuseColor = baseColor·(1 −
//   max(specularColor)) (the Lit shader's default "Energy Conserving Specular Color"); F =
//   F_Schlick(fresnel0, LdotH) (f90 = 1); D_GGX(NdotH, α) = α² / (π s²), s = (NdotH·α² −
//   NdotH)·NdotH + 1; V_SmithJointGGX (exact height-correlated Smith): 0.5 / (NdotL·√((−NdotV·α² +
//   NdotV)·NdotV + α²) + NdotV·√((−NdotL·α² + NdotL)·NdotL + α²)); DisneyDiffuse(NdotV, NdotL,
//   LdotV, perceptualRoughness) = (1/π)·F_Schlick(1, fd90, NdotL)· F_Schlick(1, fd90, NdotV)
//   / 1.03571, fd90 = 0.5 + perceptualRoughness·(1 + LdotV); NdotV clamped to ≥ 0.0001
//   (ClampNdotV); α ≥ 1e-4, the clamp a punctual light applies with its default maximum smoothness
//   0.99 (ClampRoughness with the light's minRoughness). f_r = diffuseColor·DisneyDiffuse + F·D·V.
// p = {base r, g, b, metallic, smoothness} or {base r, g, b, spec r, g, b, smoothness}.
template <class T>
std::array<T, 3> UnityHdrpLit(const ShadingGeometry& g, const T* p, bool specular_color) {
  using std::sqrt;
  const T& smoothness = specular_color ? p[6] : p[4];
  const T perceptual = T(1) - smoothness;
  T alpha = perceptual * perceptual;
  if (alpha < T(1e-4)) alpha = T(1e-4);
  const T a2 = alpha * alpha;
  const double n_dot_v = std::max(g.n_dot_v, 0.0001);
  const double n_dot_l = g.n_dot_l;
  const T s = (g.n_dot_h * a2 - g.n_dot_h) * g.n_dot_h + T(1);
  const T dist = T(kInvPi) * a2 / (s * s);
  const T lambda_v = n_dot_l * sqrt((-n_dot_v * a2 + n_dot_v) * n_dot_v + a2);
  const T lambda_l = n_dot_v * sqrt((-n_dot_l * a2 + n_dot_l) * n_dot_l + a2);
  const T vis = T(0.5) / (lambda_v + lambda_l);
  const T fd90 = T(0.5) + perceptual * (1.0 + g.l_dot_v);
  const T light_scatter = T(1) + (fd90 - T(1)) * Pow5(1.0 - n_dot_l);
  const T view_scatter = T(1) + (fd90 - T(1)) * Pow5(1.0 - n_dot_v);
  const T disney = T(kInvPi / 1.03571) * light_scatter * view_scatter;
  const double fc = Pow5(1.0 - g.v_dot_h);
  std::array<T, 3> f0, diffuse;
  if (specular_color) {
    T max_spec = p[3];
    if (p[4] > max_spec) max_spec = p[4];
    if (p[5] > max_spec) max_spec = p[5];
    for (int c = 0; c < 3; ++c) {
      f0[c] = p[3 + c];
      diffuse[c] = p[c] * (T(1) - max_spec);
    }
  } else {
    const T& metallic = p[3];
    for (int c = 0; c < 3; ++c) {
      f0[c] = T(0.04) * (T(1) - metallic) + p[c] * metallic;
      diffuse[c] = p[c] * (T(1) - metallic);
    }
  }
  std::array<T, 3> out;
  for (int c = 0; c < 3; ++c) {
    const T fresnel = f0[c] + (T(1) - f0[c]) * fc;
    out[c] = diffuse[c] * disney + fresnel * dist * vis;
  }
  return out;
}

// Unity URP Lit (com.unity.render-pipelines.universal ShaderLibrary/BRDF.hlsl,
// InitializeBRDFData, InitializeBRDFDataDirect and DirectBRDFSpecular; Lighting.hlsl,
// LightingPhysicallyBased):
//   metallic: diffuse = albedo·0.96·(1 − metallic) (OneMinusReflectivityMetallic with
//   kDielectricSpec.a = 0.96), specular = lerp(0.04, albedo, metallic);
//   specular setup: diffuse = albedo·(1 − specular) per channel, specular = specular colour;
//   perceptualRoughness = 1 − smoothness, roughness = max(perceptualRoughness², HALF_MIN_SQRT =
//   2^-7), roughness2 = max(roughness², HALF_MIN = 2^-14), normalizationTerm = 4·roughness + 2;
//   specularTerm = roughness2 / (d²·max(0.1, LoH²)·normalizationTerm),
//   d = NoH²·(roughness2 − 1) + 1.00001 (no Fresnel term: V·F is folded into 1/LoH²).
//   URP lights carry the factor π of its convention, so its "brdf" (diffuse + specularTerm ·
//   specular) is π·f_r: f_r = (diffuse + specularTerm·specular)/π.
// p = {albedo r, g, b, metallic, smoothness} or {albedo r, g, b, spec r, g, b, smoothness}.
template <class T>
std::array<T, 3> UnityUrpLit(const ShadingGeometry& g, const T* p, bool specular_setup) {
  const T& smoothness = specular_setup ? p[6] : p[4];
  const T perceptual = T(1) - smoothness;
  T roughness = perceptual * perceptual;
  if (roughness < T(0.0078125)) roughness = T(0.0078125);
  T roughness2 = roughness * roughness;
  if (roughness2 < T(6.103515625e-5)) roughness2 = T(6.103515625e-5);
  const T d = g.n_dot_h * g.n_dot_h * (roughness2 - T(1)) + T(1.00001);
  const double lo_h2 = std::max(0.1, g.v_dot_h * g.v_dot_h);
  const T specular_term = roughness2 / (d * d * lo_h2 * (T(4) * roughness + T(2)));
  std::array<T, 3> out;
  for (int c = 0; c < 3; ++c) {
    T diffuse, specular;
    if (specular_setup) {
      specular = p[3 + c];
      diffuse = p[c] * (T(1) - specular);
    } else {
      const T& metallic = p[3];
      specular = T(0.04) * (T(1) - metallic) + p[c] * metallic;
      diffuse = p[c] * T(0.96) * (T(1) - metallic);
    }
    out[c] = (diffuse + specular_term * specular) * T(kInvPi);
  }
  return out;
}

// Whether every RGB channel of `model` is an independent function of its own values (the
// legacy models: parameter k of channel c is values[offset_k + c]).
inline bool ChannelsIndependent(Model model) {
  return model == Model::kLambert || model == Model::kLafortune || model == Model::kBlinnPhong ||
         model == Model::kGgx || model == Model::kWard;
}

// One channel of a legacy model from that channel's values (a = kd / rho / rho_d, b = ks / f0 /
// rho_s, shape = n / alpha; lambert uses only a). Zero below the horizon.
template <class T>
T EvaluateChannel(Model model, const ShadingGeometry& g, const T& a, const T& b, const T& shape) {
  if (!g.AboveHorizon()) return T(0);
  switch (model) {
    case Model::kLambert:
      return Lambert(a);
    case Model::kLafortune:
      return Lafortune(g, a, b, shape);
    case Model::kBlinnPhong:
      return BlinnPhong(g, a, b, shape);
    case Model::kGgx:
      return Ggx(g, a, b, shape);
    case Model::kWard:
      return Ward(g, a, b, shape);
    default:
      return T(0);
  }
}

// Any model: `values` in the Material::values layout of DescribeModel(model). Zero when l or v
// is at or below the horizon.
template <class T>
std::array<T, 3> EvaluateRgb(Model model, const ShadingGeometry& g, const T* p) {
  std::array<T, 3> out{T(0), T(0), T(0)};
  if (!g.AboveHorizon()) return out;
  switch (model) {
    case Model::kLambert:
      for (int c = 0; c < 3; ++c) out[c] = Lambert(p[c]);
      break;
    case Model::kLafortune:
    case Model::kBlinnPhong:
    case Model::kGgx:
    case Model::kWard:
      for (int c = 0; c < 3; ++c) out[c] = EvaluateChannel(model, g, p[c], p[3 + c], p[6 + c]);
      break;
    case Model::kUnrealDefaultLit:
      out = UnrealDefaultLit(g, p);
      break;
    case Model::kUnityHdrpLit:
      out = UnityHdrpLit(g, p, false);
      break;
    case Model::kUnityHdrpLitSpecular:
      out = UnityHdrpLit(g, p, true);
      break;
    case Model::kUnityUrpLit:
      out = UnityUrpLit(g, p, false);
      break;
    case Model::kUnityUrpLitSpecular:
      out = UnityUrpLit(g, p, true);
      break;
  }
  return out;
}

}  // namespace models

// An analytic material: a model and its parameter values in DescribeModel(model)'s layout
// (each parameter's values from ParameterInfo::offset; RGB parameters take three).
struct Material {
  Model model = Model::kLambert;
  std::array<double, kMaxModelValues> values{};
  std::string name;
  std::string description;
  // Members of the JSON object this material was read from that are not model parameters
  // ("fit", "source", ...), kept verbatim as a JSON object text so a rewrite preserves them.
  std::string extra_json = "{}";

  // A material of `model` whose parameters, in DescribeModel order, are `parameters` (an RGB
  // value per parameter; scalar parameters take the first channel). Throws InvalidArgument
  // when the count does not match the model.
  static Material Make(Model model, const std::vector<Rgb>& parameters,
                       std::string material_name = "");

  // Parameter `index` (DescribeModel order) as RGB; a scalar is repeated in all three.
  Rgb Parameter(int index) const;
  // Looks a parameter up by its file name ("f0"); throws InvalidArgument if the model has none.
  Rgb Parameter(std::string_view parameter_name) const;
  void SetParameter(int index, const Rgb& value);

  Rgb Evaluate(const Vec3& l, const Vec3& v) const {
    return models::EvaluateRgb(model, ShadingGeometry::Of(l, v), values.data());
  }
};

// Parses the material file form of docs/design.md §9: "model" plus that model's parameters
// (RGB ones as a number or an [r, g, b] array). Every value must be finite and inside its
// parameter's range (ParameterInfo::min/max). `file` only names the source in error messages.
// Throws FormatError naming the member and the expected and found values.
Material ParseMaterialJson(std::string_view json_text, const std::string& file = "<material>");
Material LoadMaterialFile(const std::string& path);
// The canonical JSON form (2-space indent), parameter names as docs/design.md §9 spells them.
std::string MaterialToJson(const Material& material);

// Human-readable reasons the parameters are not physically plausible (negative values,
// kd + ks > 1, f0 > 1, values outside their range, ...). Empty when the material conserves
// energy.
std::vector<std::string> PhysicalProblems(const Material& material);

// What to type where in the engine's material editor, e.g. "Base Color 0.91 0.78 0.34,
// Metallic 1.00, Specular 0.50, Roughness 0.31" (two decimals). Empty for non-engine models.
std::string EngineInstructions(const Material& material);

}  // namespace brdf
