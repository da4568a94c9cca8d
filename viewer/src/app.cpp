// The VTK side of brdf-view. Geometry comes from lobe.h / slices.h (no VTK there); this file
// only turns it into actors, handles keys and the mouse, and writes screenshots.
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
#include <future>
#include <sstream>
#include <vector>

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkArrowSource.h>
#include <vtkAxisActor2D.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkCoordinate.h>
#include <vtkFloatArray.h>
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkImageMapToColors.h>
#include <vtkImageMapper3D.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
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
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTransform.h>
#include <vtkTransformPolyDataFilter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "brdf/core/error.h"
#include "brdf/viewer/lobe.h"
#include "brdf/viewer/slices.h"
#include "preview_panel.h"

namespace brdf::viewer {
namespace {

constexpr const char* kFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr double kBackground[3] = {0.08, 0.08, 0.10};
// World units (degrees) between heat maps: room for the axis labels and titles.
constexpr double kSliceGapX = 130;
constexpr double kSliceGapY = 110;
// Refinement passes a preview screenshot waits for (the window keeps refining while idle).
constexpr int kScreenshotPreviewPasses = 24;

// Viridis, sampled at 0, ¼, ½, ¾, 1 (perceptually ordered, readable by colour-blind users).
constexpr double kViridis[5][3] = {{0.267, 0.005, 0.329},
                                   {0.229, 0.322, 0.546},
                                   {0.128, 0.567, 0.551},
                                   {0.369, 0.789, 0.383},
                                   {0.993, 0.906, 0.144}};

void StyleText(vtkTextProperty* p, int size, double r, double g, double b) {
  if (std::filesystem::exists(kFontFile)) {
    p->SetFontFamily(VTK_FONT_FILE);
    p->SetFontFile(kFontFile);
  }
  p->SetFontSize(size);
  p->SetColor(r, g, b);
  p->SetShadow(0);
}

// Whether an OpenGL renderer string (glGetString(GL_RENDERER)) names a rasteriser that runs on
// the CPU: Mesa's llvmpipe, softpipe and the classic swrast.
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
vtkStandardNewMacro(ViewerStyle)

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

int App::NearestSlice() const {
  const Lut& lut = Primary()->lut;
  int best = 0;
  for (int k = 1; k < lut.slices(); ++k) {
    if (std::abs(lut.theta_in_deg[k] - theta_in_deg_) <
        std::abs(lut.theta_in_deg[best] - theta_in_deg_)) {
      best = k;
    }
  }
  return best;
}

LobeOptions App::CurrentLobeOptions(double theta_in_deg) const {
  LobeOptions o;
  o.theta_in_deg = std::clamp(theta_in_deg, 0.0, 89.0);
  o.channel = channel_;
  o.cosine_weighted = cosine_weighted_;
  o.scale = log_scale_ ? RadiusScale::kLog : RadiusScale::kLinear;
  o.log_floor = log_scale_ ? scale_max_ * 1e-3 : 0;
  return o;
}

// One colour scale and one arrow length for every θin, so moving the slider changes the lobe
// and not the legend: the largest value over the measured slices' lobes.
void App::RecomputeScale() {
  const ViewSource* source = Primary();
  const bool log_saved = log_scale_;
  log_scale_ = false;
  double max_value = 0;
  for (double theta : source->lut.theta_in_deg) {
    LobeOptions o = CurrentLobeOptions(theta);
    o.theta_rows = 45;
    o.phi_columns = 90;
    max_value = std::max(max_value, BuildLobe(*source, o).max_value);
  }
  log_scale_ = log_saved;
  scale_max_ = max_value > 0 ? max_value : 1.0;
}

void App::SetupColors(double lo, double hi, bool log_scale) {
  if (log_scale) {
    colors_->SetScaleToLog10();
    lo = std::max(lo, hi * 1e-3);
  } else {
    colors_->SetScaleToLinear();
  }
  if (!(hi > lo)) hi = lo + (lo > 0 ? lo : 1.0);
  colors_->SetTableRange(lo, hi);
  constexpr int kColors = 256;
  colors_->SetNumberOfTableValues(kColors);
  for (int n = 0; n < kColors; ++n) {
    const double x = 4.0 * n / (kColors - 1);
    const int k = std::min(3, static_cast<int>(x));
    const double f = x - k;
    colors_->SetTableValue(n, kViridis[k][0] * (1 - f) + kViridis[k + 1][0] * f,
                           kViridis[k][1] * (1 - f) + kViridis[k + 1][1] * f,
                           kViridis[k][2] * (1 - f) + kViridis[k + 1][2] * f, 1.0);
  }
  colors_->SetNanColor(0.75, 0.2, 0.75, 1.0);
  colors_->Build();
}

void App::ClearScene() {
  for (auto& prop : scene_) renderer_->RemoveViewProp(prop);
  scene_.clear();
  placements_.clear();
}

void App::AddLobe(const LobeMesh& mesh, bool primary, double opacity) {
  // One actor per coverage class: measured opaque, extrapolated translucent, unmeasured in
  // the flat "no data" colour.
  for (Coverage cls : {Coverage::kMeasured, Coverage::kExtrapolated, Coverage::kUnmeasured}) {
    vtkNew<vtkCellArray> cells;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (mesh.triangle_coverage[t] != cls) continue;
      const vtkIdType ids[3] = {mesh.triangles[t][0], mesh.triangles[t][1], mesh.triangles[t][2]};
      cells->InsertNextCell(3, ids);
    }
    if (cells->GetNumberOfCells() == 0) continue;
    vtkNew<vtkPoints> points;
    points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
    vtkNew<vtkFloatArray> values;
    values->SetName("value");
    values->SetNumberOfTuples(static_cast<vtkIdType>(mesh.points.size()));
    const double floor = log_scale_ ? scale_max_ * 1e-3 : 0.0;
    for (std::size_t n = 0; n < mesh.points.size(); ++n) {
      points->SetPoint(static_cast<vtkIdType>(n), mesh.points[n].x, mesh.points[n].y,
                       mesh.points[n].z);
      values->SetValue(static_cast<vtkIdType>(n),
                       static_cast<float>(std::max(mesh.values[n], floor)));
    }
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->SetPolys(cells);
    poly->GetPointData()->SetScalars(values);
    vtkNew<vtkPolyDataNormals> normals;
    normals->SetInputData(poly);
    normals->SplittingOff();
    normals->ConsistencyOff();
    normals->AutoOrientNormalsOff();
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(normals->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    vtkProperty* prop = actor->GetProperty();
    prop->SetAmbient(0.35);
    prop->SetDiffuse(0.65);
    prop->SetSpecular(0.1);
    prop->BackfaceCullingOff();
    if (!primary) {
      mapper->ScalarVisibilityOff();
      if (compare_wireframe_) {
        prop->SetRepresentationToWireframe();
        prop->SetColor(0.95, 0.95, 0.95);
        prop->SetOpacity(0.55);
        prop->SetAmbient(1.0);
        prop->SetDiffuse(0.0);
      } else {
        prop->SetColor(1.0, 0.45, 0.1);
        prop->SetOpacity(0.5);
      }
    } else if (cls == Coverage::kUnmeasured) {
      mapper->ScalarVisibilityOff();
      prop->SetColor(0.75, 0.2, 0.75);
      prop->SetOpacity(opacity);
    } else {
      mapper->SetLookupTable(colors_);
      mapper->UseLookupTableScalarRangeOn();
      mapper->SetScalarModeToUsePointData();
      // With a second source the first is see-through, or a smaller lobe inside it would vanish.
      const double see_through = Compare() ? 0.6 : 1.0;
      prop->SetOpacity((cls == Coverage::kExtrapolated ? 0.4 : 1.0) * opacity * see_through);
    }
    AddProp(actor);
  }
}

void App::AddArrow(const Vec3& direction, double length, const double color[3], double opacity) {
  vtkNew<vtkArrowSource> arrow;
  arrow->SetTipResolution(24);
  arrow->SetShaftResolution(12);
  arrow->SetShaftRadius(0.006);
  arrow->SetTipRadius(0.02);
  arrow->SetTipLength(0.06);
  // vtkArrowSource points along +x from 0 to 1: rotate +x onto `direction`, then scale.
  const Vec3 d = Normalize(direction);
  const Vec3 axis{0.0, -d.z, d.y};  // x × d
  const double axis_len = std::sqrt(Dot(axis, axis));
  const double angle_deg = RadToDeg(std::atan2(axis_len, d.x));
  vtkNew<vtkTransform> transform;
  if (axis_len > 1e-9) transform->RotateWXYZ(angle_deg, axis.x, axis.y, axis.z);
  transform->Scale(length, length, length);
  vtkNew<vtkTransformPolyDataFilter> filter;
  filter->SetTransform(transform);
  filter->SetInputConnection(arrow->GetOutputPort());
  // Point normals and a colour per point, like the lobe's meshes: VTK then draws arrows and
  // lobes with one shader program, one fewer for the OpenGL driver to compile before the first
  // frame (≈ 50 ms of CPU on a CPU rasteriser without a warm shader cache).
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputConnection(filter->GetOutputPort());
  normals->Update();
  vtkNew<vtkPolyData> poly;
  poly->ShallowCopy(normals->GetOutput());
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetNumberOfComponents(3);
  rgb->SetNumberOfTuples(poly->GetNumberOfPoints());
  for (int c = 0; c < 3; ++c) {
    rgb->FillComponent(c, std::round(255.0 * std::clamp(color[c], 0.0, 1.0)));
  }
  poly->GetPointData()->SetScalars(rgb);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(poly);
  mapper->SetColorModeToDirectScalars();
  mapper->SetScalarModeToUsePointData();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetAmbient(0.5);
  actor->GetProperty()->SetOpacity(opacity);
  AddProp(actor);
}

void App::BuildLobeScene(bool reset_camera) {
  const ViewSource* source = Primary();
  style_->pan_only = false;
  style_->orbit_preview = false;
  renderer_->GetActiveCamera()->ParallelProjectionOff();
  const LobeOptions options = CurrentLobeOptions(theta_in_deg_);
  const LobeMesh mesh = BuildLobe(*source, options);
  SetupColors(log_scale_ ? scale_max_ * 1e-3 : 0.0, scale_max_, log_scale_);
  if (all_slices_) {
    for (double theta : source->lut.theta_in_deg) {
      AddLobe(BuildLobe(*source, CurrentLobeOptions(theta)), true, 0.45);
    }
  } else {
    AddLobe(mesh, true, 1.0);
  }
  if (const ViewSource* other = Compare()) {
    AddLobe(BuildLobe(*other, options), false, 1.0);
  }
  constexpr double kWhite[3] = {0.95, 0.95, 0.95};
  constexpr double kOrange[3] = {1.0, 0.35, 0.2};
  constexpr double kCyan[3] = {0.1, 0.85, 1.0};
  // Arrows reach past the lobe drawn now (all slices: past the largest), so they never hide
  // inside it; the mirror arrow runs through a glossy lobe and is drawn translucent.
  const double lobe_radius = all_slices_ ? (log_scale_ ? 3.0 : scale_max_) : mesh.max_radius;
  arrow_length_ = 1.3 * std::max(lobe_radius, 1e-6);
  AddArrow(mesh.normal, arrow_length_, kWhite, 1.0);
  AddArrow(mesh.light, arrow_length_, kOrange, 1.0);
  AddArrow(mesh.mirror, arrow_length_, kCyan, 0.45);
  // The surface: a circle in the xz = 0 plane.
  vtkNew<vtkRegularPolygonSource> disk;
  disk->SetNumberOfSides(96);
  disk->SetRadius(arrow_length_);
  disk->GeneratePolygonOff();
  vtkNew<vtkPolyDataMapper> disk_mapper;
  disk_mapper->SetInputConnection(disk->GetOutputPort());
  vtkNew<vtkActor> disk_actor;
  disk_actor->SetMapper(disk_mapper);
  disk_actor->GetProperty()->SetColor(0.5, 0.5, 0.55);
  AddProp(disk_actor);

  legend_->SetLookupTable(colors_);
  legend_->SetTitle(cosine_weighted_ ? "f_r·cosθo (1/sr)" : "f_r (1/sr)");
  legend_->SetVisibility(1);
  if (reset_camera) {
    const double aspect = static_cast<double>(options_.width) / options_.height;
    const CameraSetup c = LobeCamera(mesh, arrow_length_, aspect);
    vtkCamera* camera = renderer_->GetActiveCamera();
    camera->SetPosition(c.position.x, c.position.y, c.position.z);
    camera->SetFocalPoint(c.focal_point.x, c.focal_point.y, c.focal_point.z);
    camera->SetViewUp(c.view_up.x, c.view_up.y, c.view_up.z);
    camera->SetViewAngle(c.view_angle_deg);
    camera->UseHorizontalViewAngleOff();
  }
  renderer_->ResetCameraClippingRange();
}

void App::BuildSlicesScene(bool reset_camera) {
  const ViewSource* source = Primary();
  style_->pan_only = true;
  style_->orbit_preview = false;
  std::vector<int> slices;
  if (all_slices_) {
    for (int k = 0; k < source->lut.slices(); ++k) slices.push_back(k);
  } else {
    slices.push_back(current_slice_);
  }
  std::vector<SliceImage> images;
  double hi = 0;
  for (int k : slices) {
    images.push_back(BuildSliceImage(*source, k, channel_));
    hi = std::max(hi, static_cast<double>(images.back().max_value));
  }
  SetupColors(0.0, hi, log_scale_);
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(slices.size()))));
  for (std::size_t n = 0; n < images.size(); ++n) {
    const SliceImage& img = images[n];
    const double x0 = static_cast<double>(n % columns) * (360.0 + kSliceGapX);
    const double y0 = -static_cast<double>(n / columns) * (180.0 + kSliceGapY);
    placements_.push_back({img.slice, x0, y0});
    vtkNew<vtkImageData> data;
    data->SetDimensions(img.width, img.height, 1);
    data->SetOrigin(x0, y0, 0);
    data->SetSpacing(1, 1, 1);
    data->AllocateScalars(VTK_FLOAT, 1);
    auto* dst = static_cast<float*>(data->GetScalarPointer());
    const float floor = log_scale_ ? static_cast<float>(hi * 1e-3) : 0.0f;
    for (int j = 0; j < img.height; ++j) {
      // Image row y = 180 − θd, so θd = 0 (the mirror direction) is at the top.
      const int y = img.height - 1 - j;
      for (int i = 0; i < img.width; ++i) {
        dst[static_cast<std::size_t>(y) * img.width + i] = std::max(img.At(i, j), floor);
      }
    }
    vtkNew<vtkImageMapToColors> map;
    map->SetInputData(data);
    map->SetLookupTable(colors_);
    map->SetOutputFormatToRGB();
    vtkNew<vtkImageActor> actor;
    actor->GetMapper()->SetInputConnection(map->GetOutputPort());
    actor->InterpolateOff();
    AddProp(actor);

    vtkNew<vtkAxisActor2D> phi_axis;
    phi_axis->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    phi_axis->GetPositionCoordinate()->SetValue(x0, y0 - 2, 0);
    phi_axis->GetPosition2Coordinate()->SetCoordinateSystemToWorld();
    phi_axis->GetPosition2Coordinate()->SetValue(x0 + 360, y0 - 2, 0);
    phi_axis->SetRange(0, 360);
    phi_axis->SetNumberOfLabels(5);
    phi_axis->AdjustLabelsOff();
    phi_axis->SetTitle("φd (°)");
    phi_axis->SetLabelFormat("%.0f");
    vtkNew<vtkAxisActor2D> theta_axis;
    theta_axis->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    theta_axis->GetPositionCoordinate()->SetValue(x0 - 2, y0 + 180, 0);
    theta_axis->GetPosition2Coordinate()->SetCoordinateSystemToWorld();
    theta_axis->GetPosition2Coordinate()->SetValue(x0 - 2, y0, 0);
    theta_axis->SetRange(0, 180);
    theta_axis->SetNumberOfLabels(5);
    theta_axis->AdjustLabelsOff();
    theta_axis->SetTitle("θd (°)");
    theta_axis->SetLabelFormat("%.0f");
    for (vtkAxisActor2D* axis : {phi_axis.Get(), theta_axis.Get()}) {
      axis->GetProperty()->SetColor(0.85, 0.85, 0.85);
      axis->SetFontFactor(0.9);
      axis->SetLabelFactor(0.8);
      Style(axis->GetTitleTextProperty(), 14, 0.9, 0.9, 0.9);
      Style(axis->GetLabelTextProperty(), 12, 0.9, 0.9, 0.9);
      AddProp(axis);
    }
    vtkNew<vtkTextActor> title;
    title->SetInput(("θin = " + Fixed(img.theta_in_deg, 0) + "°").c_str());
    title->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    title->GetPositionCoordinate()->SetValue(x0 + 150, y0 + 186, 0);
    Style(title->GetTextProperty(), 16, 1, 1, 1);
    AddProp(title);
  }
  legend_->SetLookupTable(colors_);
  legend_->SetTitle("f_r (1/sr)");
  legend_->SetVisibility(1);
  if (reset_camera) {
    vtkCamera* camera = renderer_->GetActiveCamera();
    camera->ParallelProjectionOn();
    camera->SetViewUp(0, 1, 0);
    const int rows = static_cast<int>((slices.size() + columns - 1) / columns);
    // The content box: θd labels and title to the left, θin title above, φd labels below.
    const double left = -110, right = columns * 360.0 + (columns - 1) * kSliceGapX;
    const double top = 180 + 40, bottom = -(rows - 1) * (180.0 + kSliceGapY) - 60;
    const double aspect = static_cast<double>(options_.width) / options_.height;
    // It fills 84 % of the width from 2 % (the legend sits in the right 12 %) and 82 % of the
    // height below the text lines at the top.
    const double scale = 0.5 * std::max((top - bottom) / 0.82, (right - left) / 0.84 / aspect);
    const double fx = left + scale * aspect * (1.0 - 0.04);
    const double fy = top - scale * (1.0 - 2 * 0.13);
    camera->SetFocalPoint(fx, fy, 0);
    camera->SetPosition(fx, fy, 1000);
    camera->SetParallelScale(scale);
  }
  renderer_->ResetCameraClippingRange();
}

