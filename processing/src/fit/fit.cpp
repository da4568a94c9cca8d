// FitMaterial and EvaluateFit (brdf/fit/fit.h explains the method): options checked, the
// samples prepared (fit_data.cpp), the model's multi-start run (kernel_fit.h) and the report.
#include "brdf/fit/fit.h"

#include <glog/logging.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>

#include "brdf/core/error.h"
#include "fit_data.h"
#include "loss.h"
#include "search.h"

namespace brdf::processing {

namespace {

using Clock = std::chrono::steady_clock;

std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

// Ceres reports through glog, whose lines ("Logging before InitGoogleLogging()", "E...
// trust_region_minimizer.cc:71] Terminating: ...") are a library's diary, not a message for the
// user: the outcome is in the report. glog is initialised once (unless the host program did) and
// only fatal messages pass; a host that wants Ceres' log sets FLAGS_minloglevel after fitting.
void SilenceSolverLogging() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("brdf");
    FLAGS_logtostderr = false;
    FLAGS_minloglevel = google::GLOG_FATAL;
    FLAGS_stderrthreshold = google::GLOG_FATAL;
  });
}

}  // namespace

FitReport EvaluateFit(const Measurement& measurement, const Material& material,
                      const FitOptions& options) {
  const FitData data = PrepareFitData(measurement, options);
  FitReport report;
  report.model = material.model;
  report.loss = options.loss;
  report.robust = options.robust;
  report.status = FitStatus::kEvaluated;
  report.software_version = SoftwareVersion();
  report.robust_scale = options.robust ? detail::RobustScale(data.samples, material, options) : 0.0;
  report.final_cost = report.initial_cost =
      detail::Cost(data.samples, material, options.loss, report.robust_scale);
  FillErrors(data, material, &report);
  return report;
}

FitResult FitMaterial(const Measurement& measurement, const FitOptions& options) {
  const auto t0 = Clock::now();
  SilenceSolverLogging();
  if (options.starts < 1)
    throw InvalidArgument("fit: the number of starts must be at least 1, got " +
                          std::to_string(options.starts));
  if (options.threads < 1)
    throw InvalidArgument("fit: the number of threads must be at least 1, got " +
                          std::to_string(options.threads));
  if (options.max_iterations < 1)
    throw InvalidArgument("fit: the iteration limit must be at least 1");
  if (options.start && options.start->model != options.model)
    throw InvalidArgument("fit: the start is a " + std::string(ModelName(options.start->model)) +
                          " material, the fit is of " + std::string(ModelName(options.model)));
  const FitData data = PrepareFitData(measurement, options);
  const Model model = options.model;

  detail::Search search = models::ChannelsIndependent(model)
                              ? detail::RunLegacyModelFit(data, options)
                              : detail::RunEngineModelFit(data, options);
  const std::optional<detail::Refinement>& best = search.best;
  FitReport report;
  report.model = model;
  report.loss = options.loss;
  report.robust = options.robust;
  report.robust_scale = search.robust_scale;
  report.iterations = search.iterations;
  report.starts = search.starts;
  report.status = best->termination == ceres::CONVERGENCE      ? FitStatus::kConverged
                  : best->termination == ceres::NO_CONVERGENCE ? FitStatus::kNoConvergence
                                                               : FitStatus::kFailed;
  report.message = best->message;
  report.initial_cost = best->initial_cost;
  report.final_cost = best->final_cost;
  FillErrors(data, best->material, &report);

  // Parameters pinned at a bound the model's range does not want to stop at.
  const ModelInfo& info = DescribeModel(model);
  if (info.shape_parameter >= 0) {
    const ParameterInfo& p = info.parameters[static_cast<std::size_t>(info.shape_parameter)];
    for (int c = 0; c < p.Count(); ++c) {
      const double v = best->material.values[static_cast<std::size_t>(p.offset + c)];
      if (p.log_scale && (v <= p.min * 1.0001 || v >= p.max * 0.9999))
        report.warnings.push_back(std::string(p.name) + " ended at the end of its range (" +
                                  Format("%g", v) + "): the lobe is outside what the model spans");
    }
  }
  report.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  report.software_version = SoftwareVersion();

  FitResult result;
  result.material = best->material;
  result.material.name = measurement.metadata.sample_name;
  result.material.description =
      "fit of " + std::string(ModelName(model)) + " to " + measurement.metadata.sample_name;
  result.report = std::move(report);
  return result;
}

}  // namespace brdf::processing
