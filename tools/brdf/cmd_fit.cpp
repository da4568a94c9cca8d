// `brdf fit INPUT... --model M|all --out OUT [--loss ...] [--robust] [--max-theta-out DEG]
// [--starts N] [--jobs N]`: every input becomes a measurement (captures through the LUT rule
// for damaged files, material files captured noise-free on the reference geometry, RGL and MERL
// files and exported LUTs captured virtually as `brdf import` does, third-party tables
// imported: sources::PrepareMeasurement), processing::FitMaterial fits each model, and
// the result is written as a material file with the report under "fit". A comparison table
// (model, RMSE per θin slice and overall, median relative error, seconds, and for engine models
// what to type where) goes to stdout; progress and skipped inputs to stderr.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "batch.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/importers.h"
#include "brdf/fit/fit.h"
#include "brdf/fit/result_files.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"
#include "fit_support.h"
#include "progress.h"

namespace brdf::cli {

namespace fs = std::filesystem;

namespace {

struct FitInput {
  std::string path;
  std::string name;
};

// The kind of `path` by content (sources::DetectFileKind), kUnknown when it cannot be read or
// classified (the convert rules then report it).
sources::FileKind KindOf(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return sources::FileKind::kUnknown;
  try {
    return sources::DetectFileKind(path);
  } catch (const Error&) {
    return sources::FileKind::kUnknown;
  }
}

// Measured BRDF files a folder contributes besides its captures and material files.
bool IsMeasuredBrdf(sources::FileKind kind) {
  using sources::FileKind;
  return kind == FileKind::kRgl || kind == FileKind::kMerl || kind == FileKind::kZemax ||
         kind == FileKind::kLightTools;
}

// A file named on the command line that is fitted as it is, not through the convert rules:
// measured databases, imported tables and exported LUTs (sources::PrepareMeasurement).
bool IsDirectInput(const std::string& path) {
  using sources::FileKind;
  const FileKind kind = KindOf(path);
  return IsMeasuredBrdf(kind) || kind == FileKind::kCsv || kind == FileKind::kGonio ||
         kind == FileKind::kKtx2 || kind == FileKind::kDds || kind == FileKind::kSidecar;
}

Measurement OpenForFit(const std::string& path, std::vector<std::string>* warnings) {
  const sources::FileKind kind = sources::DetectFileKind(path);
  // Transmission (BTDF) tables are read mirrored into the reflection hemisphere, with a
  // warning, as info, eval, preview and brdf-view read them (docs/robustness.md, "One verdict").
  sources::PreparedMeasurement p =
      sources::PrepareMeasurement(path, kind, std::nullopt, /*allow_btdf=*/true);
  for (std::string& w : p.warnings) warnings->push_back(std::move(w));
  return std::move(p.measurement);
}

std::string SliceErrors(const processing::FitReport& r) {
  std::string out;
  char buf[64];
  for (const processing::SliceFitError& s : r.slices) {
    std::snprintf(buf, sizeof buf, "%s%g:%.3g", out.empty() ? "" : " ", s.theta_in_deg, s.rmse);
    out += buf;
  }
  return out;
}

// Why a fit failed, in the user's terms (the solver's own sentence names its internals).
std::string FailedFitReason(const processing::FitReport& r, Model m) {
  const std::string model(ModelName(m));
  const std::string loss(FitLossName(r.loss));
  if (r.message.find("evaluation failed") != std::string::npos)
    return "the " + model + " fit failed: its error under --loss " + loss +
           " is not a finite number on these samples (a value no surface has, e.g. a negative "
           "or enormous f_r?); no material file written";
  return "the " + model +
         " fit failed (the solver stopped before a result); no material file "
         "written";
}

}  // namespace

std::optional<AutoExtrapolationChoice> AutoExtrapolationFor(const std::string& path,
                                                            sources::FileKind kind) {
  if (kind != sources::FileKind::kCapture && kind != sources::FileKind::kMaterial)
    return std::nullopt;
  const sources::PreparedMeasurement p = sources::PrepareMeasurement(path, kind, std::nullopt);
  // The input's own choice (a .extrapolate.json beside it, a material's "extrapolate") comes
  // before the command line's, so there is nothing to fit and nothing to record.
  if (p.extrapolation.origin != sources::ExtrapolationChoice::Origin::kDefaults)
    return std::nullopt;
  const processing::AutoExtrapolationResult r = processing::ChooseExtrapolationAuto(p.measurement);
  return AutoExtrapolationChoice{
      r.params, processing::AutoExtrapolationJson(r),
      r.not_used.empty() ? std::string() : path + ": warning: --extrapolate auto: " + r.not_used};
}

int RunFit(const FitCommandOptions& options) {
  if (options.out.empty()) throw InvalidArgument("--out: an output file or folder is required");
  if (options.jobs < 1)
    throw InvalidArgument("--jobs: expected at least 1, got " + std::to_string(options.jobs));
  if (options.starts < 1)
    throw InvalidArgument("--starts: expected at least 1, got " + std::to_string(options.starts));
  if (options.max_theta_out_deg < 0 || options.max_theta_out_deg > 90)
    throw InvalidArgument("--max-theta-out: expected an angle in (0, 90] degrees, got " +
                          NumberText(options.max_theta_out_deg));
  std::vector<Model> models;
  if (options.model == "all") {
    for (Model m : AllModels()) models.push_back(m);
  } else {
    models.push_back(ModelFromName(options.model));
  }
  processing::FitOptions fit;
  fit.loss = processing::FitLossFromName(options.loss);
  fit.robust = options.robust;
  if (options.max_theta_out_deg > 0) fit.max_theta_out_deg = options.max_theta_out_deg;
  fit.starts = options.starts;

  // Inputs: measured BRDF files (RGL, MERL, Zemax, LightTools; by content) directly or from
  // folders, tables and exported LUTs directly, everything else through the convert rules
  // (captures and material files).
  std::vector<FitInput> inputs;
  std::vector<BatchFailure> failures;
  std::vector<std::string> rest;
  for (const std::string& arg : options.inputs) {
    std::error_code ec;
    if (fs::is_directory(arg, ec)) {
      std::vector<std::string> evaluable;
      for (const auto& e : fs::directory_iterator(arg, ec))
        if (e.is_regular_file() && IsMeasuredBrdf(KindOf(e.path().string())))
          evaluable.push_back(e.path().string());
      std::sort(evaluable.begin(), evaluable.end());
      for (const std::string& f : evaluable) inputs.push_back({f, sources::OutputNameOf(f)});
      rest.push_back(arg);
    } else if (IsDirectInput(arg)) {
      inputs.push_back({arg, sources::OutputNameOf(arg)});
    } else {
      rest.push_back(arg);
    }
  }
  if (!rest.empty()) {
    DiscoveredInputs found = DiscoverInputs(rest);
    for (const BatchInput& in : found.inputs) inputs.push_back({in.path, in.name});
    for (const BatchFailure& f : found.failures) {
      // A folder holding only measured BRDF files is not a failure here.
      std::error_code ec;
      if (!fs::is_directory(f.path, ec)) failures.push_back(f);
    }
  }
  if (inputs.empty() && failures.empty()) {
    throw InvalidArgument("no captures, material files or measured BRDF files found in " +
                          JoinArguments(options.inputs));
  }

  // Inputs of one name (a/red.bpc, b/red.bpc) would write each other's results into a --out
  // folder: both fail before any fit, as `brdf convert` refuses them.
  if (inputs.size() > 1) {
    std::map<std::string, std::vector<std::size_t>> by_name;
    for (std::size_t i = 0; i < inputs.size(); ++i) by_name[inputs[i].name].push_back(i);
    std::vector<FitInput> kept;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const std::vector<std::size_t>& same = by_name[inputs[i].name];
      if (same.size() < 2) {
        kept.push_back(inputs[i]);
        continue;
      }
      std::string others;
      for (std::size_t o : same)
        if (o != i) others += (others.empty() ? "" : ", ") + inputs[o].path;
      failures.push_back(
          {inputs[i].path, "its results " +
                               (fs::path(options.out) / (inputs[i].name + ".*.json")).string() +
                               " would also be written for " + others + "; rename one of them"});
    }
    inputs = std::move(kept);
  }

