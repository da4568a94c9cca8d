// The compiled part of the Python module `brdf` (python/brdf/__init__.py wraps it): a file or a
// library material opened by brdf::sources::OpenBrdf, evaluated for arrays of direction pairs.
//
// Bit-identical with `brdf eval --pairs`: eval_deg calls brdf::EvalAnglePairsDeg
// (brdf/core/eval_pairs.h: a LUT sampled in angle space, other sources at the directions of the
// angles), as tools/brdf/cmd_eval.cpp does, and checks the polar angles by the same rule
// ([0, 90] degrees, finite azimuths).
//
// Batches release the GIL and are shared out by brdf::ParallelChunks (brdf/core/parallel.h);
// BrdfSource::Eval is const and used concurrently by the previewer the same way.
//
// Errors: brdf::IoError becomes brdf.IoError (an OSError), brdf::FormatError and
// brdf::InvalidArgument brdf.FormatError / brdf.InvalidArgument (ValueErrors), any other
// brdf::Error brdf.Error (a RuntimeError); the message is the library's one line, the text
// after "brdf: error: " in what the CLI prints, followed by "; " and the remedy in the module's
// words when the error carries one (remedy.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cctype>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/eval_pairs.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/parallel.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/describe.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/material_library.h"
#include "brdf/sources/open.h"
#include "remedy.h"

namespace py = pybind11;

namespace brdf::python {

namespace {

// Below this many pairs a batch runs on the calling thread (starting threads costs more).
constexpr std::size_t kParallelThreshold = 16384;
constexpr std::size_t kChunk = 4096;

const char* EvaluationName(sources::Evaluation e) {
  switch (e) {
    case sources::Evaluation::kAnalytic:
      return "analytic";
    case sources::Evaluation::kMeasuredDatabase:
      return "measured_database";
    case sources::Evaluation::kResampledLut:
      return "resampled_lut";
    case sources::Evaluation::kExportedLut:
      return "exported_lut";
  }
  return "unknown";
}

// Runs f(i) for i in [0, n) without the GIL, on the library's threads for large batches:
// `jobs` threads (0: one per core, brdf::ResolveJobs), one below kParallelThreshold pairs.
template <class F>
void ForEachRange(std::size_t n, int jobs_option, F f) {
  if (jobs_option < 0)
    throw InvalidArgument("jobs: expected 0 (one thread per core) or a positive count, got " +
                          std::to_string(jobs_option));
  const py::gil_scoped_release release;
  const int jobs = n >= kParallelThreshold ? ResolveJobs(jobs_option) : 1;
  ParallelChunks(n, kChunk, jobs, nullptr, f);
}

template <class F>
void ForEachPair(std::size_t n, int jobs_option, F f) {
  ForEachRange(n, jobs_option, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) f(i);
  });
}

// An N×3 float64 array, C-contiguous (a copy only when the caller's array is strided).
py::array_t<double, py::array::c_style> VectorsArgument(const py::array& a, const char* name) {
  if (a.dtype().kind() != 'f' || a.itemsize() != 8)
    throw InvalidArgument(std::string(name) + ": expected an N×3 array of float64, got dtype " +
                          std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d)
      shape += (d ? ", " : "") + std::to_string(a.shape(d));
    if (a.ndim() == 1) shape += ",";
    shape += ")";
    throw InvalidArgument(std::string(name) + ": expected an N×3 array of float64, got shape " +
                          shape);
  }
  return py::array_t<double, py::array::c_style>::ensure(a);
}

class Source {
 public:
  explicit Source(const std::string& path_or_name)
      : path_(path_or_name), opened_(sources::OpenBrdf(path_or_name)) {}

  std::string path() const { return path_; }
  std::string name() const { return opened_.brdf->Name(); }
  std::string evaluation() const { return EvaluationName(opened_.evaluation); }
  std::vector<std::string> warnings() const { return opened_.warnings; }
  std::vector<double> measured_theta_in_deg() const { return opened_.measured_theta_in_deg; }

