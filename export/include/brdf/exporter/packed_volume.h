// A 3D texture of RGB9E5 words: the payload shared by the KTX2 and DDS containers.
//
// Texel (x, y, z) is words[(z·height + y)·width + x]; row y = 0 is the top row (θd = 0° for a
// LUT), slice z = k is θin,k. This is the order both KTX2 (level 0 image) and DDS (volume
// texture) store texels in, so the same bytes go into both files. For a single LUT
// width = 361, height = 181, depth = K (docs/design.md §5); an atlas of M materials has width
// Cm·361 and height Rm·181 (see atlas.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "brdf/core/lut.h"

namespace brdf::exporter {

struct PackedVolume {
  int width = 0, height = 0, depth = 0;
  std::vector<std::uint32_t> words;  // width·height·depth RGB9E5 words

  std::size_t Index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * height + y) * width + x;
  }
  // Payload size in bytes (4 per texel): 361·181·4·4 = 1,045,456 for one LUT of K = 4.
  std::size_t ByteSize() const { return words.size() * 4; }
  // The payload as stored in the files: each word little-endian, in Index order.
  std::string Bytes() const;
  // CRC-32 (IEEE 802.3, as zlib's crc32) of Bytes(): the content checksum written into the
  // sidecar, the KTX2 metadata and the EXR header (docs/design.md §7).
  std::uint32_t Crc32() const;
};

// Encodes every texel of the LUT with EncodeRgb9e5 (width 361, height 181, depth K).
// Throws InvalidArgument if the LUT has no slices or its texel array has the wrong size.
PackedVolume PackLut(const Lut& lut);

// Decodes a 361 × 181 × K volume back into a Lut with the given θin list (K values).
// Throws InvalidArgument naming the mismatch if the sizes do not fit a LUT.
Lut UnpackLut(const PackedVolume& volume, std::vector<double> theta_in_deg);

// Checks a LUT before export: K ≥ 1, texel array of K·181·361·3 floats, θin strictly
// increasing and evenly spaced (the shader addresses slice k as θin/Δin, docs/design.md §5).
// Throws InvalidArgument saying what is wrong.
void ValidateLutForExport(const Lut& lut);

// "0, 20, 40, 60": a θin list for messages and metadata.
std::string FormatThetaList(const std::vector<double>& theta_in_deg);

}  // namespace brdf::exporter
