// The fit report as the JSON object a material file carries under "fit" (brdf/fit/fit.h).
#include <nlohmann/json.hpp>

#include "brdf/core/models.h"
#include "brdf/fit/fit.h"

namespace brdf::processing {

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
  j["seconds"] = report.seconds;
  j["samples_used"] = report.samples_used;
  j["excluded"] = {{"invalid", report.excluded_invalid},
                   {"saturated", report.excluded_saturated},
                   {"theta_out", report.excluded_theta_out}};
  j["representable"] = report.representable;
  j["chromaticity_error"] = report.chromaticity_error;
  j["hue_spread"] = report.hue_spread;
  j["colour_shift"] = report.colour_shift;
  j["warnings"] = report.warnings;
  j["software_version"] = SoftwareVersion();
  return j.dump();
}

}  // namespace brdf::processing
