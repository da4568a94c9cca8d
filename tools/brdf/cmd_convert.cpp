// `brdf convert INPUT... --out DIR`: captures and material files to engine-ready LUTs.
//
// Per input: open it (brdf::sources: the damaged-capture rule, noise-free capture of material
// files, the extrapolation choice), resample it (processing::BuildLut), and write every
// selected format with exporter::ExportLut, each file atomically. Inputs run on --jobs worker
// threads, one input per worker at a time, so memory stays at a few inputs' worth whatever the
// batch size. A failing input is reported and skipped; the exit code is 1 if any failed.
#include <tbb/global_control.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "batch.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/engines/engine_export.h"
#include "brdf/exporter/lut_export.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"
#include "fit_support.h"
#include "progress.h"

namespace brdf::cli {

namespace fs = std::filesystem;

namespace {

// Refuses inputs whose outputs would collide with another input's outputs or overwrite an
// input (a material "gold.json" converted into its own folder would be replaced by the sidecar
// "gold.json"). Such inputs move from `inputs` to `failures`.
void RefuseCollisions(const fs::path& out_dir, const exporter::LutExportOptions& formats,
                      std::vector<BatchInput>& inputs, std::vector<BatchFailure>& failures) {
  std::set<std::string> input_paths;
  for (const BatchInput& in : inputs) input_paths.insert(Identity(in.path));
  std::map<std::string, std::vector<std::size_t>> by_name;
  for (std::size_t i = 0; i < inputs.size(); ++i) by_name[inputs[i].name].push_back(i);
  std::vector<bool> refused(inputs.size(), false);
  std::map<std::size_t, std::string> reasons;
  for (const auto& [name, indices] : by_name) {
    if (indices.size() < 2) continue;
    for (std::size_t i : indices) {
      std::string others;
      for (std::size_t o : indices)
        if (o != i) others += (others.empty() ? "" : ", ") + inputs[o].path;
      reasons[i] = "its outputs " + (out_dir / (name + ".*")).string() +
                   " would also be written for " + others + "; rename one of them";
    }
  }
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (reasons.count(i)) continue;
    for (const std::string& out :
         exporter::LutExportPaths(out_dir.string(), inputs[i].name, formats))
      if (input_paths.count(Identity(out))) {
        reasons[i] = "its output " + out + " would overwrite an input; choose another --out folder";
        break;
      }
  }
  std::vector<BatchInput> kept;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (const auto it = reasons.find(i); it != reasons.end())
      failures.push_back({inputs[i].path, it->second});
    else
      kept.push_back(std::move(inputs[i]));
  }
  inputs = std::move(kept);
}

// The one line per input --max-error and --compress compact print: which representation, its
// bytes and the error it achieved.
std::optional<std::string> RepresentationLine(const std::string& name,
                                              const exporter::LutExportOptions& options,
                                              const exporter::LutExportResult& result) {
  if (!(options.max_error > 0) && options.compression != exporter::LutCompression::kCompact)
    return std::nullopt;
  const double bound =
      options.max_error > 0 ? options.max_error : exporter::kCompactDefaultMaxError;
  const exporter::CertifiedError& e = *result.certified_error;
  return fmt::format(
      "{}: {} {} bytes ({:.1f}x smaller than RGB9E5), measured max {:.2f} % (p99 "
      "{:.2f} %, median {:.3f} %){}",
      name, exporter::LutCompressionName(result.chosen), e.bytes,
      static_cast<double>(e.rgb9e5_bytes) / static_cast<double>(e.bytes), 100 * e.measured.max,
      100 * e.measured.p99, 100 * e.measured.median,
      result.met_max_error ? fmt::format(" <= {:g} %", 100 * bound)
                           : fmt::format(" - WARNING: above the bound {:g} %", 100 * bound));
}

