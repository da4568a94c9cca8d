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
  int jobs = 1;  // threads for the BC6H encoder (0 = one per core)
};

struct LutExportResult {
  std::vector<std::string> written;  // paths, in the order ktx2, dds, exr, png, json
  std::uint64_t payload_bytes = 0;   // RGB9E5 (or BC6H) bytes in each of the KTX2 and DDS files
  std::uint32_t payload_crc32 = 0;   // the sidecar's checksum
  std::optional<CertifiedError> certified_error;  // set when compressed
};

// The files ExportLut writes for `name` into `out_dir` with `formats`, in its order (ktx2, dds,
// exr, png, json): the list a caller's overwrite check covers before any work.
std::vector<std::string> LutExportPaths(const std::string& out_dir, const std::string& name,
                                        const LutExportFormats& formats);

// `metadata.name` names the files (must be non-empty and a plain file name);
// `metadata.companion_files` is filled in here. The folder must exist.
// Throws InvalidArgument (bad name, unexportable LUT) or IoError.
LutExportResult ExportLut(const std::string& out_dir, const Lut& lut, TextureMetadata metadata,
                          const LutExportOptions& options = {});
// The same with the LUT already packed (PackLut(lut)), for callers that need the words too.
LutExportResult ExportLut(const std::string& out_dir, const Lut& lut, const PackedVolume& packed,
                          TextureMetadata metadata, const LutExportOptions& options = {});

}  // namespace brdf::exporter
