// Opening any input of the toolchain with one call: the fitter, the previewer, the viewer and
// every `brdf` command ask these functions, so they agree on what a file holds.
//
//  - OpenBrdf: any evaluable file as a BrdfSource (`brdf eval`, `brdf preview`, `capture
//    --material`).
//  - OpenForView: the BRDF and the LUT of one source from one read and one resampling
//    (brdf-view's lobes, heat maps and preview).
//  - LutFromInput: any input as the float LUT of docs/design.md §5 (`brdf convert`, `atlas`).
//  - OpenExportedTexture: an exported LUT or atlas read back with its sidecar or manifest.
//  - ChooseExtrapolation: the §6 parameters that apply to one input.
//
// OpenBrdf and OpenForView take a file or the name of a library material ("gold"; the rule of
// brdf/sources/material_library.h: a file of that name wins). The functions that take a
// FileKind take a path the caller has resolved (ResolveSource) and classified (DetectFileKind).
//
// One evaluation path. A capture (or an imported table) is evaluated by resampling it into the
// float LUT exactly as `brdf convert` does (processing::MeasurementAsBrdf) and reading that LUT
// by the rule of docs/design.md §5 the shaders follow (Lut::SampleAngles: the reciprocity step
// below, then centre-exact texel coordinates, trilinear, clamp-to-edge). So `brdf eval CAPTURE`,
// `brdf preview CAPTURE` and `brdf eval` of its exported LUT differ
// only by the RGB9E5 rounding of the texture, and between measured θin both interpolate
// linearly in the specular frame (the same (θd, φd) in the two neighbouring slices).
//
// θin outside the measured range (one rule for captures, LUTs and eval, Lut::SampleAngles):
// when the view's polar angle is nearer to the measured range than the light's, light and view
// are exchanged (reciprocity, f(ωi, ωo) = f(ωo, ωi)), so a light beyond the last slice seen
// from inside the range gets a measured value; when both lie beyond it, the value of the
// nearest measured slice at the same specular-frame coordinates (θd, φd), as the GPU's
// clamp-to-edge along w gives it. OpenedSource::BeyondMeasuredWarning says when a query is
// answered that way (clamped, not measured).
//
// Every function throws brdf::Error subclasses whose message starts with the file's path; what
// the user can do is in Error::remedy(). Nothing here prints.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/lut.h"
#include "brdf/core/lut_brdf.h"
#include "brdf/core/measurement.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/sidecar.h"
#include "brdf/exporter/texture_file.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/processing/resample.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/material_library.h"