// Every input allocates and frees the same few large buffers (the measurement, the LUT and its
// fill's per-slice tables of 1–7 MB, the encoded files). glibc serves blocks above its mmap
// threshold with fresh mappings and returns freed heap tops to the system, so each input faulted
// in and zeroed its ~100 MB again: a third of a capture's CPU time was the kernel's
// (docs/benchmarks/batch.md). Kept in the process, the memory is reused from input to input; the
// peak is unchanged.
void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest (DEFAULT_MMAP_THRESHOLD_MAX)
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

}  // namespace

int RunConvert(const ConvertOptions& options) {
  if (options.out.empty()) throw InvalidArgument("--out: an output folder is required");
  exporter::LutExportOptions export_options;
  export_options.formats = exporter::ParseExportFormats(options.formats);
  export_options.exr = ParseExrOptions(options.exr_type, options.exr_compression);
  export_options.compression = exporter::ParseLutCompression(options.compress);
  export_options.max_error = options.max_error;
  const engines::EngineSet engine_set = engines::ParseEngines(options.engines);
  if (export_options.compression == exporter::LutCompression::kCompact &&
      !(options.max_error > 0) && engine_set.Any())
    throw InvalidArgument(
        "--compress compact: no engine kit samples the compact form; with --engine use "
        "--compress bc6h, --max-error (BC6H or RGB9E5 per material), or no --compress");
  // The engine folders may be written as BC6H (they then add unity/NAME_flipbook.exr).
  const bool engine_bc6h =
      export_options.compression == exporter::LutCompression::kBc6h || options.max_error > 0;
  if (!options.engine_fits.empty()) {
    if (!engine_set.Any())
      throw InvalidArgument("--engine-fits: goes with --engine (the fits go into its manifests)");
    std::error_code fits_ec;
    if (!fs::is_directory(options.engine_fits, fits_ec))
      throw IoError(options.engine_fits +
                    ": not a folder (--engine-fits: the folder `brdf fit "
                    "--out` wrote)");
  }
  std::optional<processing::ExtrapolationParams> extrapolate;
  const bool auto_extrapolate = options.extrapolate == "auto";  // fitted per input (brdf fit)
  if (!options.extrapolate.empty() && !auto_extrapolate)
    extrapolate = ParseExtrapolationOption(options.extrapolate);
  if (options.jobs < 1)
    throw InvalidArgument("--jobs: expected at least 1, got " + std::to_string(options.jobs));

  DiscoveredInputs found = DiscoverInputs(options.inputs);
  if (found.inputs.empty() && found.failures.empty()) {
    throw InvalidArgument("no captures (.bpc) or material files (.json) found in " +
                          JoinArguments(options.inputs));
  }
  const fs::path out_dir(options.out);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (!fs::is_directory(out_dir))
    throw IoError(options.out + ": cannot create the output folder" +
                  (ec ? ": " + ec.message() : std::string()));
  RefuseCollisions(out_dir, export_options, found.inputs, found.failures);
  {
    // The overwrite rule, for every output of the run before any work is done.
    std::vector<std::string> outputs, names;
    for (const BatchInput& in : found.inputs) {
      for (std::string& p : exporter::LutExportPaths(out_dir.string(), in.name, export_options))
        outputs.push_back(std::move(p));
      names.push_back(in.name);
    }
    for (std::string& p :
         engines::EngineOutputsToCheck(out_dir.string(), names, engine_set, engine_bc6h))
      outputs.push_back(std::move(p));
    ReportRemovedTemporaries(
        CheckWritableOutputs(outputs, options.force, /*folders_created=*/true));
  }

  const std::size_t total = found.inputs.size() + found.failures.size();
  std::vector<BatchFailure> failures = found.failures;
  for (const BatchFailure& f : failures)
    std::fprintf(stderr, "%s: FAILED: %s\n", f.path.c_str(), f.reason.c_str());
  if (!found.skipped.empty() && !options.quiet)
    std::fprintf(stderr,
                 "note: skipped %zu file%s in the input folders that %s not captures or "
                 "material files\n",
                 found.skipped.size(), found.skipped.size() == 1 ? "" : "s",
                 found.skipped.size() == 1 ? "is" : "are");

  KeepFreedMemoryForReuse();
  // One input per worker; an input resamples on several threads only when it is alone.
  const bool alone = found.inputs.size() == 1;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                            static_cast<std::size_t>(options.jobs));
  processing::ResampleOptions resample;
  resample.parallel = alone && options.jobs > 1;
  export_options.jobs = alone ? options.jobs : 1;  // the BC6H encoder, likewise
  resample.beyond.method = processing::ParseBeyondMethod(options.beyond);
  resample.beyond.subdivisions = options.beyond_subdivide;
  resample.Validate();

  Progress progress("convert", found.inputs.size(), !options.quiet);
  const std::vector<JobResult> results = RunJobs(
      found.inputs.size(), options.jobs,
      [&](std::size_t i, JobResult& result) {
        const BatchInput& in = found.inputs[i];
        std::optional<processing::ExtrapolationParams> chosen = extrapolate;
        std::optional<AutoExtrapolationChoice> automatic;
        if (auto_extrapolate) automatic = AutoExtrapolationFor(in.path, in.kind);
        if (automatic) chosen = automatic->params;
        sources::InputLut built = sources::LutFromInput(in.path, in.kind, chosen, resample);
        result.warnings = std::move(built.warnings);
        if (automatic && !automatic->warning.empty()) result.warnings.push_back(automatic->warning);
        if (auto note = sources::SaturationNote(in.path, built.saturated_samples))
          result.warnings.push_back(std::move(*note));
        if (!options.quiet)
          if (auto note = sources::LeaveLastSliceOutNote(in.path, built.beyond))
            result.warnings.push_back(std::move(*note));
        exporter::TextureMetadata metadata;
        if (automatic) metadata.fitted_models_json.push_back(automatic->record_json);
        metadata.name = in.name;
        metadata.source = sources::RecordedSourceName(in.path);
        metadata.extrapolation = built.extrapolation;
        metadata.saturated_samples = built.saturated_samples;
        metadata.beyond_json = built.beyond_json;
        std::vector<std::string> outputs =
            exporter::LutExportPaths(out_dir.string(), in.name, export_options);
        for (std::string& p :
             engines::EngineOutputPaths(out_dir.string(), in.name, engine_set, engine_bc6h))
          outputs.push_back(std::move(p));
        const OutputGuard guard(std::move(outputs));
        try {
          const engines::EngineExportResult exported = engines::ExportLutWithEngines(
              out_dir.string(), built.lut, metadata, export_options, engine_set,
              options.engine_fits.empty() ? std::vector<FittedMaterial>{}
                                          : engines::ReadFitResults(options.engine_fits, in.name));
          if (const std::optional<std::string> line =
                  RepresentationLine(in.name, export_options, exported.lut))
            result.warnings.push_back(*line);
        } catch (...) {
          // No partial set: remove what this conversion already renamed into place (the
          // writer that failed removed its own temporary file).
          guard.RemoveNew();
          throw;
        }
      },
      [&](std::size_t i, const JobResult& result) {
        const BatchInput& in = found.inputs[i];
        for (const std::string& w : result.warnings) progress.Message(w);
        if (!result.ok)
          progress.Message(in.path + ": FAILED: " + ReasonWithoutPath(in.path, result.error));
        progress.Advance(in.path, !result.ok);
      });
  progress.Finish();

  std::size_t converted = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (results[i].ok)
      ++converted;
    else
      failures.push_back(
          {found.inputs[i].path, ReasonWithoutPath(found.inputs[i].path, results[i].error)});
  }
  std::printf("%s\n", BatchSummary("converted", converted, total, failures).c_str());
  return failures.empty() ? 0 : 1;
}

}  // namespace brdf::cli
