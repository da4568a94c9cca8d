// Reading exported textures back: what the KTX2 and DDS readers return, and one entry point
// that recognises either container by its content.
//
// Used by `brdf eval` / `brdf info` and by the tests. Readers validate every header field the
// payload depends on and fail with a FormatError naming the file, the byte offset, what was
// expected and what was found ("gold.ktx2: byte 12: expected vkFormat 123
// (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32), got 97"). Allocation is bounded by the file size, which
// is capped at kMaxTextureFileBytes before anything is read.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter {

// 2 GiB: an atlas of ~250 materials of 4 slices; anything larger is refused unread.
inline constexpr std::uint64_t kMaxTextureFileBytes = 2ull << 30;

enum class TextureContainer { kKtx2, kDds };
// What the texels are: RGB9E5 words (the default export) or BC6H_UF16 blocks (`--compress
// bc6h`, bc6h.h).
enum class TexelFormat { kRgb9e5, kBc6hUfloat };

struct LoadedTexture {
  std::string file;
  TextureContainer container = TextureContainer::kKtx2;
  TexelFormat format = TexelFormat::kRgb9e5;
  // The texture's size in texels, and for kRgb9e5 the words exactly as stored (for
  // kBc6hUfloat `words` stays empty and the blocks are in `bc6h`).
  PackedVolume volume;
  Bc6hVolume bc6h;  // the BC6H blocks exactly as stored (kBc6hUfloat)
  // KTX2 key/value pairs in file order, values without their terminating NUL. Empty for DDS.
  std::vector<std::pair<std::string, std::string>> key_values;
  // Embedded metadata: the sidecar JSON of a single LUT ("brdf.sidecar") or the manifest of an
  // atlas ("brdf.atlas"); empty when absent (DDS files, third-party KTX2 files).
  std::string sidecar_json;
  std::string atlas_manifest_json;
  // Where sidecar_json / atlas_manifest_json came from when not embedded: the "<stem>.json"
  // read beside a DDS file (errors in it name that file); empty for embedded metadata.
  std::string metadata_file;
  // The θin list (degrees) from the embedded metadata or a sidecar found beside a DDS file;
  // otherwise the toolchain's layout for the slice count (k·20° for K ≤ 5, else 0–80° in
  // K − 1 equal steps; docs/design.md §5) with theta_in_from_metadata = false.
  std::vector<double> theta_in_deg;
  bool theta_in_from_metadata = false;
  // The decoded LUT when the texture is a single 361 × 181 × K LUT; empty (no slices) for an
  // atlas.
  Lut lut;

  bool IsSingleLut() const { return lut.slices() > 0; }
  // The stored payload, whatever the format: its size and CRC-32 (what metadata records).
  std::uint64_t PayloadBytes() const;
  std::uint32_t PayloadCrc32() const;
  // Texel (x, y, z) decoded exactly as a GPU's texelFetch returns it.
  std::array<float, 3> TexelValue(int x, int y, int z) const;
  // "RGB9E5" or "BC6H_UF16", for messages.
  const char* FormatName() const;
};

// Reads a .ktx2 or .dds file, recognised by its first bytes (not its extension). For a DDS
// file, a sidecar "<stem>.json" beside it, if present and of the same size, supplies the θin
// list and its checksum is verified (a DDS saved under a .json name is not its own sidecar).
// Throws IoError / FormatError.
LoadedTexture ReadTextureFile(const std::string& path);

// Fills theta_in_deg, theta_in_from_metadata and lut from volume and the embedded metadata,
// and verifies the payload checksum the metadata records. Used by the readers.
// Throws FormatError naming `loaded.file` on a checksum or size mismatch.
void FinishLoadedTexture(LoadedTexture& loaded);

}  // namespace brdf::exporter
