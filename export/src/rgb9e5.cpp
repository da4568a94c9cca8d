#include "brdf/exporter/rgb9e5.h"

#include <algorithm>
#include <bit>
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
  // Integer arithmetic on the float's fields keeps every step exact. A clamped channel is
  // +0 or a positive float c = sig · 2^(e − 150) with a 24-bit significand sig and biased
  // exponent e ≥ 1; floor(log2(c)) = e − 127. A float denormal (e = 0, c < 2^−126) is far
  // below the format's smallest step 2^−24 and encodes as 0 at any exponent.
  const int max_e = static_cast<int>(std::bit_cast<std::uint32_t>(max_c) >> 23);
  if (max_e == 0) return 0;
  int exp_shared = std::max(max_e - 127, -kB - 1) + 1 + kB;
  // floor(c / 2^(exp_shared − B − N) + 0.5) = (sig + 2^(s−1)) >> s with
  // s = 126 + exp_shared − e (≥ 15 here); for s > 24 the quotient is below ½ and rounds to 0.
  const auto mantissa = [](float c, int exp) -> std::uint32_t {
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(c);
    const int e = static_cast<int>(bits >> 23);
    const int s = 126 + exp - e;
    if (e == 0 || s > 24) return 0;
    const std::uint32_t sig = (bits & 0x7fffffu) | 0x800000u;
    return (sig + (1u << (s - 1))) >> s;
  };
  if (mantissa(max_c, exp_shared) == (1u << kN)) ++exp_shared;  // round-up correction
  return mantissa(rc, exp_shared) | (mantissa(gc, exp_shared) << 9) |
         (mantissa(bc, exp_shared) << 18) | (static_cast<std::uint32_t>(exp_shared) << 27);
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
