// The VTK side of brdf-view. Geometry comes from lobe.h / slices.h (no VTK there); this file and
// app_scenes.cpp, app_input.cpp only turn it into actors, handle keys and the mouse, and write
// screenshots. Here: the window's run loop and screenshots, and RunViewer.
#include "brdf/viewer/app.h"

#include <X11/Xlib.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkArrowSource.h>
#include <vtkAxisActor2D.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkCoordinate.h>
#include <vtkFloatArray.h>
#include <vtkImageActor.h>
#include <vtkImageMapToColors.h>
#include <vtkImageMapper3D.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRegularPolygonSource.h>
#include <vtkRenderStepsPass.h>
#include <vtkTransform.h>
#include <vtkTransformPolyDataFilter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "app_window.h"
#include "brdf/core/error.h"

namespace brdf::viewer {

namespace detail {

void StyleText(vtkTextProperty* p, int size, double r, double g, double b) {
  if (std::filesystem::exists(kFontFile)) {
    p->SetFontFamily(VTK_FONT_FILE);
    p->SetFontFile(kFontFile);
  }
  p->SetFontSize(size);
  p->SetColor(r, g, b);
  p->SetShadow(0);
}

bool IsSoftwareRenderer(const std::string& renderer) {
  std::string lower = renderer;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* name : {"llvmpipe", "softpipe", "swrast", "software rasterizer"}) {
    if (lower.find(name) != std::string::npos) return true;
  }
  return false;
}

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string Sci(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

vtkStandardNewMacro(ViewerStyle)

    bool App::WriteScreenshot(const std::string& path, std::string* error) {
  window_->Render();
  if (!first_frame_reported_) {
    first_frame_reported_ = true;
    Milestone("first frame");
  }
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window_);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  // The frame rendered just above is the picture: without this the filter renders it again.
  grab->ShouldRerenderOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(path.c_str());
  // zlib level 1: a third of the default level's time for a picture that is mostly flat
  // background (docs/benchmarks.md, viewer start-up).
  writer->SetCompressionLevel(1);
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0 || !std::filesystem::exists(path)) {
    *error = "cannot write " + path;
    return false;
  }
  vtkCamera* camera = renderer_->GetActiveCamera();
  const double* pos = camera->GetPosition();
  const double* focal = camera->GetFocalPoint();
  const double* up = camera->GetViewUp();
  const int* size = window_->GetSize();
  std::ofstream json(path + ".json");
  json.precision(17);
  json << "{\n  \"mode\": \"" << ModeName(mode_) << "\",\n  \"width\": " << size[0]
       << ",\n  \"height\": " << size[1] << ",\n  \"theta_in_deg\": " << theta_in_deg_
       << ",\n  \"camera\": {\n    \"position\": [" << pos[0] << ", " << pos[1] << ", " << pos[2]
       << "],\n    \"focal_point\": [" << focal[0] << ", " << focal[1] << ", " << focal[2]
       << "],\n    \"view_up\": [" << up[0] << ", " << up[1] << ", " << up[2]
       << "],\n    \"view_angle_deg\": " << camera->GetViewAngle()
       << ",\n    \"parallel_projection\": " << (camera->GetParallelProjection() ? "true" : "false")
       << ",\n    \"parallel_scale\": " << camera->GetParallelScale() << "\n  }";
  if (mode_ == Mode::kPreview && preview_) {
    // The rendered picture sits at world x 0…width−1, y 0…height−1 (one unit per pixel).
    const PreviewPanel::Image img = preview_->Current();
    json << ",\n  \"preview_image\": [" << img.width << ", " << img.height << "]";
  }
  json << "\n}\n";
  if (!json) {
    *error = "cannot write " + path + ".json";
    return false;
  }
  return true;
}

