// The second compiled part of the Python module `brdf`: brdf.fit, brdf.convert, brdf.preview
// and brdf.capture, each the library entry point the matching `brdf` command calls, with the
// command's defaults. It links Ceres, the previewer and the device stack, so brdf/__init__.py
// imports it on first use only (`import brdf` stays light); it imports _brdf first, whose
// exception translator (remedy.h) serves both.
//
//  - fit: sources::PrepareMeasurement then processing::FitMaterial per model, the result as the
//    material file `brdf fit` writes (FittedMaterialToJson; no wall time in it, so the same
//    input gives the same text). FitMaterial silences Ceres' glog once for the process.
//  - convert: sources::LutFromInput then exporter::ExportLut, the files of `brdf convert` for
//    one input (no engine hand-offs), each written atomically; a failure removes the outputs
//    this call created (the command's OutputGuard, tools/, also removes replaced ones).
//  - preview: sources::OpenBrdf then preview::RenderPreview, the linear image `brdf preview`
//    writes to an .exr.
//  - capture: the simulated instrument behind the in-process loopback link and
//    device::RunCaptureSession, the session `brdf capture --device sim` runs (crash-safe,
//    resumable, the same recorded settings: device::SimulatedCaptureSettings). Ctrl-C stops it
//    (KeyboardInterrupt), leaving a valid unfinished capture to resume.
//
// Long calls release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/fitted_material.h"
#include "brdf/core/models.h"
#include "brdf/core/parallel.h"
#include "brdf/device/capture_session.h"
#include "brdf/device/instrument_link.h"
#include "brdf/device/simulator.h"
#include "brdf/exporter/lut_export.h"
#include "brdf/fit/fit.h"
#include "brdf/preview/preview.h"
#include "brdf/processing/beyond.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/material_library.h"
#include "brdf/sources/open.h"

namespace py = pybind11;

namespace brdf::python {

namespace {

namespace fs = std::filesystem;

std::optional<processing::ExtrapolationParams> ExtrapolationArgument(const std::string& text) {
  if (text.empty()) return std::nullopt;
  try {
    return processing::ParseExtrapolation(text);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("extrapolate: ") + e.what());
  }
}

// The result of `brdf fit INPUT --model M --loss L --out FILE.json` as that file's text, and the
// lines the CLI prints on stderr while opening the input.
std::pair<std::string, std::vector<std::string>> Fit(const std::string& path_or_name,
                                                     const std::string& model_name,
                                                     const std::string& loss, bool robust,
                                                     double max_theta_out_deg, int starts,
                                                     int jobs) {
  if (starts < 1)
    throw InvalidArgument("starts: expected at least 1, got " + std::to_string(starts));
  if (jobs < 0)
    throw InvalidArgument("jobs: expected 0 (one thread per core) or a positive count, got " +
                          std::to_string(jobs));
  if (max_theta_out_deg < 0 || max_theta_out_deg > 90)
    throw InvalidArgument("max_theta_out: expected an angle in (0, 90] degrees, got " +
                          NumberText(max_theta_out_deg));
  processing::FitOptions options;
  try {
    options.model = ModelFromName(model_name);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("model: ") + e.what());
  }
  try {
    options.loss = processing::FitLossFromName(loss);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("loss: ") + e.what());
  }
  options.robust = robust;
  if (max_theta_out_deg > 0) options.max_theta_out_deg = max_theta_out_deg;
  options.starts = starts;
  options.threads = ResolveJobs(jobs);
  const std::string path = sources::ResolveSource(path_or_name);
  const py::gil_scoped_release release;
  sources::PreparedMeasurement prepared =
      sources::PrepareMeasurement(path, sources::DetectFileKind(path), std::nullopt);
  processing::FitResult r = processing::FitMaterial(prepared.measurement, options);
  r.material.name = sources::OutputNameOf(path);
  if (r.report.status == processing::FitStatus::kFailed)
    throw Error(path + ": the " + std::string(ModelName(options.model)) +
                " fit failed (the solver stopped before a result, or the error under loss '" +
                loss + "' is not a finite number on these samples)");
  return {FittedMaterialToJson(r), std::move(prepared.warnings)};
}

