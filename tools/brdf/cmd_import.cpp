// `brdf import FILE --out FILE.bpc [--format ...] [--allow-btdf]`: a measurement that exists
// in a third-party format becomes a .bpc capture, so every later command (info, eval, convert)
// treats it like one the instrument made.
//
// Point-cloud formats (Zemax and LightTools BSDF tables, CSV point clouds, goniometer tables)
// are read by brdf::ImportFile (brdf/core/importers.h) and written unchanged. RGL and MERL
// files are evaluable BRDFs, not point clouds: they become the toolchain's one noise-free
// virtual capture at the reference geometry (brdf::CaptureNoiseFree,
// brdf/core/virtual_capture.h), samples in MERL's unmeasured bins flagged invalid. The format
// is detected by brdf::sources::DetectFileKind, the rule every command uses.
#include <cstdio>
#include <memory>
#include <optional>
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
#include "brdf/core/virtual_capture.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/material_library.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

int RunImport(const ImportOptions& options) {
  // A library material name stands for its file (brdf/sources/material_library.h).
  const std::string file = sources::ResolveSource(options.file);
  const ImportFormat requested = ImportFormatFromName(options.format);
  // Detecting first also checks that the input can be opened before the output is judged.
  ImportFormat format = requested;
  if (requested == ImportFormat::kAuto) {
    const sources::FileKind kind = sources::DetectFileKind(file);
    const std::optional<ImportFormat> detected = sources::ImportFormatOf(kind);
    if (!detected)
      throw FormatError(
          file, "file content",
          "a third-party measurement (RGL .bsdf, Zemax or LightTools BSDF text, "
          "MERL .binary, CSV point cloud, goniometer table)",
          std::string("a ") + sources::FileKindName(kind), {},
          kind == sources::FileKind::kUnknown ? Remedy{RemedyKind::kNameFormat, file} : Remedy{});
    format = *detected;
  }
  CheckOutputPath(options.out, file, ".bpc", options.force);

  Measurement m;
  if (format == ImportFormat::kRgl || format == ImportFormat::kMerl) {
    // By format, not extension: `--format rgl` may name a file called anything.
    if (format == ImportFormat::kRgl)
      m = CaptureNoiseFree(RglBrdf::Load(file));
    else
      m = CaptureNoiseFree(MerlBrdf::Load(file));
    m.metadata.sample_name = file;
    m.metadata.extra["source_file"] = file;
    m.metadata.extra["source_format"] = ImportFormatName(format);
  } else {
    brdf::ImportOptions import_options;
    import_options.allow_btdf = options.allow_btdf;
    m = ImportFile(file, format, import_options);
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
  std::printf("%s: %s file -> %s: %zu slices (theta_in %s deg), %zu samples", file.c_str(),
              ImportFormatName(format).c_str(), options.out.c_str(), m.slices.size(),
              thetas.c_str(), m.SampleCount());
  if (invalid > 0) std::printf(", %zu flagged invalid", invalid);
  std::printf("\n");
  WarnAboutVerdict(options.out);
  return 0;
}

}  // namespace brdf::cli
