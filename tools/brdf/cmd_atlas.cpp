// `brdf atlas INPUT... --out PREFIX`: many materials in one texture (docs/design.md §5) for
// deferred renderers, with a manifest JSON.
//
// Every input becomes a LUT exactly as `brdf convert` makes it (captures and material files
// are resampled with their extrapolation; exported LUTs are used as stored), on --jobs worker
// threads. An atlas is all or nothing: if any input fails, or the θin sets differ, every
// problem is reported and nothing is written.
#include <tbb/global_control.h>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>

#include "batch.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/engines/engine_export.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"
#include "fit_support.h"
#include "progress.h"

namespace brdf::cli {

namespace fs = std::filesystem;

namespace {

// --max-error's report, from the manifest just written: the texel format chosen for the whole
// atlas, then one line per material with its error (a warning line when it is above the bound).
void PrintAtlasChoice(const std::string& manifest_path, double bound) {
  const exporter::AtlasManifest m =
      exporter::ParseAtlasManifest(ReadFileText(manifest_path, 64u << 20), manifest_path);
  const bool bc6h = m.payload_format == "bc6h_ufloat";
  std::printf("--max-error %g %%: %s for the atlas (%llu bytes%s)\n", 100 * bound,
              bc6h ? "BC6H" : "RGB9E5", static_cast<unsigned long long>(m.payload_bytes),
              bc6h ? ", every material meets the bound with BC6H"
                   : ", BC6H does not meet the bound for every material");
  for (const exporter::AtlasManifestEntry& e : m.materials) {
    if (!e.certified_error) continue;
    const exporter::CertifiedError& c = *e.certified_error;
    std::printf("  %s: measured max %.2f %% (p99 %.2f %%, median %.3f %%)%s\n", e.name.c_str(),
                100 * c.measured.max, 100 * c.measured.p99, 100 * c.measured.median,
                c.max_error_met ? "" : " - WARNING: above the bound");
  }
}

}  // namespace

int RunAtlas(const AtlasOptions& options) {
  if (options.out.empty()) throw InvalidArgument("--out: an output prefix is required");
  std::optional<processing::ExtrapolationParams> extrapolate;
  const bool auto_extrapolate = options.extrapolate == "auto";  // fitted per input (brdf fit)
  if (!options.extrapolate.empty() && !auto_extrapolate)
    extrapolate = ParseExtrapolationOption(options.extrapolate);
  const exporter::ExrOptions exr_options =
      ParseExrOptions(options.exr_type, options.exr_compression);
  const engines::EngineSet engine_set = engines::ParseEngines(options.engines);
  const exporter::LutCompression compression = exporter::ParseLutCompression(options.compress);
  if (options.jobs < 1)
    throw InvalidArgument("--jobs: expected at least 1, got " + std::to_string(options.jobs));
  if (compression != exporter::LutCompression::kNone && engine_set.Any())
    throw InvalidArgument(
        "--compress bc6h: the engine hand-offs (--engine) are written as RGB9E5 only so far; "
        "write them in a separate run without --compress");
  if (options.max_error > 0 && engine_set.Any())
    throw InvalidArgument(
        "--max-error: the engine hand-offs (--engine) are written as RGB9E5 only so far; "
        "write them in a separate run without --max-error");

  DiscoveredInputs found = DiscoverInputs(options.inputs, InputKinds{.exported_luts = true});
  if (found.inputs.empty() && found.failures.empty()) {
    throw InvalidArgument("no captures, material files or exported LUTs found in " +
                          JoinArguments(options.inputs));
  }

  // The writers' own lists (exporter::AtlasOutputPaths, engines::EngineOutputPaths).
  std::vector<std::string> outputs = exporter::AtlasOutputPaths(options.out);
  const fs::path prefix(options.out);
  const std::string engine_dir =
      prefix.has_parent_path() ? prefix.parent_path().string() : std::string(".");
  for (std::string& p :
       engines::EngineOutputPaths(engine_dir, prefix.filename().string(), engine_set))
    outputs.push_back(std::move(p));
  {
    std::set<std::string> inputs;
    for (const BatchInput& in : found.inputs) inputs.insert(Identity(in.path));
    for (const std::string& out : outputs)
      if (inputs.count(Identity(out)))
        throw InvalidArgument("--out " + options.out + ": the atlas file " + out +
                              " would overwrite an input; choose another prefix");
  }
  {
    // The overwrite rule covers the engine folders' shared files too (not the guard's list:
    // a failed atlas removes only what it created).
    std::vector<std::string> checked = outputs;
    for (std::string& p : engines::EngineOutputsToCheck(engine_dir, {}, engine_set))
      checked.push_back(std::move(p));
    ReportRemovedTemporaries(
        CheckWritableOutputs(checked, options.force, /*folders_created=*/true));
  }
  std::vector<BatchFailure> failures = found.failures;
  for (const BatchFailure& f : failures)
    std::fprintf(stderr, "%s: FAILED: %s\n", f.path.c_str(), f.reason.c_str());

  tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                            static_cast<std::size_t>(options.jobs));
  processing::ResampleOptions resample = sources::DefaultResampleOptions();
  resample.parallel = found.inputs.size() == 1 && options.jobs > 1;
  std::vector<Lut> luts(found.inputs.size());
  std::vector<std::optional<std::vector<exporter::SaturatedCount>>> saturated(found.inputs.size());
  std::vector<std::optional<exporter::ExtrapolationInfo>> extrapolation(found.inputs.size());
  std::vector<std::vector<std::string>> fitted(found.inputs.size());  // --extrapolate auto's record
  std::vector<std::string> beyond(found.inputs.size());               // the blind-spot fill's

