// The brdf-view window (private to brdf::viewer): the App that owns the VTK scene, its state
// and its handlers, and the interactor style that forwards keys and the mouse to it.
// app.cpp runs it and writes screenshots, app_scenes.cpp builds the lobe, slice and preview
// scenes, app_input.cpp handles keys and the mouse and writes the text overlay.
#pragma once

#include <X11/Xlib.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <vtkCallbackCommand.h>
#include <vtkImageData.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkProp.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "brdf/viewer/app.h"
#include "brdf/viewer/lobe.h"
#include "brdf/viewer/slices.h"
#include "preview_panel.h"

namespace brdf::viewer::detail {

inline constexpr const char* kFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
inline constexpr double kBackground[3] = {0.08, 0.08, 0.10};
// World units (degrees) between heat maps: room for the axis labels and titles.
inline constexpr double kSliceGapX = 130;
inline constexpr double kSliceGapY = 110;
// Refinement passes a preview screenshot waits for (the window keeps refining while idle).
inline constexpr int kScreenshotPreviewPasses = 24;

// Viridis, sampled at 0, ¼, ½, ¾, 1 (perceptually ordered, readable by colour-blind users).
inline constexpr double kViridis[5][3] = {{0.267, 0.005, 0.329},
                                          {0.229, 0.322, 0.546},
                                          {0.128, 0.567, 0.551},
                                          {0.369, 0.789, 0.383},
                                          {0.993, 0.906, 0.144}};

// Font, size and colour of an overlay text (DejaVu Sans when installed).
void StyleText(vtkTextProperty* p, int size, double r, double g, double b);
// Whether an OpenGL renderer string (glGetString(GL_RENDERER)) names a rasteriser that runs on
// the CPU: Mesa's llvmpipe, softpipe and the classic swrast.
bool IsSoftwareRenderer(const std::string& renderer);
// `v` with `digits` decimals, and with four significant digits.
std::string Fixed(double v, int digits);
std::string Sci(double v);

class App;

class ViewerStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static ViewerStyle* New();
  vtkTypeMacro(ViewerStyle, vtkInteractorStyleTrackballCamera) void OnChar() override;
  void OnKeyPress() override {}
  void OnMouseMove() override;
  void OnLeftButtonDown() override {
    if (orbit_preview) {
      const int* pos = GetInteractor()->GetEventPosition();
      drag_x = pos[0];
      drag_y = pos[1];
      dragging = true;
    } else if (pan_only) {
      const int* pos = GetInteractor()->GetEventPosition();
      FindPokedRenderer(pos[0], pos[1]);
      StartPan();
    } else {
      vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
    }
  }
  void OnLeftButtonUp() override;
  App* app = nullptr;
  bool pan_only = false;
  // Preview mode: a drag turns the preview camera once the button is released (each new
  // camera restarts the progressive render, so it is not redone on every mouse move).
  bool orbit_preview = false;
  bool dragging = false;
  int drag_x = 0, drag_y = 0;
};

class App {
 public:
  // The sources may still be opening on another thread: Run() creates the window first and
  // waits for them only when the scene needs them.
  App(const ViewerOptions& options, std::future<LoadedSource> primary,
      std::optional<std::future<LoadedSource>> compare, Display* display)
      : display_(display),
        options_(options),
        pending_primary_(std::move(primary)),
        pending_compare_(std::move(compare)),
        mode_(options.mode),
        theta_in_deg_(options.theta_in_deg),
        channel_(static_cast<Channel>(std::clamp(options.channel, 0, 3))),
        log_scale_(options.log_scale),
        cosine_weighted_(options.cosine_weighted),
        all_slices_(options.all_slices) {}

  ViewerResult Run();
  void OnKey(const std::string& keysym);
  void OnMouseMove(int x, int y);
  void OnSlider(double value) {
    theta_in_deg_ = value;
    if (mode_ == Mode::kSlices) current_slice_ = NearestSlice();
    Rebuild(false);
    window_->Render();
  }
  void OnPreviewDrag(int dx, int dy) {
    if (mode_ != Mode::kPreview || !preview_ || (dx == 0 && dy == 0)) return;
    preview_->Orbit(-0.4 * dy, -0.4 * dx);
    Rebuild(false);
    window_->Render();
  }
  void OnTimer() {
    if (mode_ == Mode::kPreview && preview_ && preview_->Refine()) {
      ShowPreviewImage();
      UpdateText();
      window_->Render();
    }
  }