namespace brdf::sources {

// The §6 extrapolation parameters for one input and where they came from. Precedence, most
// specific first: "<stem>.extrapolate.json" beside the input; the input's own "extrapolate"
// member (material files); `command_line`; the defaults p = 1, l = 0.5.
struct ExtrapolationChoice {
  processing::ExtrapolationParams params;
  enum class Origin { kDefaults, kCommandLine, kBesideFile, kMaterialMember };
  Origin origin = Origin::kDefaults;
  std::string file;  // kBesideFile / kMaterialMember: the file read
};
// Throws FormatError / IoError for an unreadable or invalid per-material file.
ExtrapolationChoice ChooseExtrapolation(
    const std::string& input_path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line,
    std::vector<std::string>* warnings);

// A material file as every command reads it: LoadMaterialFile (brdf/core/models.h), and its
// "extrapolate" member checked (processing::ExtrapolationFromJson) also by the commands that do
// not extrapolate (eval, preview, info), so that a file is accepted or refused as a whole by
// all of them. Throws FormatError / IoError.
Material LoadMaterialInput(const std::string& path);

// A capture, material file or imported table opened as a measurement ready to resample.
struct PreparedMeasurement {
  Measurement measurement;
  ExtrapolationChoice extrapolation;
  std::vector<std::string> warnings;
  // Measured values (a capture, a table), held to the rule of values no surface has
  // (docs/design.md §4); false for a virtual capture of an evaluable file, whose values are the
  // model's (ResampleOptions::check_measured_values).
  bool measured = true;
  // A capture's reasons the LUT textures cannot be made of it, though every other command
  // accepts it (CaptureAssessment::export_refusals: a θin list not k·Δin from 0°).
  std::vector<CaptureRefusal> export_refusals;
};
// Captures follow the damaged-capture rule (capture.h); material files are captured noise-free
// on the reference geometry (brdf/core/virtual_capture.h); third-party tables (Zemax,
// LightTools, CSV, gonio) are imported (transmission tables only with `allow_btdf`), RGL and
// MERL files and exported single-material LUTs (.ktx2, .dds, sidecar, sampled as a GPU samples
// them) captured noise-free. InvalidArgument for any other kind (an atlas included).
PreparedMeasurement PrepareMeasurement(
    const std::string& path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line, bool allow_btdf = false);

// An exported LUT or atlas read back: the texture, and the sidecar or manifest that describes
// it if there is one (given directly, embedded in the KTX2, or found beside a DDS).
struct OpenedTexture {
  exporter::LoadedTexture texture;
  std::string texture_path;
  std::optional<exporter::SidecarInfo> sidecar;     // a single LUT's
  std::optional<exporter::AtlasManifest> manifest;  // an atlas's
  std::string sidecar_path;  // the standalone sidecar or manifest read, if any
  // The payload CRC-32 was compared with the one the metadata records (the readers throw on a
  // mismatch, so this is false only when there was no metadata to compare with).
  bool checksum_verified = false;
  std::vector<std::string> warnings;
};
// `path` is a .ktx2, a .dds, a sidecar .json or an atlas manifest .json. A sidecar leads to the
// texture it lists (the .ktx2 first, else the .dds) in its folder, a manifest to PREFIX.ktx2
// (else PREFIX.dds) beside it; the size and checksum the JSON records are checked against
// that texture. Throws IoError / FormatError / InvalidArgument (another kind of file).
OpenedTexture OpenExportedTexture(const std::string& path);

// ResampleOptions as the commands use them unless told otherwise: the blind-spot fill
// processing::kDefaultBeyondMethod with kDefaultBeyondSubdivisions.
processing::ResampleOptions DefaultResampleOptions();

struct OpenOptions {
  // §6 parameters from the command line (captures and tables; ignored with a warning for
  // exported LUTs, where the extrapolation is baked in).
  std::optional<processing::ExtrapolationParams> extrapolation;
  // How captures are resampled (the same options `brdf convert` uses by default, the
  // blind-spot fill of brdf/processing/beyond.h included).
  processing::ResampleOptions resample = DefaultResampleOptions();
};

// How OpenBrdf evaluates the file.
enum class Evaluation {
  kAnalytic,          // a material file: the model's formula
  kMeasuredDatabase,  // RGL / MERL: the database's own interpolation
  kResampledLut,      // a capture or table, resampled into the float LUT (the convert path)
  kExportedLut,       // an exported texture, RGB9E5 values as stored
};

struct OpenedSource {
  std::unique_ptr<BrdfSource> brdf;
  FileKind kind = FileKind::kUnknown;
  Evaluation evaluation = Evaluation::kAnalytic;
  // The measured θin, ascending, for kResampledLut and kExportedLut (the LUT's slices); empty
  // when the source covers every θin itself.
  std::vector<double> measured_theta_in_deg;
  std::optional<ExtrapolationChoice> extrapolation;  // kResampledLut: what filled θout > θb
  std::vector<std::string> warnings;                 // full sentences starting with the path

  // A warning sentence when a query with light polar angle `theta_in_deg` and view polar angle
  // `theta_out_deg` is answered from the nearest slice (clamp-to-edge) because both lie
  // outside the measured θin range, else nullopt (also when reciprocity answers it from
  // measured slices).
  std::optional<std::string> BeyondMeasuredWarning(double theta_in_deg, double theta_out_deg,
                                                   const std::string& path) const;

