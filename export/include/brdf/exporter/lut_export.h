// One call that writes every output of one LUT (what `brdf convert` does per input).
//
// ExportLut packs the LUT to RGB9E5 once and writes OUT_DIR/<name>.ktx2, .dds, .exr, .png and
// .json (the sidecar) for the selected formats, each atomically: a file appears under its
// final name only when complete, so an interrupted batch never leaves a half-written texture.
// The sidecar lists the files written beside it.
//
// With compression kBc6h the KTX2 and DDS hold BC6H_UF16 blocks instead (bc6h.h,
// lut_compression.h): the sidecar's payload and checksum are the blocks', its "compression"
// member the certified error; the EXR (float or half, from the float LUT) and the PNG are the
// same as without compression, the EXR carrying that same sidecar.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/exr.h"
#include "brdf/exporter/lut_compression.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter {

struct LutExportFormats {
  bool ktx2 = true, dds = true, exr = true, png = true, json = true;
};
// Parses a comma-separated list such as "ktx2,dds,exr,png,json" (case-sensitive, no
// duplicates needed, at least one). Throws InvalidArgument naming an unknown entry and the
// known ones.
LutExportFormats ParseExportFormats(std::string_view list);

struct LutExportOptions {
  LutExportFormats formats;
  ExrOptions exr;
  LutCompression compression = LutCompression::kNone;
  int jobs = 1;  // threads for the BC6H encoder and the compact build (0 = one per core)
  // `--max-error E` (a fraction; 0 = not given): `compression` is ignored and the smallest of
  // the compact form, BC6H and RGB9E5 whose certified measured-range max error is at most E is
  // written (RGB9E5, the most precise, when none is); the choice goes into the result and the
  // sidecar. With kCompact alone, the compact form's target (default kCompactDefaultMaxError).
  double max_error = 0;
  // false: max_error picks from BC6H and RGB9E5 only (the engine kits, which cannot sample the
  // compact form: brdf/engines/engine_export.h).
  bool max_error_allows_compact = true;
};

struct LutExportResult {
  std::vector<std::string> written;  // paths, in the order ktx2, dds, exr, png, json
  std::uint64_t payload_bytes = 0;   // RGB9E5 (or BC6H) bytes in each of the KTX2 and DDS files
  std::uint32_t payload_crc32 = 0;   // the sidecar's checksum
  std::optional<CertifiedError> certified_error;  // set when compressed or chosen by max_error
  LutCompression chosen = LutCompression::kNone;  // the representation written
  bool met_max_error = true;  // false: even the chosen one misses max_error (or the compact target)
  // The BC6H blocks the KTX2 and DDS hold, when chosen is kBc6h (for the engine hand-offs).
  std::optional<Bc6hVolume> bc6h;
};

// The files ExportLut writes for `name` into `out_dir` with `formats`, in its order (ktx2, dds,
// brdfc, exr, png, json): the list a caller's overwrite check covers before any work. With
// kCompact the .brdfc takes the place of the KTX2 and DDS (written when either is selected);
// with `any_representation` (max_error given) every file either could be is listed.
std::vector<std::string> LutExportPaths(const std::string& out_dir, const std::string& name,
                                        const LutExportFormats& formats,
                                        LutCompression compression = LutCompression::kNone,
                                        bool any_representation = false);
// The same for the options ExportLut is given.
std::vector<std::string> LutExportPaths(const std::string& out_dir, const std::string& name,
                                        const LutExportOptions& options);
// "RGB9E5", "BC6H" or "compact", for messages.
const char* LutCompressionName(LutCompression compression);

// `metadata.name` names the files (must be non-empty and a plain file name);
// `metadata.companion_files` is filled in here. The folder must exist.
// Throws InvalidArgument (bad name, unexportable LUT) or IoError.
LutExportResult ExportLut(const std::string& out_dir, const Lut& lut, TextureMetadata metadata,
                          const LutExportOptions& options = {});
// The same with the LUT already packed (PackLut(lut)), for callers that need the words too.
LutExportResult ExportLut(const std::string& out_dir, const Lut& lut, const PackedVolume& packed,
                          TextureMetadata metadata, const LutExportOptions& options = {});

}  // namespace brdf::exporter
