#include "brdf/sources/material_library.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "brdf/core/error.h"

#ifndef BRDF_MATERIALS_DIR_FROM_EXE
#error "BRDF_MATERIALS_DIR_FROM_EXE must be defined by the build (sources/CMakeLists.txt)"
#endif
#ifndef BRDF_SOURCE_MATERIALS_DIR
#error "BRDF_SOURCE_MATERIALS_DIR must be defined by the build (sources/CMakeLists.txt)"
#endif

namespace brdf::sources {

namespace fs = std::filesystem;

std::string MaterialLibraryDir() {
  if (const char* env = std::getenv(kMaterialsDirVariable); env != nullptr && *env != '\0')
    return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = (exe.parent_path() / BRDF_MATERIALS_DIR_FROM_EXE).lexically_normal();
    if (fs::is_directory(installed, ec)) return installed.string();
  }
  return fs::path(BRDF_SOURCE_MATERIALS_DIR).lexically_normal().string();
}

std::vector<std::string> MaterialLibraryFiles() {
  const fs::path dir = MaterialLibraryDir();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw IoError(dir.string() + ": material library folder not found (set " +
                  kMaterialsDirVariable + " to the folder of the material files)");
  std::vector<std::string> files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_regular_file(type_ec) && it->path().extension() == ".json")
      files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> MaterialLibraryNames() {
  std::vector<std::string> names;
  std::error_code ec;
  if (!fs::is_directory(MaterialLibraryDir(), ec)) return names;
  for (const std::string& f : MaterialLibraryFiles()) names.push_back(fs::path(f).stem().string());
  return names;
}

std::optional<std::string> FindLibraryMaterial(const std::string& name) {
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    return std::nullopt;
  const fs::path candidate = fs::path(MaterialLibraryDir()) / (name + ".json");
  std::error_code ec;
  if (!fs::is_regular_file(candidate, ec)) return std::nullopt;
  return candidate.string();
}

std::string ResolveSource(const std::string& path_or_name) {
  std::error_code ec;
  // symlink_status: a dangling link is something at that path too (its reader says so).
  if (fs::exists(fs::symlink_status(path_or_name, ec))) return path_or_name;
  if (auto file = FindLibraryMaterial(path_or_name)) return *file;
  const bool bare_name = !path_or_name.empty() && path_or_name.find('/') == std::string::npos &&
                         !fs::path(path_or_name).has_extension();
  if (!bare_name) return path_or_name;
  std::string names;
  for (const std::string& n : MaterialLibraryNames()) names += (names.empty() ? "" : ", ") + n;
  throw IoError(path_or_name + ": no such file, and no library material of that name (library " +
                MaterialLibraryDir() + (names.empty() ? ": empty" : ": " + names) + ")");
}

}  // namespace brdf::sources
