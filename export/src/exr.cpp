#include "brdf/exporter/exr.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/text_format.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/sidecar.h"
#include "json_util.h"

namespace brdf::exporter {
namespace {

float SrgbEncode(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

double SrgbDecode(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

// round(255 · SrgbEncode(x)) for x in [0, 1] without a pow per channel: code b ≥ 1 starts
// where the encoded value reaches (b − 0.5)/255, so the code is the number of those
// thresholds at or below x (the function is monotone).
struct SrgbByteTable {
  std::array<float, 255> threshold{};  // threshold[b − 1] starts code b
  SrgbByteTable() {
    for (int b = 1; b <= 255; ++b) {
      float t = static_cast<float>(SrgbDecode((b - 0.5) / 255.0));
      // Settle the float threshold against the float encoder itself, so the table and the
      // direct formula agree exactly at the boundaries.
      while (t > 0.0f && std::lround(255.0f * SrgbEncode(std::nextafter(t, 0.0f))) >= b)
        t = std::nextafter(t, 0.0f);
      while (std::lround(255.0f * SrgbEncode(t)) < b) t = std::nextafter(t, 2.0f);
      threshold[b - 1] = t;
    }
    FillBuckets();
  }
  // The first code of each of kBuckets equal steps of [0, 1], so a lookup starts at most a
  // few thresholds below its answer (the steepest part, near 0, has under one code per step)
  // instead of bisecting all 255.
  static constexpr int kBuckets = 16384;
  std::array<unsigned char, kBuckets> first{};  // 16 KB
  void FillBuckets() {
    for (int b = 0; b < kBuckets; ++b)
      first[b] = static_cast<unsigned char>(
          std::upper_bound(threshold.begin(), threshold.end(),
                           static_cast<float>(b) / static_cast<float>(kBuckets)) -
          threshold.begin());
  }
  // x in [0, 1]: the number of thresholds at or below x, as upper_bound over all of them.
  unsigned char operator()(float x) const {
    // x · kBuckets is exact (a power of two), so b/kBuckets ≤ x and first[b] never exceeds the
    // answer.
    const int b = std::min(static_cast<int>(x * static_cast<float>(kBuckets)), kBuckets - 1);
    int code = first[b];
    while (code < 255 && threshold[code] <= x) ++code;
    return static_cast<unsigned char>(code);
  }
};

}  // namespace

FloatImage CompositeImage(const Lut& lut) {
  ValidateLutForExport(lut);
  return AtlasImage({AtlasMaterial{"lut", &lut, ""}});
}

Lut LutFromComposite(const FloatImage& image, std::vector<double> theta_in_deg) {
  const int k_count = static_cast<int>(theta_in_deg.size());
  if (k_count < 1) throw InvalidArgument("composite: need at least one θin value");
  const GridLayout grid = SquareishGrid(k_count);
  if (image.width != grid.columns * Lut::kWidth || image.height != grid.rows * Lut::kHeight)
    throw InvalidArgument(
        fmt::format("composite: {} slices need a {} × {} image ({} × {} slices), got {} × {}",
                    k_count, grid.columns * Lut::kWidth, grid.rows * Lut::kHeight, grid.columns,
                    grid.rows, image.width, image.height));
  Lut lut;
  lut.Resize(theta_in_deg.size());
  lut.theta_in_deg = std::move(theta_in_deg);
  for (int k = 0; k < k_count; ++k)
    for (int j = 0; j < Lut::kHeight; ++j) {
      const float* src =
          image.Pixel(grid.CellColumn(k) * Lut::kWidth, grid.CellRow(k) * Lut::kHeight + j);
      std::copy(src, src + Lut::kWidth * 3, lut.Texel(k, j, 0));
    }
  return lut;
}

void WriteExr(const std::string& path, const FloatImage& image, const ExrOptions& options,
              const StringAttributes& attributes) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw InvalidArgument(fmt::format("EXR: inconsistent image {} × {} with {} floats", image.width,
                                      image.height, image.rgb.size()));
  StringAttributes all = {{"Software", BrdfToolWriter()}};
  all.insert(all.end(), attributes.begin(), attributes.end());
  image_io::WriteExrImage(path, image, options.type, options.compression, all);
}

void WriteExrComposite(const std::string& path, const Lut& lut, const PackedVolume& packed,
                       const TextureMetadata& metadata, const ExrOptions& options) {
  WriteExrComposite(path, lut, SidecarJson(packed, lut.theta_in_deg, metadata), packed.Crc32(),
                    options);
}

void WriteExrComposite(const std::string& path, const Lut& lut, const std::string& sidecar_json,
                       std::uint32_t payload_crc32, const ExrOptions& options) {
  const GridLayout grid = SquareishGrid(lut.slices());
  WriteExr(path, CompositeImage(lut), options,
           {{"brdf:sidecar", sidecar_json},
            {"brdf:theta_in_deg", FormatThetaList(lut.theta_in_deg)},
            {"brdf:layout", fmt::format("{} x {} slices of 361 x 181, row-major, ascending "
                                        "theta_in, top-left first",
                                        grid.columns, grid.rows)},
            {"brdf:texel_convention", TexelCentreFormula()},
            {"brdf:payload_crc32", Hex32Text(payload_crc32)}});
}

void WriteExrComposite(const std::string& path, const Lut& lut, const TextureMetadata& metadata,
                       const ExrOptions& options) {
  WriteExrComposite(path, lut, PackLut(lut), metadata, options);
}

std::vector<unsigned char> ToneMapForPng(const FloatImage& image) {
  static const SrgbByteTable kSrgbBytes;
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  std::vector<float> luminance;
  luminance.reserve(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    const float* c = &image.rgb[3 * p];
    const float l = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
    if (l > 0.0f && std::isfinite(l)) luminance.push_back(l);
  }
  float scale = 1.0f;
  if (!luminance.empty()) {
    const std::size_t q = static_cast<std::size_t>(std::llround(0.99 * (luminance.size() - 1)));
    std::nth_element(luminance.begin(), luminance.begin() + q, luminance.end());
    scale = 1.0f / luminance[q];
  }
  std::vector<unsigned char> out(pixels * 3);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float v = image.rgb[i];
    const float x = v > 0.0f ? v * scale : 0.0f;  // NaN and negatives → black
    const float mapped = std::isinf(x) ? 1.0f : std::min(1.0f, 2.0f * x / (1.0f + x));
    out[i] = kSrgbBytes(mapped);
  }
  return out;
}

void WritePng(const std::string& path, const FloatImage& image) {
  const std::vector<unsigned char> pixels = ToneMapForPng(image);
  // zlib level 3 (half the encoding time of the default 6), the Sub filter on every row and
  // zlib's run-length strategy: measured on the batch, about a fifth less time than level 3
  // with libpng's adaptive filters for files about 7 % larger (docs/benchmarks/batch.md).
  image_io::WritePng8(path, image.width, image.height, pixels, 3, {{"Software", BrdfToolWriter()}},
                      /*fast=*/true);
}

void WritePngComposite(const std::string& path, const Lut& lut) {
  WritePng(path, CompositeImage(lut));
}

ExrFile ReadExr(const std::string& path) { return image_io::ReadExrImage(path); }

}  // namespace brdf::exporter
