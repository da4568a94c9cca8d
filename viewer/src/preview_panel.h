// Private to brdf::viewer: the environment-lit preview as the window shows it, an image that
// gets better each time the window is idle. The renderer itself is brdf::processing's preview
// module (no VTK); this interface keeps the window (app_window.h) independent of its API.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"

namespace brdf::viewer {

class PreviewPanel {
 public:
  struct Image {
    int width = 0, height = 0;
    std::vector<unsigned char> rgb8;  // top row first, tone-mapped sRGB
  };
  virtual ~PreviewPanel() = default;
  // One more refinement pass; false once the image is final (then nothing changes).
  virtual bool Refine() = 0;
  virtual Image Current() const = 0;
  // One line for the window: samples so far, environment, rotation.
  virtual std::string Describe() const = 0;
  // Turns the environment about the normal (z) by `delta_deg` and restarts the refinement.
  virtual void RotateEnvironment(double delta_deg) = 0;
  // Moves the preview camera around the object (polar angle from the normal, azimuth) and
  // restarts the refinement.
  virtual void Orbit(double delta_theta_deg, double delta_phi_deg) = 0;
};

// Null when the preview cannot be made (no evaluable source, or the renderer is missing);
// PreviewUnavailableReason() then says why.
std::unique_ptr<PreviewPanel> MakePreviewPanel(std::shared_ptr<const BrdfSource> primary,
                                               std::shared_ptr<const BrdfSource> compare,
                                               int window_width, int window_height);
std::string PreviewUnavailableReason();

}  // namespace brdf::viewer