  // Output names (brdf/fit/result_files.h): one input and one model write --out itself.
  const processing::FitResultFiles files{
      options.out, inputs.size() == 1 && failures.empty() && models.size() == 1,
      inputs.size() == 1};
  auto output_of = [&](const FitInput& in, Model m) { return files.PathOf(in.name, m); };
  // The overwrite rule of every writing command, on exactly the files the fits will write,
  // before any fit runs.
  {
    std::vector<std::string> names;
    for (const FitInput& in : inputs) names.push_back(in.name);
    const std::vector<std::string> outputs = files.Paths(names, models);
    if (files.single) {
      // fit creates the output's folder (CreateOutputFolder below), so a missing one is fine.
      CheckOutputPath(options.out, inputs.front().path, ".json", options.force, "--out",
                      /*folders_created=*/true);
    } else {
      std::set<std::string> input_paths;
      for (const FitInput& in : inputs) input_paths.insert(Identity(in.path));
      for (const FitInput& in : inputs)
        for (Model m : models)
          if (input_paths.count(Identity(output_of(in, m))))
            throw InvalidArgument(output_of(in, m) + ": the result of " + in.path +
                                  " would overwrite an input; choose another --out");
      ReportRemovedTemporaries(
          CheckWritableOutputs(outputs, options.force, /*folders_created=*/true));
    }
  }
  // The folder the results go to exists before any fit runs (the parent of a .json --out).
  CreateOutputFolder(files.Folder());

