// glTF 2.0 material values from an Unreal DefaultLit fit (brdf/engines/engine_export.h).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/engines/engine_export.h"

namespace brdf::engines {

using ordered_json = nlohmann::ordered_json;

std::string GltfFromUnrealDefaultLit(const std::string& fit_json) {
  const nlohmann::json j = nlohmann::json::parse(fit_json, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("model", "") != "unreal-defaultlit")
    throw InvalidArgument("glTF values: expected an unreal-defaultlit fit");
  const auto number = [&](const char* key) {
    if (!j.contains(key) || !j[key].is_number())
      throw InvalidArgument(std::string("glTF values: the unreal-defaultlit fit has no ") + key);
    return j[key].get<double>();
  };
  if (!j.contains("base_color") || !j["base_color"].is_array() || j["base_color"].size() != 3)
    throw InvalidArgument("glTF values: the unreal-defaultlit fit has no base_color");
  const std::vector<double> base = j["base_color"].get<std::vector<double>>();
  const double metallic = number("metallic"), specular = number("specular"),
               roughness = number("roughness");
  const double grey = 2.0 * specular;
  ordered_json out = {
      {"note",
       "glTF 2.0 values from the unreal-defaultlit fit: same base colour, metallic, roughness "
       "(alpha = roughness^2) and dielectric F0 = 0.08 * Specular = 0.04 * specularColorFactor; "
       "glTF's BRDF differs in its Fresnel-weighted diffuse and Smith term"},
      {"from", "unreal-defaultlit"},
      {"rmse", j.contains("fit") && j["fit"].is_object() ? j["fit"].value("rmse", -1.0) : -1.0},
      {"material",
       {{"pbrMetallicRoughness",
         {{"baseColorFactor", {base[0], base[1], base[2], 1.0}},
          {"metallicFactor", metallic},
          {"roughnessFactor", roughness}}},
        {"extensions",
         {{"KHR_materials_specular",
           {{"specularFactor", 1.0}, {"specularColorFactor", {grey, grey, grey}}}}}}}}};
  return out.dump();
}

}  // namespace brdf::engines
