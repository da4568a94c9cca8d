// The JSON sidecar of an exported LUT (docs/design.md §7).
//
// One small text file beside the textures that says what they hold: the source, the θin list,
// the grid, both texel conventions (the centre-exact one we address texels with, and the
// published one that drops the half-texel term), the extrapolation parameters, fitted models
// (if any), the tool version and a checksum of the texel data. The same JSON text is embedded
// in the KTX2 key/value data (key "brdf.sidecar") and the EXR header (attribute
// "brdf:sidecar").
//
// Checksum: CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib's crc32) of the
// RGB9E5 payload bytes exactly as stored in the KTX2 level 0 image and the DDS data: 4 bytes
// per texel, little-endian words, x fastest then y (rows, top first) then z (slices, θin
// ascending). The payload size is recorded too: 361·181·K·4 bytes, 1,045,456 for K = 4
// (docs/design.md §5). For a BC6H payload (`--compress bc6h`) checksum and size are those of
// the blocks as stored (91·46·K·16 bytes, 267,904 for K = 4), and "compression" records the
// certified error of the decoded texels against the float LUT (docs/design.md §7).
//
// Example (abridged):
//   { "kind": "brdf-lut-sidecar", "format_version": 1, "name": "gold", "source": "gold.bpc",
//     "theta_in_deg": [0, 20, 40, 60],
//     "grid": { "width": 361, "height": 181, "slices": 4, "delta_in_deg": 20, ... },
//     "texel_convention": { "centre_exact": "u = (phi_d/1deg + 0.5)/361, ...",
//                           "published": "u = phi_d/(2 pi), ..." },
//     "extrapolation": { "p": 1, "l": 0.5, "theta_b_deg": 75, ... },
//     "saturated_samples": [{ "theta_in_deg": 0, "count": 0 }, { "theta_in_deg": 20, "count": 12 },
//                           ...],   (only when known; samples flagged saturated, per slice)
//     "fitted_models": [], "tool": { "name": "brdf-toolchain", "version": "0.1.0" },
//     "payload": { "bytes": 1045456, "checksum": { "algorithm": "crc32", "value": "0x…" } },
//     "files": ["gold.ktx2", "gold.dds"] }
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter {

// The sidecar JSON text (2-space indent) for a payload and its θin list.
std::string SidecarJson(const PackedVolume& payload, const std::vector<double>& theta_in_deg,
                        const TextureMetadata& metadata);
// The same for a BC6H payload (`--compress bc6h`): "payload" then starts with "format":
// "bc6h_ufloat", its bytes and checksum are the blocks', and metadata.certified_error is
// written as "compression": { "format", "bytes", "rgb9e5_bytes", "certified_error": {
// "definition", "theta_b_deg", "measured": { "max", "p99", "median", "texels" }, "filled": {…} } }
// (fractions, not percent).
std::string SidecarJson(const Bc6hVolume& payload, const std::vector<double>& theta_in_deg,
                        const TextureMetadata& metadata);

// The same for a compact LUT (`--compress compact`, compact_lut.h): "payload" starts with
// "format": "compact_log_grid"; bytes and checksum are CompactLut::PayloadBytes and
// CompactPayloadCrc32.
std::string SidecarJson(const CompactLut& payload, const TextureMetadata& metadata);

// Writes SidecarJson atomically to `path`. Throws IoError.
void WriteSidecar(const std::string& path, const PackedVolume& payload,
                  const std::vector<double>& theta_in_deg, const TextureMetadata& metadata);
void WriteSidecar(const std::string& path, const Bc6hVolume& payload,
                  const std::vector<double>& theta_in_deg, const TextureMetadata& metadata);

// What a sidecar says, parsed back.
struct SidecarInfo {
  std::string name, source;
  std::vector<double> theta_in_deg;
  int width = 0, height = 0, slices = 0;
  std::string payload_format = "rgb9e5";  // or "bc6h_ufloat", "compact_log_grid"
  std::uint64_t payload_bytes = 0;
  std::uint32_t payload_crc32 = 0;
  std::optional<CertifiedError> certified_error;  // the "compression" member, when present
  std::optional<ExtrapolationInfo> extrapolation;
  std::optional<std::vector<SaturatedCount>> saturated_samples;  // absent: not recorded
  std::vector<std::string> fitted_models_json;                   // each model as compact JSON text
  std::string beyond_json;  // the blind-spot fill's "beyond" record, compact; empty: absent
  std::string tool_version;
  std::vector<std::string> files;  // companion file names
};

// Parses a sidecar text; `file` names it in errors. Throws FormatError naming the member and
// what was expected.
SidecarInfo ParseSidecarJson(std::string_view json_text, const std::string& file = "<sidecar>");
// Reads and parses a sidecar file (at most 16 MiB). Throws IoError / FormatError.
SidecarInfo ReadSidecar(const std::string& path);

}  // namespace brdf::exporter
