// Opening the files `brdf` works with, whatever they are: captures (.bpc), material files,
// exported LUTs (.ktx2, .dds) and their JSON sidecars. `brdf convert`, `brdf atlas`,
// `brdf eval` and `brdf info` all go through here, so they agree on what a file is and on the
// rules for damaged captures and extrapolation parameters.
//
// Every function throws brdf::Error subclasses whose message starts with the file's path and
// says what is wrong and what to do; nothing here prints.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/lut.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/sidecar.h"
#include "brdf/exporter/texture_file.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/processing/resample.h"

namespace brdf::cli {

// What a file is. Decided by the extension, and for .json by the content: an object with a
// "model" member is a material file (DESIGN §9), "kind": "brdf-lut-sidecar" an export sidecar,
// "kind": "brdf-atlas-manifest" an atlas manifest, and a "<name>.extrapolate.json" holds
// per-material extrapolation parameters. .ktx2 and .dds are exported textures.
enum class FileKind {
  kCapture,        // .bpc
  kMaterial,       // material .json
  kTexture,        // .ktx2 or .dds
  kSidecar,        // LUT sidecar .json
  kAtlasManifest,  // atlas manifest .json
  kExtrapolation,  // <name>.extrapolate.json
  kOtherJson,      // a JSON file that is none of the above
  kUnknown,        // any other extension
};
const char* FileKindName(FileKind kind);

// Classifies `path`. Reads .json files (at most 16 MiB); other kinds by extension only.
// Throws IoError if a .json cannot be read, FormatError if it is not valid JSON.
FileKind ClassifyFile(const std::string& path);

// The output name of an input: its file name without the extension ("gold.bpc" → "gold").
std::string OutputNameOf(const std::string& path);

// The reference instrument's geometry (DESIGN §1): θin 0/20/40/60°, θout 0–75°, φout 0–359°,
// all at 1° steps. Material files are "captured" on it before resampling, so an analytic
// material goes through exactly the path of a real capture (including the §6 extrapolation
// beyond 75°).
struct CaptureGeometry {
  std::vector<double> theta_in_deg = {0, 20, 40, 60};
  int theta_out_max_deg = 75;  // inclusive, 1° steps from 0°
  int phi_out_count = 360;     // φout = 0°, 1°, …, 359°
};

// A noise-free capture of `material` on `geometry`: f_r evaluated directly for every sample
// (light at (θin, φin = 0), viewer at (θout, φout)), no flags, no σ. The metadata names the
// material and `source`.
Measurement CaptureMaterialNoiseFree(const Material& material, const std::string& source,
                                     const CaptureGeometry& geometry = {});

// Reads a .bpc for turning into a LUT, under this rule (a capture missing slices is not a
// complete LUT):
//  - any corrupt chunk (CRC mismatch, inconsistent fields) or a cut inside a slice chunk:
//    refused, naming the byte offset and slice, with advice (resume or recapture);
//  - a slice flagged incomplete (the instrument stopped mid-slice): refused;
//  - no end chunk (the capture was never finalised, or its end chunk is cut) but no slice
//    damaged: converted, with a warning, only if every planned θin slice is present. The plan
//    is the metadata's extra "theta_in_deg" ("0, 20, 40, 60") when the capturing tool recorded
//    it, else the reference instrument's 0, 20, 40, 60°; otherwise refused with the resume
//    advice;
//  - bytes after the end chunk: converted, with a warning.
// Warnings are appended to `warnings` (full sentences starting with the path).
// Throws FormatError (damage, unreadable header) or IoError.
Measurement LoadCaptureForLut(const std::string& path, std::vector<std::string>* warnings);

// The §6 extrapolation parameters for one input and where they came from. Precedence, most
// specific first: "<stem>.extrapolate.json" beside the input; the input's own "extrapolate"
// member (material files); `command_line` (--extrapolate); the defaults p = 1, l = 0.5.
struct ExtrapolationChoice {
  processing::ExtrapolationParams params;
  std::string origin;  // "defaults", "--extrapolate", or the file it was read from
};
// Throws FormatError / IoError for an unreadable or invalid per-material file.
ExtrapolationChoice ChooseExtrapolation(
    const std::string& input_path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line,
    std::vector<std::string>* warnings);

// A capture or material file opened as a measurement ready to resample.
struct PreparedMeasurement {
  Measurement measurement;
  ExtrapolationChoice extrapolation;
  std::vector<std::string> warnings;
};
// `kind` must be kCapture or kMaterial (InvalidArgument otherwise).
PreparedMeasurement PrepareMeasurement(
    const std::string& path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line);

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
// that texture. Throws IoError / FormatError.
OpenedTexture OpenExportedTexture(const std::string& path);

// An exported LUT sampled exactly as a GPU samples the 3D texture (brdf::Lut::SampleAngles:
// DESIGN §5 centre-exact coordinates, trilinear, clamp-to-edge). The light's azimuth is folded
// into φout (isotropic LUT, light stored at φin = 0). Zero when either direction is at or below
// the horizon (the BrdfSource contract); θin between slices is interpolated as the hardware
// interpolates along w.
class LutBrdf final : public BrdfSource {
 public:
  LutBrdf(Lut lut, std::string name) : lut_(std::move(lut)), name_(std::move(name)) {}
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  std::string Name() const override { return name_; }
  const Lut& lut() const { return lut_; }

 private:
  Lut lut_;
  std::string name_;
};

// Opens any evaluable file for `brdf eval`: a material file (analytic), a .bpc capture
// (interpolated by processing::MeasurementBrdf with the extrapolation ChooseExtrapolation
// picks), a .ktx2 / .dds LUT or a sidecar (LutBrdf); any other file goes to
// brdf::OpenBrdfSource (measured databases: RGL .bsdf, MERL .binary). Atlases are refused (they
// hold many materials). Warnings (an unfinished capture, a DDS without sidecar whose θin list is
// assumed) are appended to `warnings`.
std::unique_ptr<BrdfSource> OpenEvalSource(
    const std::string& path, const std::optional<processing::ExtrapolationParams>& command_line,
    std::vector<std::string>* warnings);

// A LUT ready to export or to place in an atlas, built from any input `brdf convert` or
// `brdf atlas` accepts: captures and material files are resampled (processing::BuildLut with
// the chosen extrapolation); exported LUTs (.ktx2, .dds, sidecar) are decoded as stored.
struct InputLut {
  Lut lut;
  std::optional<exporter::ExtrapolationInfo> extrapolation;  // what filled θout > θb
  std::vector<std::string> warnings;
};
InputLut LutFromInput(const std::string& path, FileKind kind,
                      const std::optional<processing::ExtrapolationParams>& command_line,
                      const processing::ResampleOptions& resample_options);

}  // namespace brdf::cli
