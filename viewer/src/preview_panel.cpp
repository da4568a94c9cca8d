#include "preview_panel.h"

namespace brdf::viewer {

std::unique_ptr<PreviewPanel> MakePreviewPanel(std::shared_ptr<const BrdfSource>,
                                               std::shared_ptr<const BrdfSource>, int, int) {
  return nullptr;
}

std::string PreviewUnavailableReason() {
  return "the environment-lit preview renderer is not part of this build yet";
}

}  // namespace brdf::viewer
