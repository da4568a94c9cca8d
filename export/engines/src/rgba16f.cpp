// RGBA16F: half floats from floats and from RGB9E5 channels, and the Unreal volume DDS
// (brdf/engines/engine_export.h).
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/engines/engine_export.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/half.h"
#include "rgba16f.h"

namespace brdf::engines {

using detail::StagedFiles;

namespace {

constexpr std::uint32_t kDxgiFormatR16g16b16a16Float = 10;

// Binary16 bits of one RGB9E5 channel value m · 2^(e − 24) (mantissa m < 512, exponent e < 32).
// Every such value is exact in half, so there is nothing to round: it has at most 9
// significant bits and lies in [2^−24, 65408], within half's subnormal step 2^−24 and largest
// finite 65504. Half stores n · 2^−24 for n < 1024 as the subnormal n (here n = m · 2^e), else
// exponent field p + e − 9 (p: the position of m's leading bit, so the value is
// 2^(p + e − 24) · 1.f) and the 10 fraction bits below the leading one.
constexpr std::uint16_t HalfOfRgb9e5Channel(std::uint32_t m, std::uint32_t e) {
  if (m == 0) return 0;
  const int p = std::bit_width(m) - 1;
  const int field = p + static_cast<int>(e) - 9;
  if (field <= 0) return static_cast<std::uint16_t>(m << e);
  return static_cast<std::uint16_t>((static_cast<std::uint32_t>(field) << 10) |
                                    ((m << (10 - p)) & 0x3ffu));
}

// All 32 × 512 channel values, indexed by e · 512 + m (32 KiB, built at compile time).
constexpr auto kHalfOfChannel = [] {
  std::array<std::uint16_t, 32 * 512> t{};
  for (std::uint32_t e = 0; e < 32; ++e)
    for (std::uint32_t m = 0; m < 512; ++m) t[e * 512 + m] = HalfOfRgb9e5Channel(m, e);
  return t;
}();

// One texel: R, G, B halves and alpha 1.0 (0x3c00), little-endian, 8 bytes at `out`.
inline void PutRgba16fTexel(std::uint32_t word, char* out) {
  const std::uint16_t* row = &kHalfOfChannel[(word >> 27) * 512];
  const std::uint64_t texel =
      std::uint64_t{row[word & 511u]} | (std::uint64_t{row[(word >> 9) & 511u]} << 16) |
      (std::uint64_t{row[(word >> 18) & 511u]} << 32) | (std::uint64_t{0x3c00} << 48);
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out, &texel, 8);
  } else {
    for (int b = 0; b < 8; ++b) out[b] = static_cast<char>((texel >> (8 * b)) & 0xffu);
  }
}

void CheckVolume(const exporter::PackedVolume& volume) {
  if (volume.width < 1 || volume.height < 1 || volume.depth < 1 ||
      volume.words.size() != static_cast<std::size_t>(volume.width) * volume.height * volume.depth)
    throw InvalidArgument(fmt::format("RGBA16F DDS: inconsistent volume {} × {} × {}", volume.width,
                                      volume.height, volume.depth));
}

std::string Rgba16fDdsHeader(const exporter::PackedVolume& volume) {
  return exporter::DdsVolumeHeader(volume.width, volume.height, volume.depth,
                                   kDxgiFormatR16g16b16a16Float, 8);
}

}  // namespace

void detail::WriteRgba16fDds(StagedFiles::Writer& w, const exporter::PackedVolume& volume) {
  CheckVolume(volume);
  w.Append(Rgba16fDdsHeader(volume));
  constexpr std::size_t kTexelsPerChunk = StagedFiles::Writer::kChunkBytes / 8;
  for (std::size_t t = 0; t < volume.words.size(); t += kTexelsPerChunk) {
    const std::size_t n = std::min(kTexelsPerChunk, volume.words.size() - t);
    char* out = w.Reserve(n * 8);
    for (std::size_t i = 0; i < n; ++i) PutRgba16fTexel(volume.words[t + i], out + 8 * i);
    w.Keep(n * 8);
  }
}

std::uint16_t Rgb9e5ChannelToHalf(std::uint32_t mantissa, std::uint32_t exponent) {
  if (mantissa > 511 || exponent > 31)
    throw InvalidArgument(fmt::format("RGB9E5 channel: mantissa {} (0..511), exponent {} (0..31)",
                                      mantissa, exponent));
  return kHalfOfChannel[exponent * 512 + mantissa];
}

std::string Rgba16fBytes(const exporter::PackedVolume& volume) {
  std::string out(volume.words.size() * 8, '\0');
  for (std::size_t t = 0; t < volume.words.size(); ++t)
    PutRgba16fTexel(volume.words[t], out.data() + 8 * t);
  return out;
}

std::string EncodeRgba16fDds(const exporter::PackedVolume& volume) {
  CheckVolume(volume);
  return Rgba16fDdsHeader(volume) + Rgba16fBytes(volume);
}

std::string EncodeIblPackDds(const std::vector<const IblPack*>& packs) {
  constexpr int kRows = IblPack::kRows;
  if (packs.empty()) throw InvalidArgument("IBL pack texture: no material");
  std::string out = exporter::DdsTexture2dHeader(kRows, static_cast<int>(packs.size()),
                                                 kDxgiFormatR16g16b16a16Float, 8);
  const auto put = [&](double v) {
    const std::uint16_t h = exporter::FloatToHalf(static_cast<float>(v));
    out.push_back(static_cast<char>(h & 0xffu));
    out.push_back(static_cast<char>(h >> 8));
  };
  for (const IblPack* pack : packs) {
    if (pack == nullptr || pack->mu.size() != kRows || pack->specular.size() != kRows ||
        pack->alpha.size() != kRows)
      throw InvalidArgument(fmt::format("IBL pack texture: a pack without {} rows", kRows));
    for (int i = 0; i < kRows; ++i) {
      for (int c = 0; c < 3; ++c) put(pack->specular[i][c]);
      put(pack->alpha[i]);
    }
  }
  return out;
}

}  // namespace brdf::engines