  for (const BatchFailure& f : failures)
    std::fprintf(stderr, "%s: FAILED: %s\n", f.path.c_str(), f.reason.c_str());
  // One step per input and model, as `brdf convert` shows its inputs (bar and ETA on a terminal,
  // a line per fit otherwise); one fit of one input needs none.
  Progress progress("fit", inputs.size() * models.size(),
                    !options.quiet && (inputs.size() > 1 || models.size() > 1));
  // Inputs in parallel when there are several; Ceres' threads for a single input.
  fit.threads = inputs.size() == 1 ? options.jobs : 1;
  std::vector<std::vector<processing::FitResult>> results(inputs.size());
  const std::vector<JobResult> jobs = RunJobs(
      inputs.size(), inputs.size() == 1 ? 1 : options.jobs,
      [&](std::size_t i, JobResult& job) {
        const Measurement meas = OpenForFit(inputs[i].path, &job.warnings);
        for (Model m : models) {
          processing::FitOptions o = fit;
          o.model = m;
          processing::FitResult r = processing::FitMaterial(meas, o);
          r.material.name = inputs[i].name;
          // A failed fit is no material: nothing is written, the input counts as failed.
          if (r.report.status == processing::FitStatus::kFailed)
            throw Error(FailedFitReason(r.report, m));
          WriteFileAtomically(output_of(inputs[i], m), FittedMaterialToJson(r));
          char done[96];
          std::snprintf(done, sizeof done, " %s (%s, %.2f s)", std::string(ModelName(m)).c_str(),
                        std::string(processing::FitStatusName(r.report.status)).c_str(),
                        r.report.seconds);
          results[i].push_back(std::move(r));
          progress.Advance(inputs[i].path + done);
        }
      },
      [&](std::size_t i, const JobResult& job) {
        for (const std::string& w : job.warnings) progress.Message(w);
        if (!job.ok) {
          progress.Message(inputs[i].path +
                           ": FAILED: " + ReasonWithoutPath(inputs[i].path, job.error));
          if (results[i].size() < models.size()) {
            progress.Advance(inputs[i].path, true);
            progress.Drop(models.size() - results[i].size() - 1);
          }
        }
      });
  progress.Finish();

  const std::size_t total = inputs.size() + failures.size();
  std::size_t fitted = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (!jobs[i].ok) {
      failures.push_back({inputs[i].path, ReasonWithoutPath(inputs[i].path, jobs[i].error)});
      continue;
    }
    ++fitted;
    std::printf("%s\n", inputs[i].path.c_str());
    // The per-slice column as wide as its widest entry, so the columns after it line up.
    int width = 40;
    for (const processing::FitResult& r : results[i])
      width = std::max(width, static_cast<int>(SliceErrors(r.report).size()));
    std::printf("  %-24s %-15s %-*s %10s %8s %7s\n", "model", "status", width,
                "rmse per theta_in (1/sr)", "rmse", "med.rel", "seconds");
    // A colour shift is the measurement's: with several models it is said once, under the table.
    bool shared_shift = results[i].size() > 1;
    double hue_spread = 0;
    for (const processing::FitResult& r : results[i]) {
      shared_shift &= r.report.colour_shift;
      hue_spread = std::max(hue_spread, r.report.hue_spread);
    }
    for (const processing::FitResult& r : results[i]) {
      std::printf("  %-24s %-15s %-*s %10.4g %8.4f %7.2f\n",
                  std::string(ModelName(r.material.model)).c_str(),
                  std::string(processing::FitStatusName(r.report.status)).c_str(), width,
                  SliceErrors(r.report).c_str(), r.report.rmse, r.report.median_relative_error,
                  r.report.seconds);
      const std::string engine = EngineInstructions(r.material);
      if (!engine.empty())
        std::printf("    %s: %s\n", std::string(DescribeModel(r.material.model).engine).c_str(),
                    engine.c_str());
      const std::string shift =
          processing::ColourShiftWarning(r.report.hue_spread, r.material.model);
      for (const std::string& w : r.report.warnings)
        if (!shared_shift || w != shift) std::printf("    warning: %s\n", w.c_str());
    }
    if (shared_shift)
      std::printf("  warning: %s\n", processing::ColourShiftWarning(hue_spread).c_str());
    std::printf("  written: ");
    for (std::size_t k = 0; k < models.size(); ++k)
      std::printf("%s%s", k ? ", " : "", output_of(inputs[i], models[k]).c_str());
    std::printf("\n");
  }
  if (total > 1 || !failures.empty())
    std::printf("%s\n", BatchSummary("fitted", fitted, total, failures).c_str());
  return failures.empty() ? 0 : 1;
}

}  // namespace brdf::cli
