// BC6H_UF16: the unsigned HDR block format of D3D11+/Vulkan/Metal (docs/design.md §7).
//
// The compressed form of a LUT (`--compress bc6h`): KTX2 vkFormat 131
// VK_FORMAT_BC6H_UFLOAT_BLOCK, DXGI_FORMAT_BC6H_UF16 = 95, WebGL/OpenGL
// COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT (0x8E8F). Decoding follows the BPTC_FLOAT section of the
// OpenGL extension ARB_texture_compression_bptc (the same format as Microsoft's "BC6H Format"
// description) to the bit, for the unsigned variant only:
//
//   Block. 16 bytes = 128 bits, read LSB first (bit i is bit i%8 of byte i/8). It covers 4 × 4
//   texels; texel (x, y) of the block is texel number y·4 + x (x fastest, row 0 at the top).
//   Mode. If bits 1..0 are 0 or 1 they are the mode number, else bits 4..0 are (2, 6, 10,
//   14, 18, 22, 26, 30 two-subset; 3, 7, 11, 15 one-subset; 19, 23, 27, 31 reserved: the block
//   decodes to black). Every mode has an endpoint precision EPB, per-channel delta bits and a
//   flag "transformed" (all but modes 30 and 3):
//       mode  0: 10 {5,5,5}   1: 7 {6,6,6}   2: 11 {5,4,4}   6: 11 {4,5,4}  10: 11 {4,4,5}
//            14:  9 {5,5,5}  18: 8 {6,5,5}  22:  8 {5,6,5}  26:  8 {5,5,6}  30:  6 (raw)
//             3: 10 (raw)     7: 11 {9,9,9}  11: 12 {8,8,8}  15: 16 {4,4,4}
//   Fields. The endpoints e0 = (r0,g0,b0), e1, and for two subsets e2, e3 are scattered over
//   the first 77 (two subsets) or 65 (one subset) bits in the per-mode order of the
//   specification's Table.F (bc6h.cpp spells it out); two-subset modes then hold a 5-bit
//   partition number (bits 77..81), choosing one of the first 32 two-subset partitions of
//   BPTC's Table.P2.
//   Transform. In transformed modes e1..e3 are signed deltas of their channel's delta width,
//   sign-extended and added to e0 modulo 2^EPB.
//   Unquantize. x → 0 if x = 0; 0xFFFF if x = 2^EPB − 1; x if EPB ≥ 15; else
//   ((x << 16) + 0x8000) >> EPB.
//   Indices. From bit 65 (one subset, 4 bits each) or 82 (two subsets, 3 bits each), texel by
//   texel; the anchor texels (texel 0, and for two subsets the second subset's anchor of
//   Table.A2) have one bit fewer (their top bit is 0).
//   Interpolation. With w from {0,4,9,13,17,21,26,30,34,38,43,47,51,55,60,64} (4-bit) or
//   {0,9,18,27,37,46,55,64} (3-bit): c = ((64 − w)·a + w·b + 32) >> 6, then the texel's half
//   float is (c · 31) >> 6 (at most 0x7BFF = 65504: never Inf or NaN).
//
// What the encoder does (EncodeBc6hBlock). It works in the half-float bit domain, where equal
// steps are nearly equal relative steps, so minimising squared error there minimises relative
// error. Per block: a principal-axis fit of the 16 texels, quantized in the most precise
// one-subset mode whose deltas hold it; if that leaves some texel more than
// kBc6hGoodEnoughHalfSteps off, the 32 partitions are ranked by a two-line fit estimate and,
// when the best estimate is below the one-subset error, the best two partitions are tried in the
// most precise two-subset mode that holds their endpoints. Every candidate gets a least-squares
// endpoint refinement on its chosen indices, and candidates are compared by their exact decoded
// error (the palettes the decoder computes), each channel's squared error in half steps
// weighted by what it costs in the certified metric (a channel's value relative to the texel's
// largest, bounded below: bc6h.cpp, BlockInput). The early exit counts each channel's error in
// half steps of the texel's largest channel (so a dim minor channel does not force the
// two-subset search); the two-subset gate compares the unweighted error. The result depends only on
// the 16 input texels: the same bytes for any thread count.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "brdf/exporter/half.h"

