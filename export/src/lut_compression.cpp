#include "brdf/exporter/lut_compression.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr float kScaleFloor = 6.103515625e-05f;  // 2^−14
constexpr float kRelativeFloor = 1e-4f;          // of the LUT's brightest value

ErrorStatistics Statistics(std::vector<float>& errors) {
  ErrorStatistics s;
  s.texels = errors.size();
  if (errors.empty()) return s;
  // Nearest-rank percentiles: the value at rank ceil(p·n).
  const auto rank = [&](double p) {
    const std::size_t r =
        static_cast<std::size_t>(std::ceil(p * static_cast<double>(errors.size())));
    return std::clamp<std::size_t>(r, 1, errors.size()) - 1;
  };
  const std::size_t median = rank(0.5), p99 = rank(0.99);
  std::nth_element(errors.begin(), errors.begin() + median, errors.end());
  s.median = errors[median];
  std::nth_element(errors.begin() + median, errors.begin() + p99, errors.end());
  s.p99 = errors[p99];
  s.max = *std::max_element(errors.begin() + p99, errors.end());
  return s;
}

}  // namespace

LutCompression ParseLutCompression(std::string_view text) {
  if (text == "none") return LutCompression::kNone;
  if (text == "bc6h") return LutCompression::kBc6h;
  if (text == "compact") return LutCompression::kCompact;
  throw InvalidArgument("--compress: unknown compression '" + std::string(text) +
                        "' (known: none, bc6h, compact)");
}

double TexelThetaOutDeg(double theta_in_deg, int j, int i) {
  const double ti = theta_in_deg * kDegree, td = j * kDegree, pd = i * kDegree;
  const double c = std::cos(ti) * std::cos(td) - std::sin(ti) * std::sin(td) * std::cos(pd);
  return std::acos(std::clamp(c, -1.0, 1.0)) / kDegree;
}

CertifiedError MeasureCompressionError(const Lut& reference, const std::vector<float>& decoded,
                                       double theta_b_deg) {
  if (decoded.size() != reference.texels.size() ||
      reference.texels.size() !=
          static_cast<std::size_t>(reference.slices()) * Lut::kHeight * Lut::kWidth * 3)
    throw InvalidArgument(fmt::format("compression error: {} decoded values for a LUT of {}",
                                      decoded.size(), reference.texels.size()));
  CertifiedError e;
  e.theta_b_deg = theta_b_deg;
  // The reference as the unsigned formats can hold it, and the scale floor.
  const auto clamped = [](float v) { return std::clamp(v, 0.0f, kBc6hMaxValue); };
  float brightest = 0.0f;
  for (const float v : reference.texels) brightest = std::max(brightest, clamped(v));
  const float floor = std::max(kScaleFloor, kRelativeFloor * brightest);
  std::vector<float> measured, filled;
  measured.reserve(reference.texels.size() / 3);
  for (int k = 0; k < reference.slices(); ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const std::size_t at = reference.Index(k, j, i);
        const float r[3] = {clamped(reference.texels[at]), clamped(reference.texels[at + 1]),
                            clamped(reference.texels[at + 2])};
        const float* d = &decoded[at];
        const float scale = std::max({r[0], r[1], r[2], floor});
        const float err =
            std::max({std::abs(d[0] - r[0]), std::abs(d[1] - r[1]), std::abs(d[2] - r[2])}) / scale;
        // A hair of tolerance so that texels exactly at θb (θd = 0 rows of a slice at θb) count
        // as measured despite rounding in the angle.
        (TexelThetaOutDeg(reference.theta_in_deg[k], j, i) <= theta_b_deg + 1e-9 ? measured
                                                                                 : filled)
            .push_back(err);
      }
  e.measured = Statistics(measured);
  e.filled = Statistics(filled);
  return e;
}

CertifiedError MeasureRgb9e5Error(const Lut& reference, const std::vector<float>& decoded,
                                  double theta_b_deg, std::uint64_t bytes) {
  CertifiedError e = MeasureCompressionError(reference, decoded, theta_b_deg);
  e.format = "rgb9e5";
  e.bytes = e.rgb9e5_bytes = bytes;
  return e;
}

CompressedLut CompressLutBc6h(const Lut& lut, double theta_b_deg, int jobs) {
  ValidateLutForExport(lut);
  CompressedLut out;
  out.blocks = EncodeBc6hVolume(lut.texels.data(), Lut::kWidth, Lut::kHeight, lut.slices(), jobs);
  out.error = MeasureCompressionError(lut, DecodeBc6hVolume(out.blocks), theta_b_deg);
  out.error.format = "bc6h_ufloat";
  out.error.bytes = out.blocks.ByteSize();
  out.error.rgb9e5_bytes =
      static_cast<std::uint64_t>(lut.slices()) * Lut::kHeight * Lut::kWidth * 4;
  return out;
}

}  // namespace brdf::exporter