// `brdf convert INPUT --out OUT_DIR [--formats ...] [--extrapolate P,L] [--beyond ...]` for one
// capture or material file. Returns the paths written and the warnings the CLI prints.
std::pair<std::vector<std::string>, std::vector<std::string>> Convert(
    const std::string& path_or_name, const std::string& out_dir, const std::string& formats,
    const std::string& extrapolate, const std::string& beyond, int beyond_subdivide,
    const std::string& exr_type, const std::string& exr_compression, bool overwrite, int jobs) {
  if (jobs < 0)
    throw InvalidArgument("jobs: expected 0 (one thread per core) or a positive count, got " +
                          std::to_string(jobs));
  exporter::LutExportOptions export_options;
  try {
    export_options.formats = exporter::ParseExportFormats(formats);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("formats: ") + e.what());
  }
  export_options.jobs = ResolveJobs(jobs);
  // The command's defaults: float pixels, no compression (ExrOptions{} would compress).
  if (exr_type != "float" && exr_type != "half")
    throw InvalidArgument("exr_type: expected 'float' or 'half', got '" + exr_type + "'");
  if (exr_compression != "none" && exr_compression != "zip")
    throw InvalidArgument("exr_compression: expected 'none' or 'zip', got '" + exr_compression +
                          "'");
  export_options.exr = exporter::ExrOptions(
      exr_type == "half" ? exporter::ExrPixelType::kHalf : exporter::ExrPixelType::kFloat,
      exr_compression == "zip" ? exporter::ExrCompression::kZip : exporter::ExrCompression::kNone);
  const std::optional<processing::ExtrapolationParams> chosen = ExtrapolationArgument(extrapolate);
  processing::ResampleOptions resample = sources::DefaultResampleOptions();
  resample.parallel = ResolveJobs(jobs) > 1;
  if (!beyond.empty()) {
    try {
      resample.beyond.method = processing::ParseBeyondMethod(beyond);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("beyond: ") + e.what());
    }
  }
  if (beyond_subdivide > 0) resample.beyond.subdivisions = beyond_subdivide;
  resample.Validate();

  const std::string path = sources::ResolveSource(path_or_name);
  CheckRegularFile(path);
  const sources::FileKind kind = sources::DetectFileKind(path);
  if (kind != sources::FileKind::kCapture && kind != sources::FileKind::kMaterial)
    throw InvalidArgument(path + ": a " + sources::FileKindName(kind) +
                          "; convert reads captures (.bpc) and material files (.json)");
  const std::string name = sources::OutputNameOf(path);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (!fs::is_directory(out_dir))
    throw IoError(out_dir + ": cannot create the output folder" +
                  (ec ? ": " + ec.message() : std::string()));
  const std::vector<std::string> outputs =
      exporter::LutExportPaths(out_dir, name, export_options.formats);
  for (const std::string& out : outputs)
    if (fs::equivalent(out, path, ec))
      throw InvalidArgument(out + ": the output would overwrite the input; choose another folder");
  CheckWritableOutputs(outputs, overwrite);

  const py::gil_scoped_release release;
  sources::InputLut built = sources::LutFromInput(path, kind, chosen, resample);
  std::vector<std::string> warnings = std::move(built.warnings);
  if (auto note = sources::SaturationNote(path, built.saturated_samples))
    warnings.push_back(std::move(*note));
  exporter::TextureMetadata metadata;
  metadata.name = name;
  metadata.source = sources::RecordedSourceName(path);
  metadata.extrapolation = built.extrapolation;
  metadata.saturated_samples = built.saturated_samples;
  if (built.beyond) metadata.beyond_json = processing::BeyondReportJson(*built.beyond);
  // No partial set of outputs: on failure remove the files this call created (outputs that
  // existed before and were not replaced yet stay).
  std::set<std::string> existed;
  for (const std::string& out : outputs)
    if (fs::exists(out, ec)) existed.insert(out);
  try {
    return {exporter::ExportLut(out_dir, built.lut, std::move(metadata), export_options).written,
            std::move(warnings)};
  } catch (...) {
    for (const std::string& out : outputs)
      if (!existed.count(out)) fs::remove(out, ec);
    throw;
  }
}

