#include "brdf/exporter/half.h"

#include <bit>
#include <cmath>
#include <limits>

namespace brdf::exporter {

std::uint16_t FloatToHalf(float value) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(value);
  const std::uint16_t sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000u);
  const std::uint32_t abs_bits = bits & 0x7fffffffu;
  if (abs_bits >= 0x7f800000u)  // inf or NaN (keep a quiet NaN)
    return sign | (abs_bits > 0x7f800000u ? 0x7e00u : 0x7c00u);
  if (abs_bits >= 0x477ff000u) return sign | 0x7c00u;  // rounds to ≥ 65520: overflow to inf
  const int exponent = static_cast<int>(abs_bits >> 23) - 127;
  if (exponent < -25) return sign;  // below half the smallest subnormal: ±0
  std::uint32_t mantissa = (abs_bits & 0x7fffffu) | 0x800000u;  // 24 significant bits
  // Shift so the result has 10 fraction bits at the half exponent (or subnormal scale 2^-24).
  const int shift = exponent < -14 ? (-14 - exponent) + 13 : 13;
  const std::uint32_t kept = mantissa >> shift;
  const std::uint32_t rest = mantissa & ((1u << shift) - 1u);
  const std::uint32_t halfway = 1u << (shift - 1);
  std::uint32_t rounded = kept + ((rest > halfway || (rest == halfway && (kept & 1u))) ? 1u : 0u);
  if (exponent < -14) return sign | static_cast<std::uint16_t>(rounded);  // subnormal (may carry)
  // Normal: kept holds the implicit bit at 2^10; a carry to 2^11 bumps the exponent.
  const std::uint32_t half = (static_cast<std::uint32_t>(exponent + 15) << 10) + (rounded - 0x400u);
  return sign | static_cast<std::uint16_t>(half);
}

float HalfToFloat(std::uint16_t half) {
  const int e = (half >> 10) & 31, m = half & 1023;
  const float sign = (half & 0x8000) ? -1.0f : 1.0f;
  if (e == 0) return sign * std::ldexp(static_cast<float>(m), -24);
  if (e == 31)
    return m == 0 ? sign * std::numeric_limits<float>::infinity()
                  : std::numeric_limits<float>::quiet_NaN();
  return sign * std::ldexp(static_cast<float>(1024 + m), e - 25);
}

}  // namespace brdf::exporter
