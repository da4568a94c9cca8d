// KTX 2.0 container for RGB9E5 LUTs and atlases (docs/design.md §7).
//
// Layout written (KTX 2.0 specification, Khronos):
//   identifier «KTX 20» (12 bytes), header (vkFormat 123 = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32,
//   typeSize 4, pixelWidth, pixelHeight, pixelDepth = K, layerCount 0, faceCount 1,
//   levelCount 1, supercompressionScheme 0), index (DFD, key/value data, no supercompression
//   global data), one level index entry, the Data Format Descriptor, the key/value data, then
//   the level 0 image (4-byte aligned: lcm(texel block size 4, 4)).
//
// Data Format Descriptor: one basic descriptor block (Khronos Data Format Specification 1.3,
// versionNumber 2), colour model RGBSDA, primaries BT.709, transfer linear, straight alpha,
// 1×1×1×1 texel block, bytesPlane0 = 4, and six samples, the form the Data Format
// Specification gives for shared-exponent formats and libktx (KTX-Software) requires for this
// vkFormat: for each of R, G, B in turn a mantissa sample (bitOffset 0/9/18, 9 bits, no
// qualifiers, sampleLower 0, sampleUpper 8448) followed by an exponent sample (bitOffset 27,
// 5 bits, qualifier EXPONENT, sampleLower 15 = bias, sampleUpper 31).
//
// Key/value data (sorted by key): "KTXorientation" = "rdi" (row 0 at the top, slices going
// in), "KTXwriter" = "brdf-toolchain <version>", and the project's metadata: "brdf.sidecar"
// (the JSON sidecar text, sidecar.h) for a LUT or "brdf.atlas" (the manifest, atlas.h) for an
// atlas. Values are NUL-terminated UTF-8.
//
// A compressed LUT (`--compress bc6h`, bc6h.h) is the same container with vkFormat 131
// (VK_FORMAT_BC6H_UFLOAT_BLOCK), typeSize 1, pixelWidth/Height/Depth the texel size (361, 181,
// K: not rounded to blocks), the level 0 image the blocks of Bc6hVolume (ceil(w/4)·ceil(h/4)
// per slice, 16 bytes each, slice after slice) starting at a multiple of 16 bytes (lcm(block
// size 16, 4)), and the DFD of the Data Format Specification's BC6H entry, as libktx writes it:
// colour model 131 (KHR_DF_MODEL_BC6H), BT.709, linear, texelBlockDimension 4 × 4 × 1,
// bytesPlane0 = 16, one sample covering bits 0–127 of channel 0 (BC6H colour) with qualifier
// FLOAT, sampleLower 0.0f and sampleUpper 1.0f (44 bytes in all).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/exporter/texture_file.h"

namespace brdf::exporter {

// The 12-byte file identifier every KTX 2.0 file starts with (KTX 2.0 §3.1):
// «KTX 20» CR LF 0x1A LF.
inline constexpr std::array<std::uint8_t, 12> kKtx2Identifier = {
    0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};

inline constexpr std::uint32_t kVkFormatE5b9g9r9UfloatPack32 = 123;

using KeyValues = std::vector<std::pair<std::string, std::string>>;

// The whole file in memory. KTXwriter and KTXorientation are added to `key_values`; the
// pairs are written sorted by key as the specification requires. Keys must be non-empty,
// unique and free of NUL; throws InvalidArgument otherwise.
std::string EncodeKtx2(const PackedVolume& volume, const KeyValues& key_values);

// Writes a LUT atomically (temporary sibling renamed into place) with its sidecar JSON
// embedded as "brdf.sidecar". Throws InvalidArgument for an unexportable LUT, IoError.
void WriteKtx2(const std::string& path, const Lut& lut, const TextureMetadata& metadata);
// The same for an already packed LUT (PackLut), so several containers share one encoding.
void WriteKtx2(const std::string& path, const PackedVolume& volume,
               const std::vector<double>& theta_in_deg, const TextureMetadata& metadata);
// Writes any volume with the given key/value pairs (atlases).
void WriteKtx2(const std::string& path, const PackedVolume& volume, const KeyValues& key_values);
// The BC6H forms (vkFormat 131) of EncodeKtx2 and WriteKtx2.
std::string EncodeKtx2(const Bc6hVolume& volume, const KeyValues& key_values);
void WriteKtx2(const std::string& path, const Bc6hVolume& volume, const KeyValues& key_values);

// Reads and validates a KTX2 file written by us or any conforming writer of these formats.
LoadedTexture ReadKtx2(const std::string& path);
// Parses KTX2 bytes already in memory; `file` names them in errors (also the fuzz entry).
LoadedTexture ParseKtx2(const std::uint8_t* data, std::size_t size, const std::string& file);

// The 124-byte DFD described above (dfdTotalSize word included), as 31 little-endian words.
std::vector<std::uint32_t> E5b9g9r9DataFormatDescriptor();
// The 44-byte BC6H_UFLOAT DFD described above, as 11 words.
std::vector<std::uint32_t> Bc6hUfloatDataFormatDescriptor();

}  // namespace brdf::exporter
