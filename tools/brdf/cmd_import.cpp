// `brdf import FILE --out FILE.bpc [--format ...] [--allow-btdf]`: a measurement that exists
// in a third-party format becomes a .bpc capture, so every later command (info, eval, convert)
// treats it like one the instrument made.
//
// Point-cloud formats (Zemax and LightTools BSDF tables, CSV point clouds, goniometer tables)
// are read by brdf::ImportFile (brdf/core/importers.h) and written unchanged. RGL and MERL
// files are evaluable BRDFs, not point clouds: CaptureEvaluable below captures them.
#include <cstdio>
#include <memory>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/importers.h"
#include "brdf/core/measurement.h"
#include "brdf/core/merl.h"
#include "brdf/core/models.h"
#include "brdf/core/rgl.h"
#include "cli_support.h"
#include "commands.h"
#include "evaluable_capture.h"

namespace brdf::cli {

namespace {

// The reference instrument's geometry (DESIGN §1): light at θin 0°, 20°, 40°, 60° (φin = 0),
// detector at θout 0°–75° and φout 0°–359°, 1° steps.
constexpr double kReferenceThetaInDeg[] = {0, 20, 40, 60};
constexpr int kReferenceThetaOutMaxDeg = 75;
constexpr int kReferencePhiOutCount = 360;

}  // namespace

// Evaluable formats (RGL, MERL) hold a BRDF, not samples: the .bpc is a virtual, noise-free
// capture of it at the reference geometry, f_r = source.Eval(wi, wo) per sample (what
// `brdf capture --device sim --material FILE --noise 0` measures, without the simulated
// detector), no σ, and no flags except kFlagInvalid where a MERL table marks the bin as not
// measured. Should tools/brdf/sources.h's noise-free capture of a Material be generalised to
// any BrdfSource, this function becomes that call.
Measurement CaptureEvaluable(const std::string& path, ImportFormat format) {
  // By format, not extension: `--format rgl` may name a file called anything.
  std::unique_ptr<BrdfSource> source;
  const MerlBrdf* merl = nullptr;  // MERL marks unmeasured bins: those samples are flagged
  if (format == ImportFormat::kRgl) {
    source = std::make_unique<RglBrdf>(RglBrdf::Load(path));
  } else {
    auto loaded = std::make_unique<MerlBrdf>(MerlBrdf::Load(path));
    merl = loaded.get();
    source = std::move(loaded);
  }
  Measurement m;
  m.metadata.sample_name = path;
  m.metadata.extra["source_file"] = path;
  m.metadata.extra["source_format"] = ImportFormatName(format);
  m.metadata.extra["capture"] =
      "virtual, noise-free: f_r evaluated at the reference geometry (theta_in 0, 20, 40, 60; "
      "theta_out 0-75; phi_out 0-359; 1 deg steps)";
  for (const double theta_in : kReferenceThetaInDeg) {
    Slice slice;
    slice.theta_in_deg = theta_in;
    slice.samples.reserve((kReferenceThetaOutMaxDeg + 1) * kReferencePhiOutCount);
    const Vec3 wi = SphericalDirectionDeg(theta_in, 0.0);
    for (int theta_out = 0; theta_out <= kReferenceThetaOutMaxDeg; ++theta_out) {
      for (int phi_out = 0; phi_out < kReferencePhiOutCount; ++phi_out) {
        Sample x;
        x.theta_in_deg = static_cast<float>(theta_in);
        x.theta_out_deg = static_cast<float>(theta_out);
        x.phi_out_deg = static_cast<float>(phi_out);
        const Vec3 wo = SphericalDirectionDeg(theta_out, phi_out);
        const Rgb f = source->Eval(wi, wo);
        for (int c = 0; c < 3; ++c) x.rgb[c] = static_cast<float>(f[c]);
        if (merl != nullptr && !merl->IsMeasured(wi, wo)) x.flags = kFlagInvalid;
        slice.samples.push_back(x);
      }
    }
    m.slices.push_back(std::move(slice));
  }
  return m;
}

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