  // wi, wo: N×3 unit vectors (z = normal, wi towards the light). Returns N×3 f_r in 1/sr.
  py::array_t<double> Eval(const py::array& wi_arg, const py::array& wo_arg, int jobs) const {
    const auto wi = VectorsArgument(wi_arg, "wi");
    const auto wo = VectorsArgument(wo_arg, "wo");
    if (wi.shape(0) != wo.shape(0))
      throw InvalidArgument("wi, wo: expected the same number of directions, got " +
                            std::to_string(wi.shape(0)) + " and " + std::to_string(wo.shape(0)));
    const auto n = static_cast<std::size_t>(wi.shape(0));
    const double* a = wi.data();
    const double* b = wo.data();
    for (std::size_t i = 0; i < n; ++i)
      for (const auto& [v, which] : {std::pair{a + 3 * i, "wi"}, std::pair{b + 3 * i, "wo"}}) {
        const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(std::abs(len - 1.0) <= 1e-6))
          throw InvalidArgument(std::string(which) + "[" + std::to_string(i) +
                                "]: expected a unit vector, got length " + NumberText(len));
      }
    py::array_t<double> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
    double* f = out.mutable_data();
    const BrdfSource& brdf = *opened_.brdf;
    ForEachPair(n, jobs, [&](std::size_t i) {
      const Rgb r =
          brdf.Eval({a[3 * i], a[3 * i + 1], a[3 * i + 2]}, {b[3 * i], b[3 * i + 1], b[3 * i + 2]});
      f[3 * i] = r[0];
      f[3 * i + 1] = r[1];
      f[3 * i + 2] = r[2];
    });
    return out;
  }

  // Four 1-D float64 arrays of one length (brdf/__init__.py broadcasts); returns N×3.
  py::array_t<double> EvalDegFlat(const py::array_t<double, py::array::c_style>& ti,
                                  const py::array_t<double, py::array::c_style>& pi,
                                  const py::array_t<double, py::array::c_style>& to,
                                  const py::array_t<double, py::array::c_style>& po,
                                  int jobs) const {
    const auto n = static_cast<std::size_t>(ti.size());
    if (pi.size() != ti.size() || to.size() != ti.size() || po.size() != ti.size())
      throw InvalidArgument("eval_deg: the four angle arrays must have one length");
    const double *t_in = ti.data(), *p_in = pi.data(), *t_out = to.data(), *p_out = po.data();
    // The rule of `brdf eval` (cmd_eval.cpp): polar angles in [0, 90], finite azimuths.
    for (std::size_t i = 0; i < n; ++i) {
      for (const auto& [t, which] :
           {std::pair{t_in[i], "theta_in"}, std::pair{t_out[i], "theta_out"}})
        if (!(t >= 0.0 && t <= 90.0))
          throw InvalidArgument(std::string(which) + "[" + std::to_string(i) +
                                "]: polar angle must be in [0, 90] degrees, got " + NumberText(t));
      for (const auto& [p, which] : {std::pair{p_in[i], "phi_in"}, std::pair{p_out[i], "phi_out"}})
        if (!std::isfinite(p))
          throw InvalidArgument(std::string(which) + "[" + std::to_string(i) +
                                "]: azimuth must be finite, got " + NumberText(p));
    }
    py::array_t<double> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
    double* f = out.mutable_data();
    const BrdfSource& brdf = *opened_.brdf;
    ForEachRange(n, jobs, [&](std::size_t begin, std::size_t end) {
      EvalAnglePairsDeg(brdf, end - begin, t_in + begin, p_in + begin, t_out + begin, p_out + begin,
                        f + 3 * begin);
    });
    return out;
  }

 private:
  std::string path_;
  sources::OpenedSource opened_;
};

