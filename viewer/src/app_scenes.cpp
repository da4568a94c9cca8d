// The scenes of the brdf-view window (app_window.h): the lobe with its arrows, the slice heat
// maps with their axes, and the preview image; one colour scale per source.
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

}  // namespace brdf::viewer::detail
