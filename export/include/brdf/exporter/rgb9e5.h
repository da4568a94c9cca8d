// RGB9E5: three 9-bit mantissas sharing one 5-bit exponent in 32 bits (docs/design.md §7).
//
// This is the texel format of every exported LUT (KTX2 vkFormat 123
// VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, DXGI_FORMAT_R9G9B9E5_SHAREDEXP = 67), encoded exactly as
// the OpenGL extension EXT_texture_shared_exponent specifies with N = 9 mantissa bits,
// B = 15 exponent bias and Emax = 31:
//
//   sharedexp_max = (2^N − 1)/2^N · 2^(Emax − B) = 65408
//   c_c          = max(0, min(sharedexp_max, c))          (NaN → 0, −∞ → 0, +∞ → 65408)
//   max_c        = max(r_c, g_c, b_c)
//   exp_shared_p = max(−B − 1, floor(log2(max_c))) + 1 + B
//   max_s        = floor(max_c / 2^(exp_shared_p − B − N) + 0.5)
//   exp_shared   = exp_shared_p + 1 if max_s == 2^N, else exp_shared_p   (round-up correction)
//   c_s          = floor(c_c / 2^(exp_shared − B − N) + 0.5)             (round half up)
//
// Bit layout of the 32-bit word (little-endian in files): R mantissa bits 0–8, G 9–17,
// B 18–26, shared exponent 27–31. Decoding is c = c_s · 2^(exp_shared − B − N); every decoded
// value is exactly representable as a float.
//
// Canonical words. Several words can decode to the same colour (a word whose largest mantissa
// is below 256 with a non-zero exponent denormalises a value the encoder would store with a
// smaller exponent). The encoder only produces canonical words: exponent 0, or largest
// mantissa ≥ 256. For every canonical word w, EncodeRgb9e5(DecodeRgb9e5(w)) == w, and for every
// word w, EncodeRgb9e5(DecodeRgb9e5(w)) decodes to exactly the same colour as w.
#pragma once

#include <array>
#include <cstdint>

namespace brdf::exporter {

inline constexpr int kRgb9e5MantissaBits = 9;   // N
inline constexpr int kRgb9e5ExponentBias = 15;  // B
inline constexpr int kRgb9e5MaxExponent = 31;   // Emax
// The largest encodable channel value: 511/512 · 2^16.
inline constexpr float kRgb9e5MaxValue = 65408.0f;
// The smallest non-zero encodable value: 1 · 2^(0 − B − N) = 2^−24.
inline constexpr float kRgb9e5MinPositive = 1.0f / 16777216.0f;

// Encodes one linear RGB value. Never fails: out-of-range, infinite and NaN inputs are
// clamped as described above.
std::uint32_t EncodeRgb9e5(float r, float g, float b);
inline std::uint32_t EncodeRgb9e5(const float* rgb) { return EncodeRgb9e5(rgb[0], rgb[1], rgb[2]); }

// Decodes one word to linear RGB; exact (no rounding).
std::array<float, 3> DecodeRgb9e5(std::uint32_t packed);

// True when the word is what the encoder produces for its own decoded value (see above).
bool IsCanonicalRgb9e5(std::uint32_t packed);

// Field accessors, for tests and diagnostics.
constexpr std::uint32_t Rgb9e5Red(std::uint32_t w) { return w & 0x1ffu; }
constexpr std::uint32_t Rgb9e5Green(std::uint32_t w) { return (w >> 9) & 0x1ffu; }
constexpr std::uint32_t Rgb9e5Blue(std::uint32_t w) { return (w >> 18) & 0x1ffu; }
constexpr std::uint32_t Rgb9e5Exponent(std::uint32_t w) { return w >> 27; }

}  // namespace brdf::exporter