// A capture's samples as numpy arrays, read by the rule of `brdf export-csv`
// (sources::LoadCaptureForCopy: damage refused with its message, incomplete slices kept).
// The same steps as tools/brdf/cmd_export_csv.cpp, so the same file gives the same message:
// a library name resolved, the kind told by content, then the capture rule.
py::dict ReadCapture(const std::string& path_or_name) {
  const std::string path = sources::ResolveSource(path_or_name);
  const sources::FileKind kind = sources::DetectFileKind(path);
  if (kind != sources::FileKind::kCapture)
    throw InvalidArgument(path + ": a " + sources::FileKindName(kind) +
                          "; read_capture reads .bpc captures (bring other formats in with "
                          "`brdf import` first)");
  std::vector<std::string> warnings;
  const Measurement m = sources::LoadCaptureForCopy(path, &warnings);
  const auto n = static_cast<py::ssize_t>(m.SampleCount());
  py::array_t<float> t_in(n), p_in(n), t_out(n), p_out(n), rgb({n, py::ssize_t{3}}),
      sigma({n, py::ssize_t{3}});
  py::array_t<std::uint8_t> flags(n);
  py::array_t<std::int32_t> slice(n);
  float *ti = t_in.mutable_data(), *pi = p_in.mutable_data(), *to = t_out.mutable_data(),
        *po = p_out.mutable_data(), *c = rgb.mutable_data(), *e = sigma.mutable_data();
  std::uint8_t* fl = flags.mutable_data();
  std::int32_t* si = slice.mutable_data();
  py::list slices;
  std::size_t k = 0;
  for (std::size_t s = 0; s < m.slices.size(); ++s) {
    const Slice& sl = m.slices[s];
    py::dict d;
    d["theta_in_deg"] = sl.theta_in_deg;
    d["phi_in_deg"] = sl.phi_in_deg;
    d["has_sigma"] = sl.has_sigma;
    d["complete"] = sl.complete;
    d["samples"] = sl.samples.size();
    slices.append(d);
    for (const Sample& x : sl.samples) {
      ti[k] = x.theta_in_deg;
      pi[k] = x.phi_in_deg;
      to[k] = x.theta_out_deg;
      po[k] = x.phi_out_deg;
      for (int ch = 0; ch < 3; ++ch) {
        c[3 * k + ch] = x.rgb[ch];
        e[3 * k + ch] = x.sigma[ch];
      }
      fl[k] = x.flags;
      si[k] = static_cast<std::int32_t>(s);
      ++k;
    }
  }
  const Metadata& md = m.metadata;
  py::dict meta;
  meta["sample_name"] = md.sample_name;
  meta["instrument_model"] = md.instrument_model;
  meta["instrument_serial"] = md.instrument_serial;
  meta["firmware_version"] = md.firmware_version;
  meta["protocol_version"] = md.protocol_version;
  meta["calibration_reference"] = md.calibration_reference;
  meta["calibration_time"] = md.calibration_time;
  meta["capture_start"] = md.capture_start;
  meta["capture_end"] = md.capture_end;
  meta["operator_notes"] = md.operator_notes;
  meta["units"] = md.units;
  meta["software_version"] = md.software_version;
  meta["extra"] = md.extra;
  py::dict out;
  out["theta_in_deg"] = t_in;
  out["phi_in_deg"] = p_in;
  out["theta_out_deg"] = t_out;
  out["phi_out_deg"] = p_out;
  out["rgb"] = rgb;
  out["sigma"] = sigma;
  out["flags"] = flags;
  out["slice"] = slice;
  out["slices"] = slices;
  out["metadata"] = meta;
  out["warnings"] = warnings;
  return out;
}

