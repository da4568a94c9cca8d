#include "brdf/exporter/rgb9e5.h"

#include <algorithm>
#include <cmath>

namespace brdf::exporter {
namespace {

constexpr int kN = kRgb9e5MantissaBits;
constexpr int kB = kRgb9e5ExponentBias;

// Clamp of EXT_texture_shared_exponent with NaN → 0 (the comparisons are written so that a
// NaN fails the first test).
float ClampChannel(float c) {
  if (!(c > 0.0f)) return 0.0f;
  return c < kRgb9e5MaxValue ? c : kRgb9e5MaxValue;
}

// 2^(e − B − N) for every biased exponent e, exact in float (2^−24 … 2^7).
struct ScaleTable {
  std::array<float, 32> scale{};
  ScaleTable() {
    for (int e = 0; e < 32; ++e) scale[e] = std::ldexp(1.0f, e - kB - kN);
  }
};
const ScaleTable kScales;

}  // namespace

std::uint32_t EncodeRgb9e5(float r, float g, float b) {
  const float rc = ClampChannel(r), gc = ClampChannel(g), bc = ClampChannel(b);
  const float max_c = std::max(rc, std::max(gc, bc));
  if (max_c == 0.0f) return 0;  // exp_shared_p = 0, all mantissas 0
  // floor(log2(max_c)) is the float's unbiased exponent; ilogb is exact (also for float
  // denormals), where log2 rounding could misplace a value just below a power of two.
  const int floor_log2 = std::ilogb(max_c);
  int exp_shared = std::max(-kB - 1, floor_log2) + 1 + kB;
  // Dividing by a power of two is exact in double and the scaled value has at most 24
  // significant bits below 2^10, so adding 0.5 is exact too: floor(x + 0.5) is the spec's
  // round-half-up without any double rounding.
  const auto scaled = [](float c, int e) {
    return static_cast<std::uint32_t>(std::floor(std::ldexp(double{c}, kB + kN - e) + 0.5));
  };
  if (scaled(max_c, exp_shared) == (1u << kN)) ++exp_shared;  // round-up correction
  return scaled(rc, exp_shared) | (scaled(gc, exp_shared) << 9) | (scaled(bc, exp_shared) << 18) |
         (static_cast<std::uint32_t>(exp_shared) << 27);
}

std::array<float, 3> DecodeRgb9e5(std::uint32_t packed) {
  const float scale = kScales.scale[Rgb9e5Exponent(packed)];
  return {static_cast<float>(Rgb9e5Red(packed)) * scale,
          static_cast<float>(Rgb9e5Green(packed)) * scale,
          static_cast<float>(Rgb9e5Blue(packed)) * scale};
}

bool IsCanonicalRgb9e5(std::uint32_t packed) {
  const std::uint32_t max_mantissa =
      std::max(Rgb9e5Red(packed), std::max(Rgb9e5Green(packed), Rgb9e5Blue(packed)));
  return Rgb9e5Exponent(packed) == 0 || max_mantissa >= (1u << (kN - 1));
}

}  // namespace brdf::exporter
