#include "brdf/core/brdf_source.h"

#include "brdf/core/error.h"

namespace brdf {

std::unique_ptr<BrdfSource> OpenBrdfSource(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".json") return std::make_unique<AnalyticBrdf>(LoadMaterialFile(path));
  throw FormatError(path, "file name", "an evaluable BRDF file (.json material)",
                    "extension '" + ext + "'");
}

}  // namespace brdf
