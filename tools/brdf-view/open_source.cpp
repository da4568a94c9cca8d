#include "open_source.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/open.h"
#include "cli_support.h"

namespace brdf::view_tool {

viewer::LoadedSource OpenViewSource(const std::string& path_or_name) {
  viewer::LoadedSource out;
  out.path = path_or_name;
  try {
    const std::string path =
        std::filesystem::exists(path_or_name) ? path_or_name : cli::ResolveMaterial(path_or_name);
    const std::string name = sources::OutputNameOf(path);
    std::vector<std::string> warnings;
    const sources::FileKind kind = sources::DetectFileKind(path);
    if (kind == sources::FileKind::kCapture || kind == sources::FileKind::kMaterial) {
      // The measurement itself (not only an interpolated BRDF) so the lobe can show which
      // directions were measured.
      sources::PreparedMeasurement p = sources::PrepareMeasurement(path, kind, std::nullopt);
      out.view = viewer::ViewSourceFromMeasurement(p.measurement, p.extrapolation.params, name);
      // The same evaluation `brdf eval` and `brdf preview` use (a capture through its LUT).
      sources::OpenedSource opened = sources::OpenBrdf(path);
      out.brdf = std::move(opened.brdf);
      warnings.insert(warnings.end(), p.warnings.begin(), p.warnings.end());
    } else if (sources::IsTexture(kind) || kind == sources::FileKind::kSidecar) {
      sources::OpenedTexture t = sources::OpenExportedTexture(path);
      if (!t.texture.IsSingleLut()) {
        throw InvalidArgument(path + ": an atlas holds many materials; open one material's LUT");
      }
      double theta_b = 90;
      if (t.sidecar && t.sidecar->extrapolation) theta_b = t.sidecar->extrapolation->theta_b_deg;
      out.brdf = std::make_shared<brdf::LutBrdf>(t.texture.lut, name);
      out.view = viewer::ViewSourceFromLut(std::move(t.texture.lut), name, theta_b);
      warnings.insert(warnings.end(), t.warnings.begin(), t.warnings.end());
    } else {
      // Measured databases (RGL, MERL) and tables (Zemax, LightTools, CSV): whatever
      // sources::OpenBrdf makes of the file, captured at the reference geometry.
      sources::OpenedSource opened = sources::OpenBrdf(path);
      warnings.insert(warnings.end(), opened.warnings.begin(), opened.warnings.end());
      std::shared_ptr<const BrdfSource> brdf = std::move(opened.brdf);
      out.view = viewer::ViewSourceFromBrdf(*brdf, name);
      out.brdf = std::move(brdf);
    }
    out.view->warnings = std::move(warnings);
  } catch (const Error& e) {
    out.view.reset();
    out.brdf.reset();
    out.error = e.what();
  } catch (const std::exception& e) {
    out.view.reset();
    out.brdf.reset();
    out.error = std::string("unexpected failure: ") + e.what();
  }
  return out;
}

}  // namespace brdf::view_tool
