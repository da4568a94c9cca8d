// Helpers shared by the brdf subcommands (no CLI11 here).
#pragma once

#include <string>
#include <vector>

namespace brdf::cli {

// The folder of the virtual sample library: $BRDF_MATERIALS_DIR if set, else the
// repository's data-samples/materials.
std::string MaterialLibraryDir();

// Paths of every material file in the library, sorted by name.
std::vector<std::string> MaterialLibraryFiles();

// Resolves `name_or_file`: an existing file path is returned as is; otherwise the library
// material of that name. Throws InvalidArgument listing the library names when neither exists.
std::string ResolveMaterial(const std::string& name_or_file);

// Lower-case extension including the dot (".bpc"), or "" when there is none.
std::string LowerExtension(const std::string& path);

}  // namespace brdf::cli