void App::ShowPreviewImage() {
  const PreviewPanel::Image img = preview_->Current();
  if (!preview_image_) preview_image_ = vtkSmartPointer<vtkImageData>::New();
  preview_image_->SetDimensions(img.width, img.height, 1);
  preview_image_->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* dst = static_cast<unsigned char*>(preview_image_->GetScalarPointer());
  for (int y = 0; y < img.height; ++y) {
    // VTK images start at the bottom row.
    const unsigned char* src =
        &img.rgb8[static_cast<std::size_t>(img.height - 1 - y) * img.width * 3];
    std::copy(src, src + img.width * 3, dst + static_cast<std::size_t>(y) * img.width * 3);
  }
  preview_image_->Modified();
}

void App::BuildPreviewScene(bool reset_camera) {
  style_->pan_only = false;
  style_->orbit_preview = true;
  legend_->SetVisibility(0);
  if (!preview_) {
    preview_ = MakePreviewPanel(primary_.brdf, compare_ ? compare_->brdf : nullptr, options_.width,
                                options_.height);
  }
  if (!preview_) return;  // UpdateText says why
  preview_->Refine();
  ShowPreviewImage();
  vtkNew<vtkImageActor> actor;
  actor->GetMapper()->SetInputData(preview_image_);
  actor->InterpolateOff();
  AddProp(actor);
  if (reset_camera) {
    const PreviewPanel::Image img = preview_->Current();
    vtkCamera* camera = renderer_->GetActiveCamera();
    camera->ParallelProjectionOn();
    camera->SetViewUp(0, 1, 0);
    const double cx = (img.width - 1) / 2.0, cy = (img.height - 1) / 2.0;
    camera->SetFocalPoint(cx, cy, 0);
    camera->SetPosition(cx, cy, 1000);
    const double aspect = static_cast<double>(options_.width) / options_.height;
    // Room for the text lines above and the help line below.
    camera->SetParallelScale(0.5 * std::max(img.height / 0.8, img.width / aspect / 0.95));
    const double shift = 0.5 * std::max(img.height / 0.8, img.width / aspect / 0.95) * 0.06;
    camera->SetFocalPoint(cx, cy + shift, 0);
    camera->SetPosition(cx, cy + shift, 1000);
  }
  renderer_->ResetCameraClippingRange();
}

void App::Rebuild(bool reset_camera) {
  ClearScene();
  hover_text_.clear();
  if (Primary()) {
    try {
      switch (mode_) {
        case Mode::kLobe:
          BuildLobeScene(reset_camera);
          break;
        case Mode::kSlices:
          BuildSlicesScene(reset_camera);
          break;
        case Mode::kPreview:
          BuildPreviewScene(reset_camera);
          break;
      }
    } catch (const Error& e) {
      status_ = std::string("cannot draw: ") + e.what();
    }
    if (interactive_) {
      slider_->SetEnabled(mode_ != Mode::kPreview && Primary()->lut.slices() > 1 ? 1 : 0);
    }
    slider_rep_->SetValue(theta_in_deg_);
  } else {
    legend_->SetVisibility(0);
    if (interactive_) slider_->SetEnabled(0);
  }
  UpdateText();
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
      if (std::abs(lut.theta_in_deg[k] - theta_in_deg_) < 1e-6) {
        info << " (measured slice)";
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
    result.message = primary_.path + ": " + primary_.error;
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

}  // namespace

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
