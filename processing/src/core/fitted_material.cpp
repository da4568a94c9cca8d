// A fitted material and its report, to and from the material file (brdf/core/fitted_material.h).
#include "brdf/core/fitted_material.h"

#include <nlohmann/json.hpp>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/measurement.h"

namespace brdf {

namespace {

using Json = nlohmann::json;

// Reads the members of a report object, each checked for its type, naming the member in errors.
class ReportReader {
 public:
  ReportReader(const Json& fit, const std::string& file) : fit_(fit), file_(file) {}

  const Json* Find(const char* key, bool required) const {
    const auto it = fit_.find(key);
    if (it == fit_.end()) {
      if (required) Fail(key, "nothing (the member is missing)");
      return nullptr;
    }
    return &*it;
  }
  void Number(const char* key, double* out, bool required = false) const {
    if (const Json* v = Find(key, required)) *out = Checked(key, *v, v->is_number(), "a number");
  }
  template <class Int>
  void Count(const char* key, Int* out, const Json& in) const {
    const auto it = in.find(key);
    if (it == in.end()) return;
    if (!it->is_number_integer() || (it->is_number_integer() && it->template get<long long>() < 0))
      Fail(key, Kind(*it), "a whole number of at least 0");
    *out = it->template get<Int>();
  }
  template <class Int>
  void Count(const char* key, Int* out) const {
    Count(key, out, fit_);
  }
  void Bool(const char* key, bool* out) const {
    if (const Json* v = Find(key, false)) {
      if (!v->is_boolean()) Fail(key, Kind(*v), "true or false");
      *out = v->get<bool>();
    }
  }
  void Text(const char* key, std::string* out, bool required = false) const {
    if (const Json* v = Find(key, required)) {
      if (!v->is_string()) Fail(key, Kind(*v), "a string");
      *out = v->get<std::string>();
    }
  }
  [[noreturn]] void Fail(const std::string& key, const std::string& got,
                         const std::string& expected = "a member of the fit report") const {
    throw FormatError(file_, "member \"fit\".\"" + key + "\"", expected, got);
  }
  static std::string Kind(const Json& v) { return std::string("a ") + v.type_name(); }

