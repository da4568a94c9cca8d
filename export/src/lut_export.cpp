#include "brdf/exporter/lut_export.h"

#include <filesystem>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/sidecar.h"

namespace brdf::exporter {

LutExportFormats ParseExportFormats(std::string_view list) {
  LutExportFormats f{false, false, false, false, false};
  bool any = false;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string_view item = list.substr(start, comma - start);
    if (item == "ktx2") {
      f.ktx2 = true;
    } else if (item == "dds") {
      f.dds = true;
    } else if (item == "exr") {
      f.exr = true;
    } else if (item == "png") {
      f.png = true;
    } else if (item == "json") {
      f.json = true;
    } else {
      throw InvalidArgument("unknown output format '" + std::string(item) +
                            "' (known: ktx2, dds, exr, png, json)");
    }
    any = true;
    start = comma + 1;
  }
  if (!any) throw InvalidArgument("no output format given (known: ktx2, dds, exr, png, json)");
  return f;
}

std::vector<std::string> LutExportPaths(const std::string& out_dir, const std::string& name,
                                        const LutExportFormats& formats, LutCompression compression,
                                        bool any_representation) {
  std::vector<std::string> paths;
  const std::filesystem::path dir(out_dir);
  const bool blocks = any_representation || compression != LutCompression::kCompact;
  const bool compact = (any_representation || compression == LutCompression::kCompact) &&
                       (formats.ktx2 || formats.dds);
  for (const auto& [on, ext] :
       {std::pair{blocks && formats.ktx2, ".ktx2"}, std::pair{blocks && formats.dds, ".dds"},
        std::pair{compact, ".brdfc"}, std::pair{formats.exr, ".exr"},
        std::pair{formats.png, ".png"}, std::pair{formats.json, ".json"}})
    if (on) paths.push_back((dir / (name + ext)).string());
  return paths;
}

std::vector<std::string> LutExportPaths(const std::string& out_dir, const std::string& name,
                                        const LutExportOptions& options) {
  return LutExportPaths(out_dir, name, options.formats, options.compression, options.max_error > 0);
}

const char* LutCompressionName(LutCompression compression) {
  switch (compression) {
    case LutCompression::kBc6h:
      return "BC6H";
    case LutCompression::kCompact:
      return "compact";
    case LutCompression::kNone:
      break;
  }
  return "RGB9E5";
}

LutExportResult ExportLut(const std::string& out_dir, const Lut& lut, TextureMetadata metadata,
                          const LutExportOptions& options) {
  return ExportLut(out_dir, lut, PackLut(lut), std::move(metadata), options);
}

