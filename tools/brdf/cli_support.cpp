#include "cli_support.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"

namespace brdf::cli {

namespace fs = std::filesystem;

std::string MaterialLibraryDir() {
  if (const char* env = std::getenv("BRDF_MATERIALS_DIR"); env != nullptr && *env != '\0')
    return env;
  return std::string(BRDF_SOURCE_DIR) + "/data-samples/materials";
}

std::vector<std::string> MaterialLibraryFiles() {
  std::vector<std::string> files;
  const fs::path dir = MaterialLibraryDir();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw IoError(dir.string() + ": material library folder not found (set BRDF_MATERIALS_DIR)");
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".json")
      files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string ResolveMaterial(const std::string& name_or_file) {
  std::error_code ec;
  if (fs::is_regular_file(name_or_file, ec)) return name_or_file;
  const fs::path candidate = fs::path(MaterialLibraryDir()) / (name_or_file + ".json");
  if (fs::is_regular_file(candidate, ec)) return candidate.string();
  std::string names;
  for (const auto& f : MaterialLibraryFiles()) {
    if (!names.empty()) names += ", ";
    names += fs::path(f).stem().string();
  }
  throw InvalidArgument("'" + name_or_file +
                        "' is neither a file nor a library material (library: " + names + ")");
}

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void CheckOutputPath(const std::string& out, const std::string& input, const char* extension,
                     bool force, const char* option) {
  if (LowerExtension(out) != extension)
    throw InvalidArgument(std::string(option) + ": expected a file name ending in " + extension +
                          ", got '" + out + "'");
  std::error_code ec;
  if (fs::equivalent(out, input, ec))
    throw InvalidArgument(std::string(option) + ": '" + out + "' is the input file itself");
  ReportRemovedTemporaries(CheckWritableOutput(out, force));
}

void ReportRemovedTemporaries(const std::vector<std::string>& removed) {
  if (removed.empty()) return;
  std::string list;
  for (const std::string& r : removed) list += (list.empty() ? "" : ", ") + r;
  std::fprintf(stderr, "note: removed %zu temporary file%s left by an interrupted run: %s\n",
               removed.size(), removed.size() == 1 ? "" : "s", list.c_str());
}

}  // namespace brdf::cli