  Progress progress("atlas", found.inputs.size(), !options.quiet);
  const std::vector<JobResult> results = RunJobs(
      found.inputs.size(), options.jobs,
      [&](std::size_t i, JobResult& result) {
        const BatchInput& in = found.inputs[i];
        std::optional<processing::ExtrapolationParams> chosen = extrapolate;
        std::string auto_warning;
        if (auto_extrapolate)
          if (const auto automatic = AutoExtrapolationFor(in.path, in.kind)) {
            chosen = automatic->params;
            fitted[i].push_back(automatic->record_json);
            auto_warning = automatic->warning;
          }
        sources::InputLut built = sources::LutFromInput(in.path, in.kind, chosen, resample);
        exporter::ValidateLutForExport(built.lut);
        result.warnings = std::move(built.warnings);
        if (!auto_warning.empty()) result.warnings.push_back(auto_warning);
        if (auto note = sources::SaturationNote(in.path, built.saturated_samples))
          result.warnings.push_back(std::move(*note));
        saturated[i] = std::move(built.saturated_samples);
        extrapolation[i] = built.extrapolation;
        beyond[i] = std::move(built.beyond_json);
        luts[i] = std::move(built.lut);
      },
      [&](std::size_t i, const JobResult& result) {
        const BatchInput& in = found.inputs[i];
        for (const std::string& w : result.warnings) progress.Message(w);
        if (!result.ok)
          progress.Message(in.path + ": FAILED: " + ReasonWithoutPath(in.path, result.error));
        progress.Advance(in.path, !result.ok);
      });
  progress.Finish();

  for (std::size_t i = 0; i < results.size(); ++i)
    if (!results[i].ok)
      failures.push_back(
          {found.inputs[i].path, ReasonWithoutPath(found.inputs[i].path, results[i].error)});
  const std::size_t total = found.inputs.size() + found.failures.size();
  if (!failures.empty()) {
    std::printf("atlas not written: %s\n",
                BatchSummary("read", total - failures.size(), total, failures).c_str());
    return 1;
  }

  std::vector<exporter::AtlasMaterial> materials;
  for (std::size_t i = 0; i < luts.size(); ++i)
    materials.push_back({found.inputs[i].name, &luts[i],
                         sources::RecordedSourceName(found.inputs[i].path), saturated[i],
                         extrapolation[i], fitted[i], beyond[i]});
  CreateOutputFolder(fs::path(options.out).parent_path().string());
  const OutputGuard guard(outputs);
  std::vector<std::string> written;
  try {
    // BuildAtlas inside WriteAtlas refuses different θin sets, naming both materials.
    written = engines::WriteAtlasWithEngines(options.out, materials, exr_options, engine_set,
                                             compression, options.jobs, options.max_error);
  } catch (...) {
    guard.RemoveNew();
    throw;
  }
  const exporter::AtlasLayout layout =
      exporter::ComputeAtlasLayout(static_cast<int>(materials.size()), luts.front().slices());
  std::printf("atlas of %zu material%s (%d × %d cells; texture %d × %d × %d, θin %s°):\n",
              materials.size(), materials.size() == 1 ? "" : "s", layout.cells.columns,
              layout.cells.rows, layout.TextureWidth(), layout.TextureHeight(), layout.slices,
              exporter::FormatThetaList(luts.front().theta_in_deg).c_str());
  for (const std::string& w : written) std::printf("  %s\n", w.c_str());
  if (options.max_error > 0) PrintAtlasChoice(options.out + ".json", options.max_error);
  return 0;
}

}  // namespace brdf::cli