// The metadata keys read_capture returns and write_capture takes ("extra" besides them).
struct MetadataField {
  const char* key;
  std::string Metadata::*member;
};
constexpr MetadataField kMetadataFields[] = {
    {"sample_name", &Metadata::sample_name},
    {"instrument_model", &Metadata::instrument_model},
    {"instrument_serial", &Metadata::instrument_serial},
    {"firmware_version", &Metadata::firmware_version},
    {"protocol_version", &Metadata::protocol_version},
    {"calibration_reference", &Metadata::calibration_reference},
    {"calibration_time", &Metadata::calibration_time},
    {"capture_start", &Metadata::capture_start},
    {"capture_end", &Metadata::capture_end},
    {"operator_notes", &Metadata::operator_notes},
    {"units", &Metadata::units},
    {"software_version", &Metadata::software_version},
};

std::string MetadataKeyList() {
  std::string out;
  for (const MetadataField& f : kMetadataFields) out += std::string(f.key) + ", ";
  return out + "extra";
}

// The metadata dict of write_capture (the keys read_capture returns; all optional).
Metadata MetadataFromDict(const py::dict& d) {
  Metadata m;
  for (const auto& [key_handle, value] : d) {
    if (!py::isinstance<py::str>(key_handle))
      throw InvalidArgument("metadata: expected text keys, got " +
                            std::string(py::str(py::repr(key_handle))));
    const std::string key = key_handle.cast<std::string>();
    if (key == "extra") {
      if (!py::isinstance<py::dict>(value))
        throw InvalidArgument("metadata['extra']: expected a dict of text values, got " +
                              std::string(py::str(value.get_type().attr("__name__"))));
      for (const auto& [k, v] : value.cast<py::dict>()) {
        if (!py::isinstance<py::str>(k) || !py::isinstance<py::str>(v))
          throw InvalidArgument("metadata['extra']: expected text keys and values, got " +
                                std::string(py::str(py::repr(k))) + ": " +
                                std::string(py::str(py::repr(v))));
        m.extra[k.cast<std::string>()] = v.cast<std::string>();
      }
      continue;
    }
    const MetadataField* field = nullptr;
    for (const MetadataField& f : kMetadataFields)
      if (key == f.key) field = &f;
    if (field == nullptr)
      throw InvalidArgument("metadata: unknown key '" + key + "' (expected " + MetadataKeyList() +
                            ")");
    if (!py::isinstance<py::str>(value))
      throw InvalidArgument("metadata['" + key + "']: expected text, got " +
                            std::string(py::str(value.get_type().attr("__name__"))));
    m.*(field->member) = value.cast<std::string>();
  }
  return m;
}

using FloatArray = py::array_t<float, py::array::c_style>;

