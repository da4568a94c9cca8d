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

// The hook for `brdf fit`: its engine-model parameters arrive as fitted material JSON objects
// in TextureMetadata::fitted_models_json (docs/design.md §9 form, with the fit's own "fit"
// diagnostics). They are carried verbatim so an engine can fall back to an analytic material
// (e.g. glTF KHR_materials_* values or the Unity/Unreal parameters the fitter adds) with its
// error; until a fit exists the member is null.
ordered_json detail::FallbackMaterialJson(const std::vector<std::string>& fitted_models_json) {
  if (fitted_models_json.empty()) return nullptr;
  ordered_json models = ordered_json::array();
  ordered_json gltf = nullptr;
  for (const std::string& m : fitted_models_json) {
    ordered_json model = ordered_json::parse(m);
    if (gltf.is_null() && model.is_object() && model.value("model", "") == "unreal-defaultlit")
      gltf = ordered_json::parse(GltfFromUnrealDefaultLit(m));
    models.push_back(std::move(model));
  }
  return ordered_json{{"note",
                       "analytic fits of the same data, for engines or LODs that cannot "
                       "sample the 3D LUT; see each model's \"fit\" member for its error"},
                      {"models", std::move(models)},
                      {"gltf", std::move(gltf)}};
}

std::vector<std::string> ReadFitResults(const std::string& fits_dir, const std::string& name) {
  std::error_code ec;
  if (!fs::is_directory(fits_dir, ec))
    throw IoError(fits_dir + ": not a folder (expected the folder `brdf fit --out` wrote)");
  std::vector<std::string> files;
  const std::string prefix = name + ".";
  for (fs::directory_iterator it(fits_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    if (f.size() > prefix.size() + 5 && f.starts_with(prefix) && f.ends_with(".json") &&
        f.find('.', prefix.size()) == f.size() - 5)
      files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  std::vector<std::string> fits;
  for (const std::string& path : files) {
    const std::string text = ReadFileText(path, 16u << 20);
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object())
      throw FormatError(path, "the whole file", "a `brdf fit` result (a JSON object)",
                        "text that is not a JSON object");
    const auto kind = [&](const char* key) {
      return j.contains(key) ? std::string("a ") + j[key].type_name() : std::string("none");
    };
    if (!j.contains("model") || !j["model"].is_string())
      throw FormatError(path, "member \"model\"", "the fitted model's name", kind("model"));
    if (!j.contains("fit") || !j["fit"].is_object())
      throw FormatError(path, "member \"fit\"", "the fit report of `brdf fit`", kind("fit"));
    fits.push_back(j.dump());
  }
  return fits;
}

}  // namespace brdf::engines
