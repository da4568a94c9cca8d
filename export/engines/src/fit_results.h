// Private: the `brdf fit` results a manifest carries as its fallback material (fit_results.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace brdf::engines::detail {

// The hook for `brdf fit`: its engine-model parameters arrive as fitted material JSON objects
// in TextureMetadata::fitted_models_json (docs/design.md §9 form, with the fit's own "fit"
// diagnostics). They are carried verbatim so an engine can fall back to an analytic material
// (e.g. glTF KHR_materials_* values or the Unity/Unreal parameters the fitter adds) with its
// error; until a fit exists the member is null.
nlohmann::ordered_json FallbackMaterialJson(const std::vector<std::string>& fitted_models_json);

}  // namespace brdf::engines::detail