  // For pictures that show every pair of directions up to grazing (a sphere or a mesh under a
  // map, as `brdf preview` renders them): a note, starting with the path, when the measured θin
  // range ends before kSphereCoverageThetaInDeg, so the pixels lit and seen beyond it (the sphere's
  // rim) show the last slice's values rather than measured ones; nullopt otherwise.
  static constexpr double kSphereCoverageThetaInDeg = 85.0;
  std::optional<std::string> SphereCoverageNote(const std::string& path) const;
};

// The .brdfc beside a compact LUT's sidecar (payload format "compact_log_grid"), which `brdf
// eval` and `brdf info` read in its place; nullopt for any other sidecar. Throws IoError when
// the .brdfc is missing, FormatError for a damaged sidecar.
std::optional<std::string> CompactLutOfSidecar(const std::string& sidecar_path);

// Opens any evaluable file: material .json, .bpc capture, .ktx2 / .dds LUT or LUT sidecar,
// RGL .bsdf, MERL .binary, Zemax / LightTools tables, CSV point clouds and goniometer tables
// (tables evaluated like a capture; transmission tables mirrored, with a warning). Atlases are
// refused (RemedyKind::kEvaluateSingleLut). Throws IoError / FormatError / InvalidArgument.
OpenedSource OpenBrdf(const std::string& path_or_name, const OpenOptions& options = {});

// One source as brdf-view shows it: the BRDF its preview renders and the LUT its lobes and heat
// maps sample (docs/design.md §5), both from one read of the file and at most one resampling.
//  - captures and tables (kResampledLut): the measurement is resampled once (the convert path,
//    any distinct θin accepted as OpenBrdf accepts them); `brdf` samples that very LUT;
//  - material files (kAnalytic), RGL and MERL files (kMeasuredDatabase): `brdf` is the
//    model's formula or the database's interpolation, as OpenBrdf gives it; the LUT is that of
//    their noise-free capture on the reference geometry (brdf/core/virtual_capture.h) with the
//    input's extrapolation, as `brdf convert` makes it;
//  - exported LUTs (kExportedLut): the texture's LUT as stored, `brdf` sampling it.
// `measurement` and `resample_report` are what the LUT was resampled from and how (absent for
// exported LUTs), so the viewer can show which directions were measured. Throws what OpenBrdf
// throws.
struct OpenedForView {
  std::string path;  // the file read (a library name resolved to its file)
  FileKind kind = FileKind::kUnknown;
  Evaluation evaluation = Evaluation::kAnalytic;
  std::shared_ptr<const BrdfSource> brdf;
  Lut lut;
  // Last measured θout (θb, degrees): the resampling's, an exported LUT's sidecar's, else 90.
  double theta_b_deg = 90;
  std::optional<Measurement> measurement;
  std::optional<processing::ResampleReport> resample_report;
  std::optional<ExtrapolationChoice> extrapolation;  // what filled θout > θb when resampled
  std::vector<std::string> warnings;                 // full sentences starting with the path
};
OpenedForView OpenForView(const std::string& path_or_name, const OpenOptions& options = {});

// A LUT ready to export or to place in an atlas, built from any input `brdf convert` or
// `brdf atlas` accepts: captures and material files are resampled (processing::BuildLut with
// the chosen extrapolation); exported LUTs (.ktx2, .dds, sidecar) are decoded as stored.
//
// Saturated samples: for a measurement, the samples of each slice that carry kFlagSaturated
// (counted over the slices the LUT is built from, θin ascending as the measurement lists them);
// for an exported LUT, what its sidecar recorded, or nothing when it recorded none.
struct InputLut {
  Lut lut;
  std::optional<exporter::ExtrapolationInfo> extrapolation;  // what filled θout > θb
  std::optional<std::vector<exporter::SaturatedCount>> saturated_samples;  // absent: unknown
  // What filled the blind spots (a resampled input with a fill other than clamp).
  std::optional<processing::BeyondReport> beyond;
  // The fill's record as JSON text (processing::BeyondReportJson of `beyond`, or an exported
  // LUT's sidecar's "beyond"): what sidecars and atlas manifests carry; empty: none.
  std::string beyond_json;
  std::vector<std::string> warnings;
};
InputLut LutFromInput(const std::string& path, FileKind kind,
                      const std::optional<processing::ExtrapolationParams>& command_line,
                      const processing::ResampleOptions& resample_options);

// The warning `brdf convert` and `brdf atlas` print when the RGB9E5 textures cannot hold every
// value of `lut` (a channel below 0 or above 65408 1/sr, clamped by the encoding of
// docs/design.md §7): how many texel values are clipped and to what; nullopt when none is.
// LutFromInput appends it to InputLut::warnings for a resampled input.
std::optional<std::string> ClipNote(const std::string& path, const Lut& lut);

// The samples flagged saturated (kFlagSaturated) in each slice of `m`, in slice order.
std::vector<exporter::SaturatedCount> CountSaturated(const Measurement& m);

// The one line `brdf convert` and `brdf atlas` print for an input with saturated samples, e.g.
// "gold.bpc: 12 saturated samples (θin 0°: 0, 20°: 12, 40°: 0, 60°: 0); their values are
// clipped"; nullopt when there are none (or the counts are unknown).
std::optional<std::string> SaturationNote(
    const std::string& path, const std::optional<std::vector<exporter::SaturatedCount>>& counts);

// The one line `brdf convert` prints for a capture whose fill was validated (three or more
// measured slices), e.g. "gold.bpc: blind-spot fill model (ggx): the θin 60° slice predicted
// from the others within 1.2 % (median), 6.9 % (p90)"; nothing without a validation.
std::optional<std::string> LeaveLastSliceOutNote(const std::string& path,
                                                 const std::optional<processing::BeyondReport>& b);

}  // namespace brdf::sources