preview::Estimator EstimatorFromName(const std::string& name) {
  if (name == "auto") return preview::Estimator::kAuto;
  if (name == "hierarchical") return preview::Estimator::kHierarchical;
  if (name == "mis") return preview::Estimator::kMis;
  if (name == "env") return preview::Estimator::kEnvironment;
  if (name == "brdf") return preview::Estimator::kBrdf;
  if (name == "quadrature") return preview::Estimator::kQuadrature;
  throw InvalidArgument(
      "estimator: expected auto, hierarchical, mis, env, brdf or quadrature, got '" + name + "'");
}

struct PreviewArguments {
  int size = 512;
  std::string env = "studio";
  bool env_given = false;
  double env_rotation_deg = 0;
  std::string mesh = "sphere";
  std::optional<std::pair<double, double>> light, view;
  double fov_deg = 0;
  std::string estimator = "auto";
  int spp = 64;
  bool spp_given = false;
  double rms = 0;
  int subdivisions = 2;
  std::uint64_t seed = 1;
  int jobs = 0;
  bool background = true;
  std::string extrapolate;
};

// The image `brdf preview SOURCE --out IMAGE.exr` writes, with the same options, as
// height × width × 3 float32 linear radiance (row 0 at the top), and the opening warnings.
std::pair<py::array_t<float>, std::vector<std::string>> Preview(const std::string& path_or_name,
                                                                const PreviewArguments& a) {
  if (a.size < 1 || a.size > 8192)
    throw InvalidArgument("size: expected 1 to 8192 pixels, got " + std::to_string(a.size));
  if (a.jobs < 0)
    throw InvalidArgument("jobs: expected 0 (one thread per core) or a positive count, got " +
                          std::to_string(a.jobs));
  preview::PreviewOptions options;
  options.width = options.height = a.size;
  options.estimator = EstimatorFromName(a.estimator);
  if (options.estimator == preview::Estimator::kAuto && (a.spp_given || a.rms > 0))
    options.estimator = preview::Estimator::kMis;  // a pass count or an error target
  options.quadrature_subdivisions = a.subdivisions;
  options.samples_per_pixel = a.spp;
  options.target_relative_rms = a.rms;
  options.jobs = a.jobs;
  options.seed = a.seed;
  options.environment_rotation_deg = a.env_rotation_deg;
  preview::Mesh mesh;
  preview::SelectShape(a.mesh, &mesh, &options);
  for (const auto& [value, which] : {std::pair{a.view, "view"}, std::pair{a.light, "light"}})
    if (value && !(value->first >= 0 && value->first <= 180 && std::isfinite(value->second)))
      throw InvalidArgument(std::string(which) +
                            ": expected (theta, phi) in degrees with theta in [0, 180], got (" +
                            NumberText(value->first) + ", " + NumberText(value->second) + ")");
  if (a.view) {
    options.camera.theta_deg = a.view->first;
    options.camera.phi_deg = a.view->second;
  }
  if (a.fov_deg > 0) {
    options.camera.projection = preview::Camera::Projection::kPerspective;
    options.camera.fov_deg = a.fov_deg;
  }
  if (a.light) {
    options.light = preview::DirectionalLight{a.light->first, a.light->second};
    // A direct-lighting picture: the map lights the object only when asked for.
    options.environment_lighting = a.env_given;
    options.show_background = a.env_given;
  }
  if (!a.background) options.show_background = false;
  const preview::EnvironmentMap map = preview::EnvironmentMap::FromName(a.env);
  sources::OpenOptions open_options;
  open_options.extrapolation = ExtrapolationArgument(a.extrapolate);
  sources::OpenedSource opened = sources::OpenBrdf(path_or_name, open_options);
  preview::PreviewImage image;
  {
    const py::gil_scoped_release release;
    image = preview::RenderPreview(*opened.brdf, map, options);
  }
  py::array_t<float> out({static_cast<py::ssize_t>(image.height),
                          static_cast<py::ssize_t>(image.width), py::ssize_t{3}});
  std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
  // The map's bad texels (NaN, ±Inf, negative) in the words `brdf preview` prints.
  if (!map.load_warning().empty()) opened.warnings.push_back(map.load_warning());
  return {std::move(out), std::move(opened.warnings)};
}