ViewerResult App::Run() {
  renderer_->SetBackground(kBackground[0], kBackground[1], kBackground[2]);
  // VTK's standard sequence of passes, with plain alpha blending for translucent surfaces (the
  // extrapolated band, the mirror arrow). Without a pass of its own the renderer blends them
  // order-independently, which costs extra framebuffers, a full-window compositing pass and,
  // on a CPU rasteriser, ≈ 15 ms of shader compilation before the first frame; blending in
  // drawing order looks the same for these few thin or nested surfaces.
  vtkNew<vtkRenderStepsPass> passes;
  renderer_->SetPass(passes);
  window_->SetDisplayId(display_);
  window_->SetSize(options_.width, options_.height);
  window_->SetWindowName("brdf-view");
  window_->AddRenderer(renderer_);
  const bool headless = !options_.screenshot_path.empty();
  // A screenshot renders into VTK's own framebuffers and reads the picture from there: no
  // window is mapped and nothing is copied to it (on a CPU rasteriser that copy, colour plus a
  // depth pass with a shader of its own, cost ≈ 15 % of the run). It still needs an X display
  // for the OpenGL context. Only interactive runs create the X interactor (VTK 9.1's crashed
  // in its Initialize, XSync on a null display, with an off-screen window and sometimes under
  // Xvfb), and the slider widget is only attached to it.
  if (headless) window_->SetOffScreenRendering(1);
  if (auto* gl = vtkOpenGLRenderWindow::SafeDownCast(window_)) {
    gl->Initialize();  // the X window and the GL context
    // VTK renders into an 8× multisampled framebuffer by default. On a GPU that is free; on a
    // CPU rasteriser (Mesa llvmpipe, e.g. under Xvfb) it shades every pixel up to 8 times and
    // made each frame cost ≈ 100 ms of CPU more (docs/benchmarks.md, viewer start-up).
    if (IsSoftwareRenderer(gl->GetState()->GetRenderer())) window_->SetMultiSamples(0);
  }
  Milestone("window");
  primary_ = pending_primary_.get();
  if (pending_compare_) compare_ = pending_compare_->get();
  Milestone("sources opened");
  interactive_ = !headless;
  if (!headless) interactor_->SetRenderWindow(window_);
  style_->app = this;
  interactor_->SetInteractorStyle(style_);

  info_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedDisplay();
  info_->GetPositionCoordinate()->SetValue(0.01, 0.99);
  info_->GetTextProperty()->SetVerticalJustificationToTop();
  Style(info_->GetTextProperty(), 14, 0.95, 0.95, 0.95);
  info_->GetTextProperty()->SetVerticalJustificationToTop();
  help_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedDisplay();
  help_->GetPositionCoordinate()->SetValue(0.01, 0.01);
  Style(help_->GetTextProperty(), 13, 0.7, 0.8, 0.95);
  hover_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedDisplay();
  hover_->GetPositionCoordinate()->SetValue(0.01, 0.90);
  hover_->GetTextProperty()->SetVerticalJustificationToTop();
  Style(hover_->GetTextProperty(), 13, 1.0, 0.95, 0.6);
  message_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedDisplay();
  message_->GetPositionCoordinate()->SetValue(0.5, 0.5);
  Style(message_->GetTextProperty(), 18, 1.0, 0.35, 0.3);
  message_->GetTextProperty()->SetJustificationToCentered();
  message_->GetTextProperty()->SetVerticalJustificationToCentered();
  for (vtkTextActor* t : {info_.Get(), help_.Get(), hover_.Get(), message_.Get()}) {
    renderer_->AddViewProp(t);
  }
  legend_->SetNumberOfLabels(5);
  legend_->UnconstrainedFontSizeOn();
  legend_->SetMaximumWidthInPixels(static_cast<int>(90 * TextScale()));
  legend_->SetVerticalTitleSeparation(static_cast<int>(std::lround(8 * TextScale())));
  legend_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  legend_->GetPositionCoordinate()->SetValue(0.89, 0.15);
  legend_->SetWidth(0.1);
  legend_->SetHeight(0.7);
  Style(legend_->GetTitleTextProperty(), 13, 0.95, 0.95, 0.95);
  Style(legend_->GetLabelTextProperty(), 12, 0.9, 0.9, 0.9);
  legend_->SetLabelFormat("%.3g");
  renderer_->AddViewProp(legend_);

  slider_rep_->GetPoint1Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  slider_rep_->GetPoint1Coordinate()->SetValue(0.30, 0.08);
  slider_rep_->GetPoint2Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  slider_rep_->GetPoint2Coordinate()->SetValue(0.75, 0.08);
  slider_rep_->SetTitleText("θin (°)");
  slider_rep_->SetLabelFormat("%.1f");
  slider_rep_->SetSliderLength(0.02);
  slider_rep_->SetSliderWidth(0.03);
  slider_rep_->SetTubeWidth(0.006);
  slider_rep_->SetTitleHeight(0.025);
  slider_rep_->SetLabelHeight(0.022);
  Style(slider_rep_->GetTitleProperty(), 14, 0.9, 0.9, 0.9);
  Style(slider_rep_->GetLabelProperty(), 14, 0.9, 0.9, 0.9);
  if (Primary()) {
    theta_in_deg_ = std::clamp(theta_in_deg_, MinThetaIn(), MaxThetaIn());
    current_slice_ = NearestSlice();
    slider_rep_->SetMinimumValue(MinThetaIn());
    slider_rep_->SetMaximumValue(std::max(MaxThetaIn(), MinThetaIn() + 1e-3));
    slider_rep_->SetValue(theta_in_deg_);
  }
  if (interactive_) slider_->SetInteractor(interactor_);
  slider_->SetRepresentation(slider_rep_);
  slider_->SetAnimationModeToJump();
  slider_callback_->SetClientData(this);
  slider_callback_->SetCallback([](vtkObject* caller, unsigned long, void* client, void*) {
    auto* widget = static_cast<vtkSliderWidget*>(caller);
    auto* rep = static_cast<vtkSliderRepresentation2D*>(widget->GetRepresentation());
    static_cast<App*>(client)->OnSlider(rep->GetValue());
  });
  slider_->AddObserver(vtkCommand::InteractionEvent, slider_callback_);

  if (interactive_) interactor_->Initialize();
  if (Primary()) {
    try {
      RecomputeScale();
    } catch (const Error& e) {
      status_ = std::string("cannot draw: ") + e.what();
    }
  }
  Rebuild(true);
  Milestone("scene");

  ViewerResult result;
  if (!primary_.error.empty()) {
    result.ok = false;
    // The readers' messages already start with the file's name; it is said once.
    const std::string& error = primary_.error;
    result.message =
        error.rfind(primary_.path + ":", 0) == 0 ? error : primary_.path + ": " + error;
  }
  if (headless) {
    if (mode_ == Mode::kPreview && !preview_ && result.ok) {
      result.ok = false;
      result.message = "no preview: " + PreviewUnavailableReason();
    }
    // A progressive preview gets its full budget before the picture is taken.
    if (mode_ == Mode::kPreview && preview_) {
      for (int pass = 0; pass < kScreenshotPreviewPasses && preview_->Refine(); ++pass) {
      }
      ShowPreviewImage();
      UpdateText();
    }
    std::string error;
    if (!WriteScreenshot(options_.screenshot_path, &error)) {
      result.ok = false;
      result.message = error;
    }
    Milestone("screenshot");
    return result;
  }
  timer_callback_->SetClientData(this);
  timer_callback_->SetCallback(
      [](vtkObject*, unsigned long, void* client, void*) { static_cast<App*>(client)->OnTimer(); });
  interactor_->AddObserver(vtkCommand::TimerEvent, timer_callback_);
  interactor_->CreateRepeatingTimer(30);
  window_->Render();
  first_frame_reported_ = true;
  Milestone("first frame");
  interactor_->Start();
  return result;
}

}  // namespace detail

