#include "brdf/core/brdf_source.h"

#include "brdf/core/error.h"
#include "brdf/core/merl.h"
#include "brdf/core/rgl.h"

namespace brdf {

std::unique_ptr<BrdfSource> OpenBrdfSource(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".json") return std::make_unique<AnalyticBrdf>(LoadMaterialFile(path));
  if (ext == ".bsdf") return std::make_unique<RglBrdf>(RglBrdf::Load(path));
  if (ext == ".binary") return std::make_unique<MerlBrdf>(MerlBrdf::Load(path));
  throw FormatError(path, "file name",
                    "an evaluable BRDF file (.json material, .bsdf RGL, .binary MERL)",
                    "extension '" + ext + "'");
}

}  // namespace brdf
