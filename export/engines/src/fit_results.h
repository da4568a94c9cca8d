// Private: the `brdf fit` results a manifest carries as its fallback material (fit_results.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "brdf/core/fitted_material.h"

namespace brdf::engines::detail {

// The hook for `brdf fit`: the fits the metadata carries (TextureMetadata::fitted_models_json,
// JSON texts, verbatim) and `brdf fit` results (`fits`, written as their material files,
// docs/design.md §9 with the fit's own "fit" diagnostics), so an engine can fall back to an
// analytic material (e.g. glTF KHR_materials_* values or the Unity/Unreal parameters the fitter
// adds) with its error; until a fit exists the member is null.
nlohmann::ordered_json FallbackMaterialJson(const std::vector<std::string>& fitted_models_json,
                                            const std::vector<FittedMaterial>& fits);

}  // namespace brdf::engines::detail
