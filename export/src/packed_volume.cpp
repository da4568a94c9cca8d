#include "brdf/exporter/packed_volume.h"

#include <bit>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/rgb9e5.h"

namespace brdf::exporter {

std::string PackedVolume::Bytes() const {
  std::string out(ByteSize(), '\0');
  if constexpr (std::endian::native == std::endian::little) {
    if (!words.empty()) std::memcpy(out.data(), words.data(), out.size());
  } else {
    for (std::size_t i = 0; i < words.size(); ++i)
      for (int b = 0; b < 4; ++b) out[4 * i + b] = static_cast<char>((words[i] >> (8 * b)) & 0xff);
  }
  return out;
}

std::uint32_t PackedVolume::Crc32() const {
  if constexpr (std::endian::native == std::endian::little) {
    return brdf::Crc32(words.data(), ByteSize());
  } else {
    const std::string bytes = Bytes();
    return brdf::Crc32(bytes.data(), bytes.size());
  }
}

std::string FormatThetaList(const std::vector<double>& theta_in_deg) {
  std::string out;
  for (std::size_t k = 0; k < theta_in_deg.size(); ++k) {
    if (k > 0) out += ", ";
    out += fmt::format("{:g}", theta_in_deg[k]);
  }
  return out;
}

void ValidateLutForExport(const Lut& lut) {
  const std::size_t k = lut.theta_in_deg.size();
  if (k == 0) throw InvalidArgument("LUT export: the LUT has no θin slices");
  const std::size_t expected = k * Lut::kHeight * Lut::kWidth * 3;
  if (lut.texels.size() != expected)
    throw InvalidArgument(
        fmt::format("LUT export: expected {} floats for {} slices of {} × {} RGB texels, got {}",
                    expected, k, Lut::kWidth, Lut::kHeight, lut.texels.size()));
  for (double t : lut.theta_in_deg)
    if (!std::isfinite(t) || t < 0.0 || t >= 90.0)
      throw InvalidArgument(fmt::format("LUT export: θin values must lie in [0°, 90°), got [{}]",
                                        FormatThetaList(lut.theta_in_deg)));
  if (k >= 2) {
    const double delta = lut.theta_in_deg[1] - lut.theta_in_deg[0];
    for (std::size_t i = 1; i < k; ++i) {
      const double step = lut.theta_in_deg[i] - lut.theta_in_deg[i - 1];
      if (!(step > 0.0) || std::abs(step - delta) > 1e-9 * std::max(1.0, delta))
        throw InvalidArgument(
            fmt::format("LUT export: θin must be strictly increasing and evenly spaced (the shader "
                        "addresses slice k as θin/Δin), got [{}]",
                        FormatThetaList(lut.theta_in_deg)));
    }
  }
}

PackedVolume PackLut(const Lut& lut) {
  ValidateLutForExport(lut);
  PackedVolume v;
  v.width = Lut::kWidth;
  v.height = Lut::kHeight;
  v.depth = lut.slices();
  v.words.resize(lut.texels.size() / 3);
  const float* src = lut.texels.data();
  for (std::size_t i = 0; i < v.words.size(); ++i) v.words[i] = EncodeRgb9e5(src + 3 * i);
  return v;
}

Lut UnpackLut(const PackedVolume& volume, std::vector<double> theta_in_deg) {
  if (volume.width != Lut::kWidth || volume.height != Lut::kHeight)
    throw InvalidArgument(fmt::format("LUT: expected a {} × {} texture, got {} × {}", Lut::kWidth,
                                      Lut::kHeight, volume.width, volume.height));
  if (static_cast<std::size_t>(volume.depth) != theta_in_deg.size())
    throw InvalidArgument(fmt::format("LUT: {} slices but {} θin values [{}]", volume.depth,
                                      theta_in_deg.size(), FormatThetaList(theta_in_deg)));
  if (volume.words.size() != static_cast<std::size_t>(volume.width) * volume.height * volume.depth)
    throw InvalidArgument(
        fmt::format("LUT: expected {} texels, got {}",
                    static_cast<std::size_t>(volume.width) * volume.height * volume.depth,
                    volume.words.size()));
  Lut lut;
  lut.Resize(theta_in_deg.size());
  lut.theta_in_deg = std::move(theta_in_deg);
  for (std::size_t i = 0; i < volume.words.size(); ++i) {
    const auto rgb = DecodeRgb9e5(volume.words[i]);
    lut.texels[3 * i] = rgb[0];
    lut.texels[3 * i + 1] = rgb[1];
    lut.texels[3 * i + 2] = rgb[2];
  }
  return lut;
}

}  // namespace brdf::exporter