using detail::App;

const char* ModeName(Mode mode) {
  switch (mode) {
    case Mode::kLobe:
      return "lobe";
    case Mode::kSlices:
      return "slices";
    case Mode::kPreview:
      return "preview";
  }
  return "?";
}

Mode ModeFromName(const std::string& name) {
  if (name == "lobe") return Mode::kLobe;
  if (name == "slices") return Mode::kSlices;
  if (name == "preview") return Mode::kPreview;
  throw InvalidArgument("unknown mode '" + name + "': expected lobe, slices or preview");
}

void ViewerOptions::Validate() const {
  if (width < 64 || width > 8192 || height < 64 || height > 8192) {
    throw InvalidArgument("window size " + std::to_string(width) + "x" + std::to_string(height) +
                          " is outside 64…8192 pixels");
  }
  if (!std::isfinite(theta_in_deg) || theta_in_deg < 0 || theta_in_deg >= 90) {
    throw InvalidArgument("θin must be in [0°, 90°), got " + std::to_string(theta_in_deg) + "°");
  }
}

std::string DisplayProblem() {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') return "no X display: DISPLAY is not set";
  Display* d = XOpenDisplay(display);
  if (d == nullptr) return std::string("cannot open the X display '") + display + "'";
  XCloseDisplay(d);
  return {};
}

ViewerResult RunViewer(const ViewerOptions& options, const SourceOpener& open_primary,
                       const SourceOpener& open_compare) {
  options.Validate();
  const char* display_name = std::getenv("DISPLAY");
  if (display_name == nullptr || *display_name == '\0') return {false, DisplayProblem(), true};
  // Opening the sources (reading, resampling the LUT: CPU work, no X or GL) runs on its own
  // thread while this one connects to the X server and creates the window and its OpenGL
  // context, the two longest steps before the first frame.
  std::future<LoadedSource> primary = std::async(std::launch::async, open_primary);
  std::optional<std::future<LoadedSource>> compare;
  if (open_compare) compare = std::async(std::launch::async, open_compare);
  // The window gets a display connection opened here. Left to itself, VTK 9.1's X interactor
  // opens one in Initialize and uses it without checking; under a freshly started Xvfb that
  // open sometimes failed and the program crashed (XSync on a null display). A few retries
  // cover the start-up race; if they all fail the user gets a sentence, not a crash.
  Display* display = nullptr;
  for (int attempt = 0; attempt < 20 && display == nullptr; ++attempt) {
    display = XOpenDisplay(nullptr);
    if (display == nullptr) usleep(100000);
  }
  if (display == nullptr) {
    return {false, std::string("cannot open the X display '") + display_name + "'", true};
  }
  ViewerResult result;
  {
    App app(options, std::move(primary), std::move(compare), display);
    result = app.Run();
  }
  XCloseDisplay(display);
  return result;
}

}  // namespace brdf::viewer