// A capture from arrays (brdf/__init__.py checked shapes and converted dtypes): consecutive
// samples of one light direction (θin, φin) form one slice, in the order given. Written as
// every whole-file writer writes (brdf::WriteBpc: a temporary sibling, fsync, rename), after
// the overwrite rule of every writing command (CheckWritableOutput). Returns the slice count.
std::size_t WriteCapture(const std::string& path, const FloatArray& ti, const FloatArray& pi,
                         const FloatArray& to, const FloatArray& po, const FloatArray& rgb,
                         const std::optional<FloatArray>& sigma,
                         const py::array_t<std::uint8_t, py::array::c_style>& flags,
                         const py::dict& metadata, bool overwrite) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".bpc")
    throw InvalidArgument(path + ": a capture is written as a .bpc file (the extension .bpc)");
  Measurement m;
  m.metadata = MetadataFromDict(metadata);
  if (m.metadata.software_version.empty()) m.metadata.software_version = SoftwareVersion();
  const auto n = static_cast<std::size_t>(ti.size());
  const float *t_in = ti.data(), *p_in = pi.data(), *t_out = to.data(), *p_out = po.data();
  const float* c = rgb.data();
  const float* e = sigma ? sigma->data() : nullptr;
  const std::uint8_t* fl = flags.data();
  for (std::size_t i = 0; i < n; ++i) {
    const auto bad = [&](const char* name, const char* rule, float v) {
      return InvalidArgument(std::string(name) + "[" + std::to_string(i) + "]: expected " + rule +
                             ", got " + NumberText(v));
    };
    if (!(t_in[i] >= 0 && t_in[i] < 90))
      throw bad("theta_in", "a light polar angle in [0, 90) degrees", t_in[i]);
    if (!(t_out[i] >= 0 && t_out[i] <= 90))
      throw bad("theta_out", "a polar angle in [0, 90] degrees", t_out[i]);
    if (!std::isfinite(p_in[i])) throw bad("phi_in", "a finite azimuth in degrees", p_in[i]);
    if (!std::isfinite(p_out[i])) throw bad("phi_out", "a finite azimuth in degrees", p_out[i]);
    if ((fl[i] & ~kKnownSampleFlags) != 0)
      throw InvalidArgument("flags[" + std::to_string(i) +
                            "]: expected bits 0-3 only (saturated 1, below noise floor 2, "
                            "interpolated 4, invalid 8), got " +
                            std::to_string(fl[i]));
    if (m.slices.empty() || m.slices.back().theta_in_deg != t_in[i] ||
        m.slices.back().phi_in_deg != p_in[i]) {
      Slice s;
      s.theta_in_deg = t_in[i];
      s.phi_in_deg = p_in[i];
      s.has_sigma = e != nullptr;
      m.slices.push_back(std::move(s));
    }
    Sample x;
    x.theta_in_deg = t_in[i];
    x.phi_in_deg = p_in[i];
    x.theta_out_deg = t_out[i];
    x.phi_out_deg = p_out[i];
    for (int ch = 0; ch < 3; ++ch) {
      x.rgb[ch] = c[3 * i + ch];
      x.sigma[ch] = e ? e[3 * i + ch] : 0.0f;
    }
    x.flags = fl[i];
    m.slices.back().samples.push_back(x);
  }
  CheckWritableOutput(path, overwrite);
  {
    const py::gil_scoped_release release;
    WriteBpc(path, m);
  }
  return m.slices.size();
}

// The JSON text of `brdf info --json` for the same file (sources::DescribeFile), remedies in the
// module's words; brdf/__init__.py parses it.
std::string Describe(const std::string& path_or_name) {
  const std::string path = sources::ResolveSource(path_or_name);
  return sources::DescribeFile(path, [](const Remedy& r) { return PythonRemedyText(r); });
}

}  // namespace

}  // namespace brdf::python

PYBIND11_MODULE(_brdf, m) {
  using brdf::python::Source;
  m.doc() = "Compiled core of the brdf module (use `import brdf`).";
  brdf::python::RegisterExceptions(m);

  m.def("read_capture", &brdf::python::ReadCapture, py::arg("path"));
  m.def("describe", &brdf::python::Describe, py::arg("path_or_name"));
  m.def("write_capture", &brdf::python::WriteCapture, py::arg("path"), py::arg("theta_in"),
        py::arg("phi_in"), py::arg("theta_out"), py::arg("phi_out"), py::arg("rgb"),
        py::arg("sigma"), py::arg("flags"), py::arg("metadata"), py::arg("overwrite"));

  py::class_<Source>(m, "Source")
      .def(py::init<const std::string&>(), py::arg("path_or_name"))
      .def_property_readonly("path", &Source::path)
      .def_property_readonly("name", &Source::name)
      .def_property_readonly("evaluation", &Source::evaluation)
      .def_property_readonly("warnings", &Source::warnings)
      .def_property_readonly("measured_theta_in_deg", &Source::measured_theta_in_deg)
      .def("eval", &Source::Eval, py::arg("wi"), py::arg("wo"), py::arg("jobs") = 0)
      .def("_eval_deg_flat", &Source::EvalDegFlat, py::arg("theta_in"), py::arg("phi_in"),
           py::arg("theta_out"), py::arg("phi_out"), py::arg("jobs") = 0);
}