struct CaptureArguments {
  std::string material, out, sample, operator_notes;
  double noise = 1.0;
  std::uint64_t seed = 1;
  CaptureGeometry geometry = ReferenceGeometry();
  std::string exposure = "auto";  // as given (recorded); parsed by brdf/__init__.py:
  int exposure_mode = 0;          // 0 auto per row, 1 auto per slice, 2 fixed
  double exposure_ms = 0;
  bool resume = false, overwrite = false, calibrate = false;
};

// `brdf capture --device sim --material M --sample S --out FILE.bpc ...` (loopback link).
py::dict Capture(const CaptureArguments& a) {
  const std::string material_path = sources::ResolveSource(a.material);
  sources::OpenedSource opened = sources::OpenBrdf(material_path);
  std::shared_ptr<const BrdfSource> source = std::move(opened.brdf);
  device::SimulatorConfig config;
  config.sample = source;
  config.noise_level = a.noise;
  config.seed = a.seed;
  config.model.SetGeometry(a.geometry);
  const std::unique_ptr<device::InstrumentLink> link = device::OpenInstrumentLink(
      device::ParseDeviceSpec("sim"), config, device::SimLink::kLoopback, nullptr);

  device::CaptureRequest request;
  request.out_path = a.out;
  request.theta_in_deg = a.geometry.theta_in_deg;
  request.exposure = {a.exposure_mode == 0   ? device::ExposureMode::kAutoPerRow
                      : a.exposure_mode == 1 ? device::ExposureMode::kAutoPerSlice
                                             : device::ExposureMode::kFixed,
                      static_cast<float>(a.exposure_ms)};
  request.sample_name = a.sample;
  request.operator_notes = a.operator_notes;
  request.settings =
      device::SimulatedCaptureSettings("sim", source->Name(), config, a.geometry, a.exposure);
  request.notes["material_file"] = sources::RecordedSourceName(material_path);
  request.resume = a.resume;
  request.saved_values_refusal = sources::SavedValuesRefusal;
  request.force = a.overwrite;
  request.calibrate = a.calibrate;

  // Ctrl-C: while the session runs (on a worker thread, without the GIL) this thread checks
  // Python's signals every 20 ms; a KeyboardInterrupt sets `cancel`, the session stops after
  // the slice in progress (the file stays a valid unfinished capture) and is re-raised here.
  device::CancelSignal cancel;
  std::atomic<bool> done{false};
  bool interrupted_by_user = false;
  device::CaptureSessionResult r;
  std::exception_ptr error;
  {
    const py::gil_scoped_release release;
    std::thread session([&] {
      try {
        r = device::RunCaptureSession(request, link->transport(), {}, &cancel);
      } catch (...) {
        error = std::current_exception();
      }
      done.store(true);
    });
    while (!done.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      if (interrupted_by_user) continue;
      const py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {  // the exception stays set on this thread
        interrupted_by_user = true;
        cancel.Raise();
      }
    }
    session.join();
  }
  if (interrupted_by_user) throw py::error_already_set();  // KeyboardInterrupt
  if (error) std::rethrow_exception(error);
  using device::CaptureOutcome;
  if (r.outcome == CaptureOutcome::kRefused || r.outcome == CaptureOutcome::kFailed ||
      r.outcome == CaptureOutcome::kInterrupted) {
    std::string message = r.message;
    using device::NextStep;
    switch (r.next) {
      case NextStep::kResume:
        message += "; " + std::to_string(r.slices_saved) + " of " +
                   std::to_string(r.slices_planned) + " slices are saved in " + a.out +
                   "; call brdf.capture again with resume=True to capture the rest";
        break;
      case NextStep::kOverwrite:
        message += "; pass overwrite=True to start over";
        break;
      case NextStep::kAcceptInstrument:
        message +=
            "; connect the original instrument, or pass overwrite=True to resume on this one";
        break;
      case NextStep::kUseOriginalSettings:
        message += "; call it again with the original settings";
        break;
      case NextStep::kRepairSlices:
        message += "; run 'brdf repair " + a.out +
                   " --out FIXED.bpc' to drop the refused slices, then call brdf.capture(...) "
                   "with out='FIXED.bpc' and resume=True to measure them again";
        break;
      case NextStep::kRetry:
        message += "; nothing was saved; call it again";
        break;
      case NextStep::kNone:
        break;
    }
    throw Error(message);
  }
  py::dict out;
  out["path"] = a.out;
  out["finished"] = r.outcome == CaptureOutcome::kFinished;
  out["resumed"] = r.resumed;
  out["slices_planned"] = r.slices_planned;
  out["slices_saved"] = r.slices_saved;
  out["new_samples"] = r.new_samples;
  out["saturated"] = r.saturated;
  out["below_noise_floor"] = r.below_noise_floor;
  out["message"] = r.message;
  out["warnings"] = opened.warnings;
  return out;
}

}  // namespace

}  // namespace brdf::python

