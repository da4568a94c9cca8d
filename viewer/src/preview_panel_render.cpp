// The preview panel on top of brdf::preview (preview/include/brdf/preview/preview.h):
// a sphere under the built-in studio map, refined one pass per idle tick. Built only when the
// brdf::preview target exists (viewer/CMakeLists.txt); preview_panel.cpp is the fallback.
#include <algorithm>
#include <cmath>
#include <string>

#include "brdf/core/error.h"
#include "brdf/preview/preview.h"
#include "preview_panel.h"

namespace brdf::viewer {
namespace {

// Passes after which the picture is final; a screenshot renders all of them. A MIS pass draws
// one map and one BRDF direction per pixel.
constexpr int kMaxPasses = 64;
constexpr double kTargetRelativeRms = 0.01;

class RenderedPreview final : public PreviewPanel {
 public:
  RenderedPreview(std::shared_ptr<const BrdfSource> primary,
                  std::shared_ptr<const BrdfSource> compare, int size)
      : primary_(std::move(primary)),
        compare_(std::move(compare)),
        environment_(preview::EnvironmentMap::Studio()),
        size_(size) {
    Restart();
  }

  bool Refine() override {
    if (Done()) return false;
    first_->RenderPasses(1);
    if (second_) second_->RenderPasses(1);
    return true;
  }

  Image Current() const override {
    preview::PreviewImage img = first_->Image();
    if (second_) img = preview::SideBySide(img, second_->Image());
    Image out;
    out.width = img.width;
    out.height = img.height;
    out.rgb8 = preview::ToneMap(img);
    return out;
  }

  std::string Describe() const override {
    const double rms = first_->EstimatedRelativeRms();
    std::string text = "preview: sphere under the studio map, map turned " +
                       std::to_string(static_cast<int>(std::lround(rotation_deg_))) +
                       "°, camera at θ " + std::to_string(static_cast<int>(camera_theta_deg_)) +
                       "° φ " + std::to_string(static_cast<int>(camera_phi_deg_)) + "°, " +
                       std::to_string(first_->passes()) + " passes";
    if (std::isfinite(rms)) {
      text += ", est. error " +
              std::to_string(static_cast<int>(std::lround(rms * 1000)) / 10.0).substr(0, 4) + " %";
    }
    if (second_) text += "\nleft: first source, middle: second, right: difference";
    return text;
  }

  void RotateEnvironment(double delta_deg) override {
    rotation_deg_ = std::fmod(rotation_deg_ + delta_deg + 360.0, 360.0);
    Restart();
  }

  void Orbit(double delta_theta_deg, double delta_phi_deg) override {
    camera_theta_deg_ = std::clamp(camera_theta_deg_ + delta_theta_deg, 5.0, 175.0);
    camera_phi_deg_ = std::fmod(camera_phi_deg_ + delta_phi_deg + 360.0, 360.0);
    Restart();
  }

 private:
  bool Done() const {
    const double rms = first_->EstimatedRelativeRms();
    return first_->passes() >= kMaxPasses || (std::isfinite(rms) && rms < kTargetRelativeRms);
  }

  preview::PreviewOptions Options() const {
    preview::PreviewOptions o;
    o.width = o.height = size_;
    o.camera.theta_deg = camera_theta_deg_;
    o.camera.phi_deg = camera_phi_deg_;
    o.environment_rotation_deg = rotation_deg_;
    o.jobs = 0;
    return o;
  }

  // A new camera or map rotation means new renderers; the BRDF samplers are kept.
  void Restart() {
    first_ = std::make_unique<preview::PreviewRenderer>(*primary_, environment_, Options(),
                                                        first_ ? first_->sampler() : nullptr);
    if (compare_) {
      second_ = std::make_unique<preview::PreviewRenderer>(*compare_, environment_, Options(),
                                                           second_ ? second_->sampler() : nullptr);
    }
  }

  std::shared_ptr<const BrdfSource> primary_, compare_;
  preview::EnvironmentMap environment_;
  int size_;
  double rotation_deg_ = 0, camera_theta_deg_ = 70, camera_phi_deg_ = 0;
  std::unique_ptr<preview::PreviewRenderer> first_, second_;
};

std::string g_reason;

}  // namespace

std::unique_ptr<PreviewPanel> MakePreviewPanel(std::shared_ptr<const BrdfSource> primary,
                                               std::shared_ptr<const BrdfSource> compare,
                                               int window_width, int window_height) {
  if (!primary) {
    g_reason = "this source cannot be evaluated for a preview";
    return nullptr;
  }
  // Square renders that leave room for the text; three panels side by side with a comparison.
  const int panels = compare ? 3 : 1;
  const int size = std::max(32, std::min(window_height * 3 / 4, window_width * 9 / 10 / panels));
  try {
    return std::make_unique<RenderedPreview>(std::move(primary), std::move(compare), size);
  } catch (const Error& e) {
    g_reason = e.what();
    return nullptr;
  }
}

std::string PreviewUnavailableReason() { return g_reason; }

}  // namespace brdf::viewer
