// Fits in the engine hand-off: the `brdf fit` results read from a folder, and the manifest's
// "fallback_material" made of them (brdf/engines/engine_export.h).
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/engines/engine_export.h"
#include "fit_results.h"

namespace brdf::engines {

namespace fs = std::filesystem;
using ordered_json = nlohmann::ordered_json;

ordered_json detail::FallbackMaterialJson(const std::vector<std::string>& fitted_models_json,
                                          const std::vector<FittedMaterial>& fits) {
  if (fitted_models_json.empty() && fits.empty()) return nullptr;
  ordered_json models = ordered_json::array();
  ordered_json gltf = nullptr;
  for (const std::string& m : fitted_models_json) {
    ordered_json model = ordered_json::parse(m);
    if (gltf.is_null() && model.is_object() && model.value("model", "") == "unreal-defaultlit")
      gltf = ordered_json::parse(
          GltfFromUnrealDefaultLit(ParseFittedMaterialJson(m, "the texture's metadata")));
    models.push_back(std::move(model));
  }
  for (const FittedMaterial& f : fits) {
    if (gltf.is_null() && f.material.model == Model::kUnrealDefaultLit)
      gltf = ordered_json::parse(GltfFromUnrealDefaultLit(f));
    // Members in the order a JSON object read back from the file has them (sorted).
    models.push_back(ordered_json::parse(nlohmann::json::parse(FittedMaterialToJson(f)).dump()));
  }
  return ordered_json{{"note",
                       "analytic fits of the same data, for engines or LODs that cannot "
                       "sample the 3D LUT; see each model's \"fit\" member for its error"},
                      {"models", std::move(models)},
                      {"gltf", std::move(gltf)}};
}

std::vector<FittedMaterial> ReadFitResults(const std::string& fits_dir, const std::string& name) {
  std::error_code ec;
  if (!fs::is_directory(fits_dir, ec))
    throw IoError(fits_dir + ": not a folder (expected a folder of fit results NAME.MODEL.json)");
  std::vector<std::string> files;
  const std::string prefix = name + ".";
  for (fs::directory_iterator it(fits_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    if (f.size() > prefix.size() + 5 && f.starts_with(prefix) && f.ends_with(".json") &&
        f.find('.', prefix.size()) == f.size() - 5)
      files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  std::vector<FittedMaterial> fits;
  for (const std::string& path : files)
    fits.push_back(ParseFittedMaterialJson(ReadFileText(path, 16u << 20), path));
  return fits;
}

}  // namespace brdf::engines
