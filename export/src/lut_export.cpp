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
                                        const LutExportFormats& formats) {
  std::vector<std::string> paths;
  const std::filesystem::path dir(out_dir);
  for (const auto& [on, ext] : {std::pair{formats.ktx2, ".ktx2"}, std::pair{formats.dds, ".dds"},
                                std::pair{formats.exr, ".exr"}, std::pair{formats.png, ".png"},
                                std::pair{formats.json, ".json"}})
    if (on) paths.push_back((dir / (name + ext)).string());
  return paths;
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
  metadata.companion_files.clear();
  if (f.ktx2) metadata.companion_files.push_back(name + ".ktx2");
  if (f.dds) metadata.companion_files.push_back(name + ".dds");
  if (f.exr) metadata.companion_files.push_back(name + ".exr");
  if (f.png) metadata.companion_files.push_back(name + ".png");

  const std::filesystem::path dir(out_dir);
  const auto path = [&](const char* ext) { return (dir / (name + ext)).string(); };
  LutExportResult result;
  std::optional<CompressedLut> compressed;
  if (options.compression == LutCompression::kBc6h) {
    compressed = CompressLutBc6h(
        lut, metadata.extrapolation ? metadata.extrapolation->theta_b_deg : 90.0, options.jobs);
    metadata.certified_error = compressed->error;
    result.certified_error = compressed->error;
    result.payload_bytes = compressed->blocks.ByteSize();
    result.payload_crc32 = compressed->blocks.Crc32();
  } else {
    result.payload_bytes = packed.ByteSize();
    result.payload_crc32 = packed.Crc32();
  }
  const std::string sidecar = compressed
                                  ? SidecarJson(compressed->blocks, lut.theta_in_deg, metadata)
                                  : SidecarJson(packed, lut.theta_in_deg, metadata);
  if (f.ktx2) {
    const KeyValues kvs{{"brdf.sidecar", sidecar}};
    if (compressed)
      WriteKtx2(path(".ktx2"), compressed->blocks, kvs);
    else
      WriteKtx2(path(".ktx2"), packed, kvs);
    result.written.push_back(path(".ktx2"));
  }
  if (f.dds) {
    if (compressed)
      WriteDds(path(".dds"), compressed->blocks);
    else
      WriteDds(path(".dds"), packed);
    result.written.push_back(path(".dds"));
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
  return result;
}

}  // namespace brdf::exporter
