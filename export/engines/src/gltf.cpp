// glTF 2.0 material values from an Unreal DefaultLit fit (brdf/engines/engine_export.h).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/engines/engine_export.h"

namespace brdf::engines {

using ordered_json = nlohmann::ordered_json;

std::string GltfFromUnrealDefaultLit(const FittedMaterial& fit) {
  const Material& m = fit.material;
  if (m.model != Model::kUnrealDefaultLit)
    throw InvalidArgument("glTF values: expected an unreal-defaultlit fit, got " +
                          std::string(ModelName(m.model)));
  const Rgb base = m.Parameter("base_color");
  const double metallic = m.Parameter("metallic")[0], specular = m.Parameter("specular")[0],
               roughness = m.Parameter("roughness")[0];
  const double grey = 2.0 * specular;
  ordered_json out = {
      {"note",
       "glTF 2.0 values from the unreal-defaultlit fit: same base colour, metallic, roughness "
       "(alpha = roughness^2) and dielectric F0 = 0.08 * Specular = 0.04 * specularColorFactor; "
       "glTF's BRDF differs in its Fresnel-weighted diffuse and Smith term"},
      {"from", "unreal-defaultlit"},
      {"rmse", fit.report.rmse},
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