namespace brdf::exporter {

inline constexpr std::size_t kBc6hBlockBytes = 16;
inline constexpr std::uint32_t kVkFormatBc6hUfloatBlock = 131;  // VK_FORMAT_BC6H_UFLOAT_BLOCK
inline constexpr std::uint32_t kDxgiFormatBc6hUf16 = 95;        // DXGI_FORMAT_BC6H_UF16
// The largest value a BC6H_UF16 texel decodes to: half 0x7BFF.
inline constexpr float kBc6hMaxValue = 65504.0f;
// The encoder stops looking beyond one-subset modes for a block whose every texel channel is
// within this many half-float steps of the texel's largest channel (about 0.4–0.8 % of that
// channel's value) of its input.
inline constexpr int kBc6hGoodEnoughHalfSteps = 8;

using Bc6hBlock = std::array<std::uint8_t, kBc6hBlockBytes>;
// 16 texels (x fastest) × RGB, as half-float bit patterns.
using Bc6hHalfTexels = std::array<std::array<std::uint16_t, 3>, 16>;

// Binary16 for the unsigned format: FloatToHalf (brdf/exporter/half.h) clamped to [0, 65504]
// (NaN and negative values → 0, +∞ → 65504), as the format cannot hold anything else.
std::uint16_t FloatToHalfUnsigned(float value);

// Decodes one block bit-exactly as the specification (and so a GPU) does; texels x fastest.
Bc6hHalfTexels DecodeBc6hBlock(const std::uint8_t* block);
// The mode number of a block (0, 1, 2, 3, 6, 7, 10, 11, 14, 15, 18, 22, 26, 30, or a reserved
// 19, 23, 27, 31), for tests and statistics.
int Bc6hBlockMode(const std::uint8_t* block);

// Encodes 16 texels (x fastest, rows top first), RGB floats each, as described above.
// `reference_max` is R of the certified error (brdf/exporter/metadata.h), the largest value of
// the texture the block belongs to: texels below 10^−4·R weigh as that floor (0: no floor
// beyond 2^−14).
Bc6hBlock EncodeBc6hBlock(const float* rgb48, float reference_max = 0.0f);

// A 3D texture of BC6H blocks: the payload of a compressed LUT's KTX2 and DDS files.
//
// Each slice of width × height texels is padded to whole blocks, ceil(width/4) ×
// ceil(height/4), as the KTX2, DDS and OpenGL specifications lay block-compressed images out
// (a 361 × 181 slice is 91 × 46 blocks, covering 364 × 184 texels). Padding texels repeat the
// nearest texel of the slice (clamped coordinates), so they add no values a block must also
// represent; samplers never read them. Blocks are stored block row by block row (top first),
// left to right, slice after slice: the level 0 image of KTX2 and the data of DDS alike.
struct Bc6hVolume {
  int width = 0, height = 0, depth = 0;  // in texels, as the containers record them
  std::vector<std::uint8_t> bytes;       // BlockCount() × 16

  int BlocksWide() const { return (width + 3) / 4; }
  int BlocksHigh() const { return (height + 3) / 4; }
  std::size_t BlockCount() const {
    return static_cast<std::size_t>(BlocksWide()) * BlocksHigh() * depth;
  }
  // Byte offset of the block holding texel (x, y) of slice z.
  std::size_t BlockOffset(int x, int y, int z) const {
    return ((static_cast<std::size_t>(z) * BlocksHigh() + y / 4) * BlocksWide() + x / 4) *
           kBc6hBlockBytes;
  }
  // 91 · 46 · 16 · K: 267,904 bytes for one LUT of K = 4.
  std::size_t ByteSize() const { return bytes.size(); }
  // CRC-32 (as PackedVolume::Crc32) of `bytes`: the checksum a compressed LUT's sidecar records.
  std::uint32_t Crc32() const;
};

// Compresses width × height × depth RGB floats (index ((z·height + y)·width + x)·3 + c) on
// `jobs` threads (brdf::ResolveJobs: 0 = one per core). Throws InvalidArgument for sizes that
// do not match or a dimension outside 1..65536.
Bc6hVolume EncodeBc6hVolume(const float* rgb, int width, int height, int depth, int jobs = 1);

// Decodes every texel inside the image (padding dropped) to RGB floats in the same index order,
// exactly the values a GPU's texelFetch returns. Throws InvalidArgument if `bytes` has the
// wrong size.
std::vector<float> DecodeBc6hVolume(const Bc6hVolume& volume);

}  // namespace brdf::exporter
