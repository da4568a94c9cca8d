#include "open_source.h"

#include <utility>

#include "brdf/core/error.h"
#include "brdf/sources/open.h"

namespace brdf::view_tool {

std::string RemedyText(const Remedy& remedy) {
  switch (remedy.kind) {
    case RemedyKind::kEvaluateSingleLut:
      return "; open one material's LUT";
    case RemedyKind::kForceOverwrite:  // an empty file: several outputs exist
      return std::string("; use --force to overwrite ") + (remedy.file.empty() ? "them" : "it");
    default:
      return {};
  }
}

viewer::LoadedSource OpenViewSource(const std::string& path_or_name) {
  viewer::LoadedSource out;
  out.path = path_or_name;
  try {
    sources::OpenedForView opened = sources::OpenForView(path_or_name);
    const std::string name = sources::OutputNameOf(opened.path);
    // The lobe shows which directions were measured when the LUT came from a measurement.
    out.view = opened.measurement
                   ? viewer::ViewSourceFromResampled(*opened.measurement, std::move(opened.lut),
                                                     *opened.resample_report, name)
                   : viewer::ViewSourceFromLut(std::move(opened.lut), name, opened.theta_b_deg);
    out.view->warnings = std::move(opened.warnings);
    out.brdf = std::move(opened.brdf);
  } catch (const Error& e) {
    out.view.reset();
    out.brdf.reset();
    out.error = e.what();
    out.error += RemedyText(e.remedy());
  } catch (const std::exception& e) {
    out.view.reset();
    out.brdf.reset();
    out.error = std::string("unexpected failure: ") + e.what();
  }
  return out;
}

}  // namespace brdf::view_tool