 private:
  const ViewSource* Primary() const { return primary_.view ? &*primary_.view : nullptr; }
  const ViewSource* Compare() const {
    return compare_ && compare_->view ? &*compare_->view : nullptr;
  }
  int NearestSlice() const;
  double MinThetaIn() const { return Primary()->lut.theta_in_deg.front(); }
  double MaxThetaIn() const { return std::min(89.0, Primary()->lut.theta_in_deg.back()); }
  LobeOptions CurrentLobeOptions(double theta_in_deg) const;
  void RecomputeScale();
  void SetupColors(double lo, double hi, bool log_scale);
  void ClearScene();
  void Rebuild(bool reset_camera);
  void BuildLobeScene(bool reset_camera);
  void BuildSlicesScene(bool reset_camera);
  void BuildPreviewScene(bool reset_camera);
  void AddLobe(const LobeMesh& mesh, bool primary, double opacity);
  void AddArrow(const Vec3& direction, double length, const double color[3], double opacity);
  void ShowPreviewImage();
  void UpdateText();
  bool WriteScreenshot(const std::string& path, std::string* error);
  // Reports a milestone once the X server has processed everything sent so far (so a frame
  // that was just swapped is on screen, not still in Xlib's output buffer).
  void Milestone(const char* what) {
    if (!options_.on_milestone) return;
    XSync(display_, False);
    options_.on_milestone(what);
  }
  void AddProp(vtkProp* prop) {
    renderer_->AddViewProp(prop);
    scene_.emplace_back(prop);
  }
  // Text is sized for the default 960 × 720 window and shrinks with a smaller one (to half at
  // most, 7 points at least), so that the overlay does not run into the legend in small
  // screenshots.
  double TextScale() const {
    return std::clamp(std::min(options_.width / 960.0, options_.height / 720.0), 0.5, 1.0);
  }
  void Style(vtkTextProperty* p, int points, double r, double g, double b) const {
    StyleText(p, std::max(7, static_cast<int>(std::lround(points * TextScale()))), r, g, b);
  }

  Display* display_;  // owned by RunViewer, outlives every VTK object here
  ViewerOptions options_;
  std::future<LoadedSource> pending_primary_;
  std::optional<std::future<LoadedSource>> pending_compare_;
  LoadedSource primary_;
  std::optional<LoadedSource> compare_;
  Mode mode_;
  double theta_in_deg_;
  Channel channel_;
  bool log_scale_;
  bool cosine_weighted_;
  bool all_slices_;
  bool compare_wireframe_ = true;
  bool show_help_ = false;
  bool interactive_ = false;  // a window with an interactor (false for a screenshot run)
  bool first_frame_reported_ = false;
  int current_slice_ = 0;
  double scale_max_ = 1;  // colour scale and log floor for the lobe (fixed while θin moves)
  double arrow_length_ = 1;
  std::string status_;  // last action ("saved brdf-view-1.png")
  std::string hover_text_;

  vtkNew<vtkRenderer> renderer_;
  vtkNew<vtkRenderWindow> window_;
  vtkNew<vtkRenderWindowInteractor> interactor_;
  vtkNew<ViewerStyle> style_;
  vtkNew<vtkTextActor> info_, help_, hover_, message_;
  vtkNew<vtkScalarBarActor> legend_;
  vtkNew<vtkLookupTable> colors_;
  vtkNew<vtkSliderRepresentation2D> slider_rep_;
  vtkNew<vtkSliderWidget> slider_;
  vtkNew<vtkCallbackCommand> slider_callback_, timer_callback_;
  std::vector<vtkSmartPointer<vtkProp>> scene_;
  struct SlicePlacement {
    int slice;
    double x0, y0;  // world position of texel (0, 180): φd = 0 at x0, θd = 180 at y0
  };
  std::vector<SlicePlacement> placements_;
  std::unique_ptr<PreviewPanel> preview_;
  vtkSmartPointer<vtkImageData> preview_image_;
};

}  // namespace brdf::viewer::detail
