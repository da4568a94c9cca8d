// `brdf import FILE --out FILE.bpc [--format ...] [--allow-btdf]`: a measurement that exists
// in a third-party format becomes a .bpc capture, so every later command (info, eval, convert)
// treats it like one the instrument made.
//
// Point-cloud formats (Zemax and LightTools BSDF tables, CSV point clouds, goniometer tables)
// are read by brdf::ImportFile (brdf/core/importers.h) and written unchanged. RGL and MERL
// files are evaluable BRDFs, not point clouds: they go through CaptureEvaluable below.
#include <cstdio>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/importers.h"
#include "brdf/core/measurement.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

namespace {

// The hook for evaluable formats. A .bpc of an RGL or MERL material is a virtual, noise-free
// capture at the reference instrument's geometry (DESIGN §1: θin 0/20/40/60°, θout 0–75°,
// φout 0–359°, 1° steps): f_r = source->Eval(wi, wo) per sample. Once OpenBrdfSource opens
// .bsdf (RGL) and .binary (MERL) files, replace the throw with
//   return <noise-free capture of *OpenBrdfSource(path) on the reference geometry>;
// (the noise-free capture of tools/brdf/sources.h, CaptureMaterialNoiseFree, taken over a
// BrdfSource instead of a Material), and update the --format help in main.cpp. Until then
// the user is pointed at the simulator, which makes the same capture with --noise 0.
Measurement CaptureEvaluable(const std::string& path, ImportFormat format) {
  throw InvalidArgument(path + ": " + ImportFormatName(format) +
                        " files are evaluable BRDFs, not point clouds, and `brdf import` cannot "
                        "capture them yet: run `brdf capture --device sim --material " +
                        path + " --noise 0 --sample NAME --out FILE.bpc` instead");
}

}  // namespace

int RunImport(const ImportOptions& options) {
  const ImportFormat requested = ImportFormatFromName(options.format);
  // Detecting first also checks that the input can be opened before the output is judged.
  const ImportFormat format =
      requested == ImportFormat::kAuto ? DetectImportFormat(options.file) : requested;
  CheckOutputPath(options.out, options.file, ".bpc", options.force);

  Measurement m;
  if (format == ImportFormat::kRgl || format == ImportFormat::kMerl) {
    m = CaptureEvaluable(options.file, format);
  } else {
    brdf::ImportOptions import_options;
    import_options.allow_btdf = options.allow_btdf;
    m = ImportFile(options.file, format, import_options);
  }
  if (!options.sample.empty()) m.metadata.sample_name = options.sample;
  // A CSV written by `brdf export-csv` names the software that made the capture; keep it.
  if (m.metadata.software_version.empty()) m.metadata.software_version = SoftwareVersion();
  WriteBpc(options.out, m);

  std::size_t invalid = 0;
  for (const Slice& s : m.slices)
    for (const Sample& x : s.samples) invalid += (x.flags & kFlagInvalid) != 0;
  std::string thetas;
  for (const double t : m.ThetaInDeg()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%g", thetas.empty() ? "" : ", ", t);
    thetas += buf;
  }
  std::printf("%s: %s file -> %s: %zu slices (theta_in %s deg), %zu samples", options.file.c_str(),
              ImportFormatName(format).c_str(), options.out.c_str(), m.slices.size(),
              thetas.c_str(), m.SampleCount());
  if (invalid > 0) std::printf(", %zu flagged invalid", invalid);
  std::printf("\n");
  return 0;
}

}  // namespace brdf::cli
