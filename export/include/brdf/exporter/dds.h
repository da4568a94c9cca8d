// DirectDraw Surface container for RGB9E5 LUTs and atlases (docs/design.md §7).
//
// Layout written (Microsoft "DDS" programming guide: DDS_HEADER, DDS_PIXELFORMAT,
// DDS_HEADER_DXT10), all fields little-endian 32-bit:
//   "DDS " magic; DDS_HEADER (124 bytes): dwFlags = CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT
//   | MIPMAPCOUNT | DEPTH (0x0082100F), dwHeight, dwWidth, dwPitchOrLinearSize = width · 4,
//   dwDepth = K, dwMipMapCount = 1, DDS_PIXELFORMAT {dwSize 32, dwFlags DDPF_FOURCC,
//   dwFourCC "DX10"}, dwCaps = DDSCAPS_TEXTURE (a single-level volume is one surface, so no
//   DDSCAPS_COMPLEX, as DirectXTex writes it), dwCaps2 = DDSCAPS2_VOLUME;
//   DDS_HEADER_DXT10 (20 bytes): dxgiFormat 67 (DXGI_FORMAT_R9G9B9E5_SHAREDEXP),
//   resourceDimension 4 (D3D10_RESOURCE_DIMENSION_TEXTURE3D), miscFlag 0, arraySize 1,
//   miscFlags2 0; then the texels, byte for byte the same payload as the KTX2 level 0 image
//   (slice by slice, rows top first), starting at byte 148.
//
// A compressed LUT (`--compress bc6h`, bc6h.h) has dxgiFormat 95 (DXGI_FORMAT_BC6H_UF16),
// dwWidth/dwHeight the texel size (361 × 181, not rounded to blocks), DDSD_LINEARSIZE (0x80000)
// instead of DDSD_PITCH with dwPitchOrLinearSize = the bytes of one slice's blocks
// (ceil(w/4)·ceil(h/4)·16 = 66,976 for a LUT, as DirectXTex writes it), and the blocks of
// Bc6hVolume from byte 148: the same bytes as the KTX2 level 0 image.
//
// DDS has no place for metadata: the θin list travels in the sidecar (sidecar.h) beside it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/exporter/texture_file.h"

namespace brdf::exporter {

// The 4 bytes every DDS file starts with: "DDS " (the little-endian word 0x20534444).
inline constexpr std::array<std::uint8_t, 4> kDdsMagic = {'D', 'D', 'S', ' '};

inline constexpr std::uint32_t kDxgiFormatR9g9b9e5Sharedexp = 67;
inline constexpr std::size_t kDdsDataOffset = 4 + 124 + 20;

// The 148-byte header above for any single-mip 3D texture: `dxgi_format` and the row pitch
// width · bytes_per_texel vary (e.g. DXGI_FORMAT_R16G16B16A16_FLOAT = 10, 8 bytes per texel,
// for engines whose DDS importers do not take format 67). The caller appends the texels.
std::string DdsVolumeHeader(int width, int height, int depth, std::uint32_t dxgi_format,
                            int bytes_per_texel);

// The same header for a single-mip 2D texture (no DDSD_DEPTH, no volume cap, dimension
// TEXTURE2D): the engine kit's RGBA16F IBL pack (brdf/engines/engine_export.h).
std::string DdsTexture2dHeader(int width, int height, std::uint32_t dxgi_format,
                               int bytes_per_texel);

// The whole file in memory. Throws InvalidArgument for an inconsistent volume.
std::string EncodeDds(const PackedVolume& volume);

// Writes atomically (temporary sibling renamed into place). Throws InvalidArgument, IoError.
void WriteDds(const std::string& path, const Lut& lut);
void WriteDds(const std::string& path, const PackedVolume& volume);
// The BC6H form (DXGI 95).
std::string EncodeDds(const Bc6hVolume& volume);
void WriteDds(const std::string& path, const Bc6hVolume& volume);

// Reads and validates a DDS file of this format. θin comes from `theta_in_deg` when given
// (must have depth entries), else the assumed layout of texture_file.h
// (theta_in_from_metadata = false); ReadTextureFile looks for the sidecar instead. Throws IoError /
// FormatError ("expected DXGI format 67 (DXGI_FORMAT_R9G9B9E5_SHAREDEXP) or 95
// (DXGI_FORMAT_BC6H_UF16), got unsupported DXGI format 71").
LoadedTexture ReadDds(const std::string& path, const std::vector<double>& theta_in_deg = {});
LoadedTexture ParseDds(const std::uint8_t* data, std::size_t size, const std::string& file,
                       const std::vector<double>& theta_in_deg = {});

}  // namespace brdf::exporter