 private:
  double Checked(const char* key, const Json& v, bool ok, const char* expected) const {
    if (!ok) Fail(key, Kind(v), expected);
    return v.get<double>();
  }
  const Json& fit_;
  const std::string& file_;
};

FitReport ReportFromJson(const Json& fit, const std::string& file, Model material_model) {
  if (!fit.is_object())
    throw FormatError(file, "member \"fit\"", "the fit report of `brdf fit` (an object)",
                      ReportReader::Kind(fit));
  const ReportReader in(fit, file);
  FitReport r;
  r.model = material_model;
  if (const Json* v = in.Find("model", false)) {
    if (!v->is_string()) in.Fail("model", ReportReader::Kind(*v), "a model name");
    bool known = false;
    for (Model m : AllModels())
      if (ModelName(m) == v->get<std::string>()) r.model = m, known = true;
    if (!known) {
      // Appended piece by piece: GCC 12's -Wrestrict misreads "'" + std::string&& at -O2.
      std::string quoted = "'";
      quoted += v->get<std::string>();
      quoted += '\'';
      in.Fail("model", quoted, "a model name");
    }
  }
  if (const Json* v = in.Find("loss", false)) {
    bool known = false;
    for (FitLoss l : {FitLoss::kNgan, FitLoss::kLog, FitLoss::kCbrt})
      if (v->is_string() && FitLossName(l) == v->get<std::string>()) r.loss = l, known = true;
    if (!known) in.Fail("loss", v->dump(), "ngan, log or cbrt");
  }
  in.Bool("robust", &r.robust);
  in.Number("robust_scale", &r.robust_scale);
  {
    const Json* v = in.Find("status", true);
    bool known = false;
    for (FitStatus s : {FitStatus::kConverged, FitStatus::kNoConvergence, FitStatus::kFailed,
                        FitStatus::kEvaluated})
      if (v->is_string() && FitStatusName(s) == v->get<std::string>()) r.status = s, known = true;
    if (!known) in.Fail("status", v->dump(), "converged, no-convergence, failed or evaluated");
  }
  in.Text("message", &r.message);
  in.Number("initial_cost", &r.initial_cost);
  in.Number("final_cost", &r.final_cost);
  in.Number("rmse", &r.rmse, true);
  in.Number("median_relative_error", &r.median_relative_error);
  if (const Json* v = in.Find("slices", false)) {
    if (!v->is_array()) in.Fail("slices", ReportReader::Kind(*v), "an array of slice errors");
    for (const Json& s : *v) {
      if (!s.is_object()) in.Fail("slices", ReportReader::Kind(s), "an array of slice errors");
      const ReportReader slice(s, file);
      SliceFitError e;
      slice.Number("theta_in_deg", &e.theta_in_deg);
      slice.Count("samples", &e.samples);
      slice.Number("rmse", &e.rmse);
      slice.Number("median_relative_error", &e.median_relative_error);
      r.slices.push_back(e);
    }
  }
  in.Count("iterations", &r.iterations);
  in.Count("starts", &r.starts);
  in.Number("seconds", &r.seconds);
  in.Count("samples_used", &r.samples_used);
  if (const Json* v = in.Find("excluded", false)) {
    if (!v->is_object()) in.Fail("excluded", ReportReader::Kind(*v), "an object of counts");
    in.Count("invalid", &r.excluded_invalid, *v);
    in.Count("saturated", &r.excluded_saturated, *v);
    in.Count("theta_out", &r.excluded_theta_out, *v);
  }
  in.Bool("representable", &r.representable);
  in.Number("chromaticity_error", &r.chromaticity_error);
  in.Number("hue_spread", &r.hue_spread);
  in.Bool("colour_shift", &r.colour_shift);
  if (const Json* v = in.Find("warnings", false)) {
    if (!v->is_array()) in.Fail("warnings", ReportReader::Kind(*v), "an array of strings");
    for (const Json& w : *v) {
      if (!w.is_string()) in.Fail("warnings", ReportReader::Kind(w), "an array of strings");
      r.warnings.push_back(w.get<std::string>());
    }
  }
  in.Text("software_version", &r.software_version);
  return r;
}

}  // namespace

std::string_view FitLossName(FitLoss loss) {
  switch (loss) {
    case FitLoss::kNgan:
      return "ngan";
    case FitLoss::kLog:
      return "log";
    case FitLoss::kCbrt:
      return "cbrt";
  }
  return "ngan";
}

FitLoss FitLossFromName(std::string_view name) {
  for (FitLoss l : {FitLoss::kNgan, FitLoss::kLog, FitLoss::kCbrt})
    if (FitLossName(l) == name) return l;
  throw InvalidArgument("unknown fit loss '" + std::string(name) + "' (known: ngan, log, cbrt)");
}

std::string_view FitStatusName(FitStatus status) {
  switch (status) {
    case FitStatus::kConverged:
      return "converged";
    case FitStatus::kNoConvergence:
      return "no-convergence";
    case FitStatus::kFailed:
      return "failed";
    case FitStatus::kEvaluated:
      return "evaluated";
  }
  return "failed";
}

std::string FitReportJson(const FitReport& report) {
  nlohmann::ordered_json j;
  j["model"] = std::string(ModelName(report.model));
  j["loss"] = std::string(FitLossName(report.loss));
  j["robust"] = report.robust;
  if (report.robust) j["robust_scale"] = report.robust_scale;
  j["status"] = std::string(FitStatusName(report.status));
  j["message"] = report.message;
  j["initial_cost"] = report.initial_cost;
  j["final_cost"] = report.final_cost;
  j["rmse"] = report.rmse;
  j["median_relative_error"] = report.median_relative_error;
  nlohmann::ordered_json slices = nlohmann::ordered_json::array();
  for (const SliceFitError& s : report.slices)
    slices.push_back({{"theta_in_deg", s.theta_in_deg},
                      {"samples", s.samples},
                      {"rmse", s.rmse},
                      {"median_relative_error", s.median_relative_error}});
  j["slices"] = slices;
  j["iterations"] = report.iterations;
  j["starts"] = report.starts;
  j["samples_used"] = report.samples_used;
  j["excluded"] = {{"invalid", report.excluded_invalid},
                   {"saturated", report.excluded_saturated},
                   {"theta_out", report.excluded_theta_out}};
  j["representable"] = report.representable;
  j["chromaticity_error"] = report.chromaticity_error;
  j["hue_spread"] = report.hue_spread;
  j["colour_shift"] = report.colour_shift;
  j["warnings"] = report.warnings;
  j["software_version"] =
      report.software_version.empty() ? std::string(SoftwareVersion()) : report.software_version;
  return j.dump();
}

std::string FittedMaterialToJson(const FittedMaterial& fitted) {
  Material m = fitted.material;
  Json extra = Json::parse(m.extra_json, nullptr, false);
  if (!extra.is_object()) extra = Json::object();
  extra["fit"] = Json::parse(FitReportJson(fitted.report));
  m.extra_json = extra.dump();
  return MaterialToJson(m);
}

FittedMaterial ParseFittedMaterialJson(std::string_view json_text, const std::string& file) {
  FittedMaterial out;
  out.material = ParseMaterialJson(json_text, file);
  Json extra = Json::parse(out.material.extra_json, nullptr, false);
  if (!extra.is_object() || !extra.contains("fit"))
    throw FormatError(file, "member \"fit\"", "the fit report of `brdf fit`", "none");
  out.report = ReportFromJson(extra["fit"], file, out.material.model);
  extra.erase("fit");
  out.material.extra_json = extra.dump();
  return out;
}

}  // namespace brdf