PYBIND11_MODULE(_brdf_tools, m) {
  using namespace brdf::python;
  m.doc() = "Compiled fit, convert, preview and capture of the brdf module (use `import brdf`).";
  py::module_::import("brdf._brdf");  // the exception types and their translator
  m.def("fit", &Fit);
  m.def("convert", &Convert);
  py::class_<PreviewArguments>(m, "PreviewArguments")
      .def(py::init<>())
      .def_readwrite("size", &PreviewArguments::size)
      .def_readwrite("env", &PreviewArguments::env)
      .def_readwrite("env_given", &PreviewArguments::env_given)
      .def_readwrite("env_rotation_deg", &PreviewArguments::env_rotation_deg)
      .def_readwrite("mesh", &PreviewArguments::mesh)
      .def_readwrite("light", &PreviewArguments::light)
      .def_readwrite("view", &PreviewArguments::view)
      .def_readwrite("fov_deg", &PreviewArguments::fov_deg)
      .def_readwrite("estimator", &PreviewArguments::estimator)
      .def_readwrite("spp", &PreviewArguments::spp)
      .def_readwrite("spp_given", &PreviewArguments::spp_given)
      .def_readwrite("rms", &PreviewArguments::rms)
      .def_readwrite("subdivisions", &PreviewArguments::subdivisions)
      .def_readwrite("seed", &PreviewArguments::seed)
      .def_readwrite("jobs", &PreviewArguments::jobs)
      .def_readwrite("background", &PreviewArguments::background)
      .def_readwrite("extrapolate", &PreviewArguments::extrapolate);
  m.def("preview", &Preview);
  py::class_<CaptureArguments>(m, "CaptureArguments")
      .def(py::init<>())
      .def_readwrite("material", &CaptureArguments::material)
      .def_readwrite("out", &CaptureArguments::out)
      .def_readwrite("sample", &CaptureArguments::sample)
      .def_readwrite("operator_notes", &CaptureArguments::operator_notes)
      .def_readwrite("noise", &CaptureArguments::noise)
      .def_readwrite("seed", &CaptureArguments::seed)
      .def_property(
          "theta_in_deg", [](const CaptureArguments& c) { return c.geometry.theta_in_deg; },
          [](CaptureArguments& c, std::vector<double> v) {
            c.geometry.theta_in_deg = std::move(v);
          })
      .def_property(
          "theta_out_max_deg",
          [](const CaptureArguments& c) { return c.geometry.theta_out_max_deg; },
          [](CaptureArguments& c, double v) { c.geometry.theta_out_max_deg = v; })
      .def_property(
          "theta_out_step_deg",
          [](const CaptureArguments& c) { return c.geometry.theta_out_step_deg; },
          [](CaptureArguments& c, double v) { c.geometry.theta_out_step_deg = v; })
      .def_property(
          "phi_out_step_deg", [](const CaptureArguments& c) { return c.geometry.phi_out_step_deg; },
          [](CaptureArguments& c, double v) { c.geometry.phi_out_step_deg = v; })
      .def_readwrite("exposure", &CaptureArguments::exposure)
      .def_readwrite("exposure_mode", &CaptureArguments::exposure_mode)
      .def_readwrite("exposure_ms", &CaptureArguments::exposure_ms)
      .def_readwrite("resume", &CaptureArguments::resume)
      .def_readwrite("overwrite", &CaptureArguments::overwrite)
      .def_readwrite("calibrate", &CaptureArguments::calibrate);
  m.def("capture", &Capture);
}
