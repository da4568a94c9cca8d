// The virtual sample library: the analytic materials (gold, paper_white, wood_oak, ...) that a
// bare name stands for on every command line and in brdf-view, and that `brdf materials` lists.
// Each is a material file (docs/design.md §9) named NAME.json in one folder.
//
// Which folder, first match wins:
//  1. $BRDF_MATERIALS_DIR, when set and not empty (then nowhere else: for tests, packagers and
//     users with their own library);
//  2. <folder of the running executable>/../share/brdf-toolchain/materials, the installed
//     layout (`cmake --install` puts the files there; found relative to the executable, like
//     the lazy modules of brdf/core/lazy_module.h, so an installed tree can be moved), when that
//     folder exists;
//  3. the source tree's data-samples/materials, for programs run from the build tree.
//
// Names and files: an argument that names an existing path is that path, whatever the library
// holds (a file called `gold` in the current folder wins over the library's gold). Only an
// argument that names nothing on disk is looked up in the library.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace brdf::sources {

// The environment variable of rule 1.
inline constexpr const char* kMaterialsDirVariable = "BRDF_MATERIALS_DIR";

// The folder the rule above chooses (it may not exist when rule 1 names a missing folder).
std::string MaterialLibraryDir();

// Every material file (*.json) of the library, sorted by name. Throws IoError naming the folder
// and the variable when the folder does not exist.
std::vector<std::string> MaterialLibraryFiles();

// The library names ("gold", ...), sorted; empty when the folder does not exist.
std::vector<std::string> MaterialLibraryNames();

// The file of the library material `name` ("gold" → ".../gold.json"), or nullopt when the
// library has none of that name (or `name` contains a '/', which no library name does).
std::optional<std::string> FindLibraryMaterial(const std::string& name);

// What a source argument names: `path_or_name` itself when anything exists at that path (a
// file, or a folder, FIFO or device that the reader then refuses), else the library material of
// that name. For an argument that is neither, a bare name (no '/', no extension) throws IoError
// "<name>: no such file, and no library material of that name (library FOLDER: gold, ...)"; any
// other argument is returned as it is, so the reader reports the missing file in its own words.
std::string ResolveSource(const std::string& path_or_name);

}  // namespace brdf::sources
