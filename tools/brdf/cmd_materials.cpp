#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "brdf/core/models.h"
#include "brdf/sources/material_library.h"
#include "commands.h"

namespace brdf::cli {

int RunMaterials(const MaterialsOptions& options) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  if (!options.json) std::printf("%-22s %-12s %s\n", "NAME", "MODEL", "DESCRIPTION");
  for (const std::string& file : sources::MaterialLibraryFiles()) {
    const Material m = LoadMaterialFile(file);
    const std::string name = std::filesystem::path(file).stem().string();
    if (options.json) {
      list.push_back({{"name", name},
                      {"model", std::string(ModelName(m.model))},
                      {"description", m.description},
                      {"file", file}});
    } else {
      std::printf("%-22s %-12s %s\n", name.c_str(), std::string(ModelName(m.model)).c_str(),
                  m.description.c_str());
    }
  }
  if (options.json) std::printf("%s\n", list.dump(2).c_str());
  return 0;
}

}  // namespace brdf::cli
