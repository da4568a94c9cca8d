#include "brdf/exporter/texture_file.h"

#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/rgb9e5.h"
#include "brdf/exporter/sidecar.h"

namespace brdf::exporter {
namespace {

void CheckRecordedPayload(const LoadedTexture& t, const std::string& what, int width, int height,
                          int depth, std::uint64_t bytes, std::uint32_t crc) {
  const PackedVolume& v = t.volume;
  if (width != v.width || height != v.height || depth != v.depth)
    throw FormatError(
        t.file, what,
        fmt::format("a {} × {} × {} texture as the metadata records", width, height, depth),
        fmt::format("{} × {} × {}", v.width, v.height, v.depth));
  if (bytes != t.PayloadBytes())
    throw FormatError(t.file, what,
                      fmt::format("a payload of {} bytes as the metadata records", bytes),
                      std::to_string(t.PayloadBytes()) + " bytes");
  const std::uint32_t actual = t.PayloadCrc32();
  if (actual != crc)
    throw FormatError(t.file, what, "payload CRC-32 " + Hex32Text(crc) + " as the metadata records",
                      Hex32Text(actual), "the texel data was changed or damaged");
}

}  // namespace

void FinishLoadedTexture(LoadedTexture& t) {
  // Metadata read beside a DDS is named by its own file, embedded metadata by the texture's.
  const bool beside = !t.metadata_file.empty();
  if (!t.sidecar_json.empty()) {
    const SidecarInfo info =
        ParseSidecarJson(t.sidecar_json, beside ? t.metadata_file : t.file + " (embedded sidecar)");
    const std::string what = beside ? "sidecar " + t.metadata_file : "embedded sidecar";
    const bool recorded_bc6h = info.payload_format == "bc6h_ufloat";
    if (recorded_bc6h != (t.format == TexelFormat::kBc6hUfloat))
      throw FormatError(t.file, what,
                        std::string("a ") + (recorded_bc6h ? "BC6H_UF16" : "RGB9E5") +
                            " texture as the metadata records",
                        std::string("a ") + t.FormatName() + " texture");
    CheckRecordedPayload(t, what, info.width, info.height, info.slices, info.payload_bytes,
                         info.payload_crc32);
    t.theta_in_deg = info.theta_in_deg;
    t.theta_in_from_metadata = true;
  } else if (!t.atlas_manifest_json.empty()) {
    const AtlasManifest m = ParseAtlasManifest(
        t.atlas_manifest_json, beside ? t.metadata_file : t.file + " (embedded manifest)");
    const std::string what =
        beside ? "atlas manifest " + t.metadata_file : "embedded atlas manifest";
    const bool recorded_bc6h = m.payload_format == "bc6h_ufloat";
    if (recorded_bc6h != (t.format == TexelFormat::kBc6hUfloat))
      throw FormatError(t.file, what,
                        std::string("a ") + (recorded_bc6h ? "BC6H_UF16" : "RGB9E5") +
                            " texture as the manifest records",
                        std::string("a ") + t.FormatName() + " texture");
    CheckRecordedPayload(t, what, m.texture_width, m.texture_height,
                         static_cast<int>(m.theta_in_deg.size()), m.payload_bytes, m.payload_crc32);
    t.theta_in_deg = m.theta_in_deg;
    t.theta_in_from_metadata = true;
  } else if (t.theta_in_deg.size() != static_cast<std::size_t>(t.volume.depth)) {
    // No metadata: the layouts the toolchain writes (docs/design.md §5): the reference
    // spacing θin,k = k·20° while it stays within 0–80° (K ≤ 5), else the filled LUT's 0–80°
    // in K − 1 equal steps (K = 9: every 10°, the default of the blind-spot fill).
    t.theta_in_deg.clear();
    const int depth = t.volume.depth;
    const double step = depth <= 5 ? 20.0 : 80.0 / (depth - 1);
    for (int k = 0; k < depth; ++k) t.theta_in_deg.push_back(step * k);
    t.theta_in_from_metadata = false;
  }
  t.lut = Lut();
  if (t.volume.width == Lut::kWidth && t.volume.height == Lut::kHeight) {
    if (t.format == TexelFormat::kBc6hUfloat) {
      t.lut.theta_in_deg = t.theta_in_deg;
      t.lut.texels = DecodeBc6hVolume(t.bc6h);
    } else {
      t.lut = UnpackLut(t.volume, t.theta_in_deg);
    }
  }
}

std::uint64_t LoadedTexture::PayloadBytes() const {
  return format == TexelFormat::kBc6hUfloat ? bc6h.ByteSize() : volume.ByteSize();
}

std::uint32_t LoadedTexture::PayloadCrc32() const {
  return format == TexelFormat::kBc6hUfloat ? bc6h.Crc32() : volume.Crc32();
}

std::array<float, 3> LoadedTexture::TexelValue(int x, int y, int z) const {
  if (format == TexelFormat::kRgb9e5) return DecodeRgb9e5(volume.words[volume.Index(x, y, z)]);
  const Bc6hHalfTexels block = DecodeBc6hBlock(bc6h.bytes.data() + bc6h.BlockOffset(x, y, z));
  const auto& h = block[(y % 4) * 4 + x % 4];
  return {HalfToFloat(h[0]), HalfToFloat(h[1]), HalfToFloat(h[2])};
}

const char* LoadedTexture::FormatName() const {
  return format == TexelFormat::kBc6hUfloat ? "BC6H_UF16" : "RGB9E5";
}

LoadedTexture ReadTextureFile(const std::string& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path, kMaxTextureFileBytes);
  // «KTX 20 names the family: a file whose identifier is damaged after it is the KTX2 reader's
  // to report.
  if (bytes.size() >= 12 && std::memcmp(bytes.data(), kKtx2Identifier.data(), 7) == 0)
    return ParseKtx2(bytes.data(), bytes.size(), path);
  if (bytes.size() >= kDdsMagic.size() &&
      std::memcmp(bytes.data(), kDdsMagic.data(), kDdsMagic.size()) == 0) {
    LoadedTexture t = ParseDds(bytes.data(), bytes.size(), path);
    std::filesystem::path sidecar(path);
    sidecar.replace_extension(".json");
    std::error_code ec;
    if (std::filesystem::is_regular_file(sidecar, ec) &&
        !std::filesystem::equivalent(sidecar, path, ec)) {
      // "<prefix>.json" beside an atlas is its manifest, beside a LUT its sidecar.
      std::string text = ReadFileText(sidecar.string(), 16u << 20);
      t.metadata_file = sidecar.string();
      if (text.find("\"brdf-atlas-manifest\"") != std::string::npos)
        t.atlas_manifest_json = std::move(text);
      else
        t.sidecar_json = std::move(text);
      FinishLoadedTexture(t);
    }
    return t;
  }
  std::string head;
  for (std::size_t i = 0; i < std::min<std::size_t>(bytes.size(), 8); ++i)
    head += fmt::format("{:02x} ", bytes[i]);
  throw FormatError(path, BytePosition(0), "a KTX2 («KTX 20») or DDS (\"DDS \") texture",
                    bytes.empty() ? std::string("an empty file") : "bytes " + head);
}

}  // namespace brdf::exporter
