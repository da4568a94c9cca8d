// Keys, the mouse and the text overlay of the brdf-view window (app_window.h).
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

namespace brdf::viewer::detail {

void ViewerStyle::OnChar() {
  if (app) app->OnKey(GetInteractor()->GetKeySym() ? GetInteractor()->GetKeySym() : "");
}

void ViewerStyle::OnLeftButtonUp() {
  if (dragging) {
    dragging = false;
    const int* pos = GetInteractor()->GetEventPosition();
    if (app) app->OnPreviewDrag(pos[0] - drag_x, pos[1] - drag_y);
    return;
  }
  vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
}

void ViewerStyle::OnMouseMove() {
  vtkInteractorStyleTrackballCamera::OnMouseMove();
  if (app) {
    const int* pos = GetInteractor()->GetEventPosition();
    app->OnMouseMove(pos[0], pos[1]);
  }
}

void App::UpdateText() {
  std::ostringstream info;
  if (const ViewSource* source = Primary()) {
    info << source->name;
    if (const ViewSource* other = Compare()) {
      info << "  vs  " << other->name;
      if (mode_ == Mode::kLobe) info << (compare_wireframe_ ? " (wireframe)" : " (orange)");
    }
    info << "\nmode " << ModeName(mode_) << "   channel " << ChannelName(channel_);
    if (mode_ == Mode::kLobe) {
      const Lut& lut = source->lut;
      info << "\nθin = " << Fixed(theta_in_deg_, 1) << "°";
      const int k = NearestSlice();
      const bool filled = k < static_cast<int>(source->coverage.size()) &&
                          source->coverage[static_cast<std::size_t>(k)].filled;
      if (std::abs(lut.theta_in_deg[k] - theta_in_deg_) < 1e-6) {
        info << (filled ? " (filled slice, translucent)" : " (measured slice)");
      } else {
        info << " (between measured slices, interpolated as the LUT does)";
      }
      info << "\nradius " << (cosine_weighted_ ? "f_r·cosθo" : "f_r") << ", "
           << (log_scale_ ? "log (decades above 10⁻³ of max)" : "linear (1/sr)")
           << (all_slices_ ? ", all slices" : "");
      info << "\narrows: white normal, orange light, cyan mirror";
      info << "\ntranslucent: extrapolated beyond θb = " << Fixed(source->theta_b_deg, 0)
           << "°;  magenta: not measured";
    } else if (mode_ == Mode::kSlices) {
      info << "\nslice heat maps in the specular frame (θd = 0: mirror direction)";
    } else if (mode_ == Mode::kPreview) {
      if (preview_) {
        info << "\n" << preview_->Describe();
      } else {
        info << "\npreview: " << PreviewUnavailableReason();
      }
    }
    for (const std::string& w : source->warnings) info << "\nwarning: " << w;
    if (compare_ && !compare_->error.empty()) info << "\ncompare: " << compare_->error;
  }
  if (!status_.empty()) info << "\n" << status_;
  info_->SetInput(info.str().c_str());

  if (interactive_ && Primary()) {
    // The help lines cover the slider's place: the slider steps aside while they show.
    slider_->SetEnabled(!show_help_ && mode_ != Mode::kPreview && Primary()->lut.slices() > 1);
  }
  if (show_help_) {
    help_->SetInput(
        "h help   q quit   s screenshot   r reset camera\n"
        "1 lobe   2 slices   3 preview\n"
        "Left/Right θin −/+1°   PgUp/PgDn previous/next measured slice\n"
        "a all slices   c channel (R, G, B, luminance)\n"
        "l linear/log   w radius f_r or f_r·cosθo   m compare wireframe/colour\n"
        "preview: e/E rotate the environment, arrows or drag orbit the camera\n"
        "mouse: drag to orbit (lobe) or pan (slices), wheel to zoom");
  } else {
    help_->SetInput("h: keyboard help");
  }
  hover_->SetInput(hover_text_.c_str());
  if (!primary_.error.empty()) {
    message_->SetInput(("Could not open " + primary_.path + ":\n" + primary_.error).c_str());
    message_->SetVisibility(1);
  } else {
    message_->SetVisibility(0);
  }
}

void App::OnKey(const std::string& key) {
  if (key == "q" || key == "Escape") {
    interactor_->TerminateApp();
    return;
  }
  if (key == "h") {
    show_help_ = !show_help_;
    UpdateText();
    window_->Render();
    return;
  }
  if (key == "s") {
    std::string name;
    for (int n = 1;; ++n) {
      name = "brdf-view-" + std::to_string(n) + ".png";
      if (!std::filesystem::exists(name)) break;
    }
    std::string error;
    status_ = WriteScreenshot(name, &error) ? "saved " + name : "screenshot failed: " + error;
    UpdateText();
    window_->Render();
    return;
  }
  if (!Primary()) return;
  bool rebuild = true, reset = false, rescale = false;
  const Lut& lut = Primary()->lut;
  if (key == "1" || key == "2" || key == "3") {
    mode_ = key == "1" ? Mode::kLobe : key == "2" ? Mode::kSlices : Mode::kPreview;
    reset = true;
  } else if (mode_ == Mode::kPreview && preview_ &&
             (key == "Left" || key == "Right" || key == "Up" || key == "Down")) {
    preview_->Orbit(key == "Up"     ? -10.0
                    : key == "Down" ? 10.0
                                    : 0.0,
                    key == "Left"    ? -15.0
                    : key == "Right" ? 15.0
                                     : 0.0);
  } else if (key == "Left" || key == "Right") {
    theta_in_deg_ =
        std::clamp(theta_in_deg_ + (key == "Left" ? -1.0 : 1.0), MinThetaIn(), MaxThetaIn());
    current_slice_ = NearestSlice();
  } else if (key == "Prior" || key == "Next" || key == "Page_Up" || key == "Page_Down") {
    const bool up = key == "Prior" || key == "Page_Up";
    double target = theta_in_deg_;
    if (up) {
      for (int k = lut.slices() - 1; k >= 0; --k) {
        if (lut.theta_in_deg[k] < theta_in_deg_ - 1e-6) {
          target = lut.theta_in_deg[k];
          break;
        }
      }
    } else {
      for (int k = 0; k < lut.slices(); ++k) {
        if (lut.theta_in_deg[k] > theta_in_deg_ + 1e-6) {
          target = lut.theta_in_deg[k];
          break;
        }
      }
    }
    theta_in_deg_ = std::min(target, MaxThetaIn());
    current_slice_ = NearestSlice();
  } else if (key == "a") {
    all_slices_ = !all_slices_;
    reset = mode_ == Mode::kSlices;
  } else if (key == "c") {
    channel_ = static_cast<Channel>((static_cast<int>(channel_) + 1) % 4);
    rescale = true;
  } else if (key == "l") {
    log_scale_ = !log_scale_;
    rescale = true;
    reset = true;
  } else if (key == "w") {
    cosine_weighted_ = !cosine_weighted_;
    rescale = true;
    reset = true;
  } else if (key == "m") {
    compare_wireframe_ = !compare_wireframe_;
  } else if (key == "r") {
    reset = true;
  } else if ((key == "e" || key == "E") && preview_) {
    preview_->RotateEnvironment(key == "e" ? 15.0 : -15.0);
  } else {
    rebuild = false;
  }
  if (!rebuild) return;
  status_.clear();
  if (rescale) RecomputeScale();
  Rebuild(reset);
  window_->Render();
}

void App::OnMouseMove(int x, int y) {
  if (mode_ != Mode::kSlices || !Primary() || placements_.empty()) return;
  renderer_->SetDisplayPoint(x, y, 0);
  renderer_->DisplayToWorld();
  const double* w = renderer_->GetWorldPoint();
  const double wx = w[3] != 0 ? w[0] / w[3] : w[0];
  const double wy = w[3] != 0 ? w[1] / w[3] : w[1];
  std::string text;
  for (const SlicePlacement& p : placements_) {
    const double phi_d = wx - p.x0;
    const double theta_d = 180.0 - (wy - p.y0);
    if (phi_d < -0.5 || phi_d > 360.5 || theta_d < -0.5 || theta_d > 180.5) continue;
    const SliceProbe probe = ProbeSlice(*Primary(), p.slice, channel_, phi_d, theta_d);
    text = "θin " + Fixed(Primary()->lut.theta_in_deg[p.slice], 0) + "°   θd " +
           Fixed(probe.theta_d_deg, 0) + "°  φd " + Fixed(probe.phi_d_deg, 0) + "°   from θout " +
           Fixed(probe.theta_out_deg, 1) + "°  φout " + Fixed(probe.phi_out_deg, 1) + "°\n" +
           ChannelName(channel_) + " " + Sci(probe.value) + " 1/sr   (RGB " + Sci(probe.rgb[0]) +
           ", " + Sci(probe.rgb[1]) + ", " + Sci(probe.rgb[2]) + ")   " +
           (probe.below_horizon ? "below the horizon: edge extension of θout = 90°"
                                : CoverageName(probe.coverage));
    break;
  }
  if (text != hover_text_) {
    hover_text_ = text;
    hover_->SetInput(hover_text_.c_str());
    window_->Render();
  }
}

}  // namespace brdf::viewer::detail