LutExportResult ExportLut(const std::string& out_dir, const Lut& lut, const PackedVolume& packed,
                          TextureMetadata metadata, const LutExportOptions& options) {
  const std::string& name = metadata.name;
  if (name.empty() || name == "." || name == ".." ||
      name.find_first_of("/\\") != std::string::npos || name.find('\0') != std::string::npos)
    throw InvalidArgument("LUT export: the output name must be a plain file name, got '" + name +
                          "'");
  const LutExportFormats& f = options.formats;
  const double theta_b = metadata.extrapolation ? metadata.extrapolation->theta_b_deg : 90.0;
  LutExportResult result;
  std::optional<CompressedLut> compressed;
  std::optional<CompactBuild> compact;
  LutCompression chosen = options.compression;
  if (options.max_error > 0) {
    // The smallest representation meeting the bound: compact, else BC6H, else RGB9E5.
    const double bound = options.max_error;
    if (options.max_error_allows_compact)
      compact = BuildCompactLut(lut, theta_b, bound, options.jobs);
    const std::uint64_t bc6h_bytes = static_cast<std::uint64_t>((Lut::kWidth + 3) / 4) *
                                     ((Lut::kHeight + 3) / 4) * 16 * lut.slices();
    const bool compact_met = compact && compact->met_target;
    if (compact_met && compact->error.bytes < bc6h_bytes) {
      chosen = LutCompression::kCompact;
    } else {
      compressed = CompressLutBc6h(lut, theta_b, options.jobs);
      if (compressed->error.measured.max <= bound) {
        chosen = LutCompression::kBc6h;
        compact.reset();
      } else if (compact_met) {
        chosen = LutCompression::kCompact;
        compressed.reset();
      } else {
        chosen = LutCompression::kNone;
        compressed.reset(), compact.reset();
        result.certified_error = MeasureRgb9e5Error(lut, UnpackLut(packed, lut.theta_in_deg).texels,
                                                    theta_b, packed.ByteSize());
        result.met_max_error = result.certified_error->measured.max <= bound;
      }
    }
  } else if (chosen == LutCompression::kCompact) {
    compact = BuildCompactLut(lut, theta_b, kCompactDefaultMaxError, options.jobs);
    result.met_max_error = compact->met_target;
  } else if (chosen == LutCompression::kBc6h) {
    compressed = CompressLutBc6h(lut, theta_b, options.jobs);
  }
  result.chosen = chosen;
  const bool blocks = chosen != LutCompression::kCompact;
  metadata.companion_files.clear();
  if (blocks && f.ktx2) metadata.companion_files.push_back(name + ".ktx2");
  if (blocks && f.dds) metadata.companion_files.push_back(name + ".dds");
  if (!blocks && (f.ktx2 || f.dds)) metadata.companion_files.push_back(name + ".brdfc");
  if (f.exr) metadata.companion_files.push_back(name + ".exr");
  if (f.png) metadata.companion_files.push_back(name + ".png");

  const std::filesystem::path dir(out_dir);
  const auto path = [&](const char* ext) { return (dir / (name + ext)).string(); };
  if (compact) {
    result.certified_error = compact->error;
    result.payload_bytes = compact->compact.PayloadBytes();
    result.payload_crc32 = CompactPayloadCrc32(compact->compact);
  } else if (compressed) {
    result.certified_error = compressed->error;
    result.payload_bytes = compressed->blocks.ByteSize();
    result.payload_crc32 = compressed->blocks.Crc32();
  } else {
    result.payload_bytes = packed.ByteSize();
    result.payload_crc32 = packed.Crc32();
  }
  if (options.max_error > 0 && result.certified_error) {
    result.certified_error->max_error_bound = options.max_error;
    result.certified_error->max_error_met = result.met_max_error;
  }
  metadata.certified_error = result.certified_error;
  const std::string sidecar = compact ? SidecarJson(compact->compact, metadata)
                              : compressed
                                  ? SidecarJson(compressed->blocks, lut.theta_in_deg, metadata)
                                  : SidecarJson(packed, lut.theta_in_deg, metadata);
  if (blocks && f.ktx2) {
    const KeyValues kvs{{"brdf.sidecar", sidecar}};
    if (compressed)
      WriteKtx2(path(".ktx2"), compressed->blocks, kvs);
    else
      WriteKtx2(path(".ktx2"), packed, kvs);
    result.written.push_back(path(".ktx2"));
  }
  if (blocks && f.dds) {
    if (compressed)
      WriteDds(path(".dds"), compressed->blocks);
    else
      WriteDds(path(".dds"), packed);
    result.written.push_back(path(".dds"));
  }
  if (!blocks && (f.ktx2 || f.dds)) {
    WriteCompactLut(path(".brdfc"), compact->compact, sidecar);
    result.written.push_back(path(".brdfc"));
  }
  if (f.exr) {
    WriteExrComposite(path(".exr"), lut, sidecar, result.payload_crc32, options.exr);
    result.written.push_back(path(".exr"));
  }
  if (f.png) {
    WritePngComposite(path(".png"), lut);
    result.written.push_back(path(".png"));
  }
  if (f.json) {
    WriteFileAtomically(path(".json"), sidecar);
    result.written.push_back(path(".json"));
  }
  if (compressed) result.bc6h = std::move(compressed->blocks);
  return result;
}

}  // namespace brdf::exporter
