#include "brdf/exporter/rgb9e5.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "brdf/core/error.h"
#include "brdf/exporter/packed_volume.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

// EXT_texture_shared_exponent, "Additions to Chapter 3", read literally and written
// differently from the library: long double arithmetic, frexp for floor(log2(x)), pow for the
// powers of two, channels handled through arrays.
std::uint32_t ReferenceEncode(float r, float g, float b) {
  constexpr long double kSharedExpMax =
      (512.0L - 1.0L) / 512.0L * 65536.0L;  // (2^N−1)/2^N·2^(Emax−B)
  long double c[3];
  const float in[3] = {r, g, b};
  for (int i = 0; i < 3; ++i)
    c[i] = std::isnan(in[i])
               ? 0.0L
               : std::max(0.0L, std::min(kSharedExpMax, static_cast<long double>(in[i])));
  const long double max_c = std::max(c[0], std::max(c[1], c[2]));
  int floor_log2;
  if (max_c == 0.0L) {
    floor_log2 = std::numeric_limits<int>::min() / 2;  // log2(0) = −∞
  } else {
    int e;
    std::frexp(max_c, &e);  // max_c = m·2^e, m ∈ [0.5, 1)
    floor_log2 = e - 1;
  }
  const int exp_shared_p = std::max(-15 - 1, floor_log2) + 1 + 15;
  const long double max_s = std::floor(max_c / std::pow(2.0L, exp_shared_p - 15 - 9) + 0.5L);
  const int exp_shared = max_s == 512.0L ? exp_shared_p + 1 : exp_shared_p;
  std::uint32_t word = static_cast<std::uint32_t>(exp_shared) << 27;
  for (int i = 0; i < 3; ++i) {
    const long double s = std::floor(c[i] / std::pow(2.0L, exp_shared - 15 - 9) + 0.5L);
    word |= static_cast<std::uint32_t>(s) << (9 * i);
  }
  return word;
}

// c = c_s · 2^(exp_shared − B − N), in double.
double ReferenceDecode(std::uint32_t w, int channel) {
  const double mantissa = static_cast<double>((w >> (9 * channel)) & 511u);
  return mantissa * std::pow(2.0, static_cast<int>(w >> 27) - 24);
}

std::uint32_t Word(std::uint32_t r, std::uint32_t g, std::uint32_t b, std::uint32_t e) {
  return r | (g << 9) | (b << 18) | (e << 27);
}

TEST(Rgb9e5, EncodesZeroAsTheZeroWord) {
  EXPECT_EQ(EncodeRgb9e5(0.0f, 0.0f, 0.0f), 0u);
  EXPECT_EQ(EncodeRgb9e5(-0.0f, 0.0f, -0.0f), 0u);
}

TEST(Rgb9e5, RoundTripsLargestFiniteValue) {
  // 65408 = 511 · 2^(31 − 15 − 9): every mantissa full, exponent 31.
  EXPECT_EQ(EncodeRgb9e5(65408.0f, 65408.0f, 65408.0f), 0xFFFFFFFFu);
  EXPECT_EQ(EncodeRgb9e5(65408.0f, 0.0f, 0.0f), Word(511, 0, 0, 31));
  const auto rgb = DecodeRgb9e5(Word(511, 0, 0, 31));
  EXPECT_EQ(rgb[0], 65408.0f);
  EXPECT_EQ(kRgb9e5MaxValue, 65408.0f);
}

TEST(Rgb9e5, ClampsAboveTheMaximumAndInfinity) {
  const std::uint32_t max_word = Word(511, 0, 0, 31);
  EXPECT_EQ(EncodeRgb9e5(65409.0f, 0, 0), max_word);
  EXPECT_EQ(EncodeRgb9e5(1e30f, 0, 0), max_word);
  EXPECT_EQ(EncodeRgb9e5(std::numeric_limits<float>::infinity(), 0, 0), max_word);
  EXPECT_EQ(EncodeRgb9e5(std::numeric_limits<float>::max(), 0, 0), max_word);
}

TEST(Rgb9e5, NegativeInfinityNegativesAndNaNBecomeZero) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(EncodeRgb9e5(-1.0f, -65408.0f, -std::numeric_limits<float>::infinity()), 0u);
  EXPECT_EQ(EncodeRgb9e5(nan, nan, nan), 0u);
  EXPECT_EQ(EncodeRgb9e5(-std::numeric_limits<float>::signaling_NaN(), 0, 0), 0u);
  // A NaN channel is 0 beside a finite one: (NaN, 1, 0) encodes like (0, 1, 0).
  EXPECT_EQ(EncodeRgb9e5(nan, 1.0f, 0.0f), EncodeRgb9e5(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(EncodeRgb9e5(0.0f, 1.0f, 0.0f), Word(0, 256, 0, 16));
}

TEST(Rgb9e5, RoundUpCorrectionMovesToTheNextExponent) {
  // 0.9995: floor(log2) = −1, exp_shared_p = 15, max_s = floor(0.9995·512 + 0.5) = 512 = 2^N,
  // so the exponent becomes 16 and the mantissa floor(0.9995·256 + 0.5) = 256.
  EXPECT_EQ(EncodeRgb9e5(0.9995f, 0.0f, 0.0f), Word(256, 0, 0, 16));
  // 0.999: max_s = floor(0.999·512 + 0.5) = floor(511.988) = 511, no correction.
  EXPECT_EQ(EncodeRgb9e5(0.999f, 0.0f, 0.0f), Word(511, 0, 0, 15));
  // The halfway point above 511 at every exponent rounds up into the next exponent.
  for (int e = 0; e < 31; ++e) {
    const float v = static_cast<float>(std::ldexp(511.5, e - 24));
    EXPECT_EQ(EncodeRgb9e5(v, 0, 0), Word(256, 0, 0, static_cast<std::uint32_t>(e + 1)))
        << "e=" << e;
  }
  // Just below the halfway point it stays at 511.
  const float below = std::nextafter(static_cast<float>(std::ldexp(511.5, 0)), 0.0f);
  EXPECT_EQ(EncodeRgb9e5(below, 0, 0), Word(511, 0, 0, 24));
}

TEST(Rgb9e5, DenormalRangeInputs) {
  const float tiny = std::ldexp(1.0f, -24);  // smallest positive value: mantissa 1, exponent 0
  EXPECT_EQ(EncodeRgb9e5(tiny, 0, 0), Word(1, 0, 0, 0));
  EXPECT_EQ(DecodeRgb9e5(Word(1, 0, 0, 0))[0], tiny);
  EXPECT_EQ(kRgb9e5MinPositive, tiny);
  // Half of it rounds half up to 1; a quarter rounds to 0.
  EXPECT_EQ(EncodeRgb9e5(std::ldexp(1.0f, -25), 0, 0), Word(1, 0, 0, 0));
  EXPECT_EQ(EncodeRgb9e5(std::ldexp(1.0f, -26), 0, 0), 0u);
  // Float denormals are far below the format's range.
  EXPECT_EQ(EncodeRgb9e5(std::numeric_limits<float>::denorm_min(), 0, 0), 0u);
  EXPECT_EQ(EncodeRgb9e5(1e-40f, 1e-39f, 0), 0u);
  // Exponent 0 holds mantissas below 256 unnormalised: 3·2^−24 and 255·2^−24.
  EXPECT_EQ(EncodeRgb9e5(std::ldexp(3.0f, -24), 0, 0), Word(3, 0, 0, 0));
  EXPECT_EQ(EncodeRgb9e5(std::ldexp(255.0f, -24), 0, 0), Word(255, 0, 0, 0));
  EXPECT_EQ(EncodeRgb9e5(std::ldexp(255.5f, -24), 0, 0), Word(256, 0, 0, 0));
}

TEST(Rgb9e5, SharedExponentFollowsTheLargestChannel) {
  // 1.0 is 256·2^(16−24); 0.001·256 = 0.256 rounds to 0, 0.25 to exactly 64.
  EXPECT_EQ(EncodeRgb9e5(0.001f, 1.0f, 0.25f), Word(0, 256, 64, 16));
  EXPECT_EQ(EncodeRgb9e5(0.25f, 0.001f, 1.0f), Word(64, 0, 256, 16));
}

TEST(Rgb9e5, MatchesReferenceAtEveryExponentAndBoundaryMantissa) {
  const int mantissas[] = {0, 1, 2, 127, 128, 255, 256, 257, 383, 384, 509, 510, 511};
  for (int e = 0; e < 32; ++e)
    for (int m : mantissas)
      for (double frac : {0.0, 0.25, 0.5, 0.75}) {
        const float v = static_cast<float>(std::ldexp(m + frac, e - 24));
        for (float x : {v, std::nextafter(v, 0.0f), std::nextafter(v, INFINITY)}) {
          ASSERT_EQ(EncodeRgb9e5(x, 0, 0), ReferenceEncode(x, 0, 0)) << "x=" << x;
          ASSERT_EQ(EncodeRgb9e5(0, x, 0.5f * x), ReferenceEncode(0, x, 0.5f * x)) << "x=" << x;
          ASSERT_EQ(EncodeRgb9e5(x / 3, x / 7, x), ReferenceEncode(x / 3, x / 7, x)) << "x=" << x;
        }
      }
}

TEST(Rgb9e5, MatchesReferenceAroundEveryPowerOfTwo) {
  for (int p = -40; p <= 20; ++p) {
    const float v = std::ldexp(1.0f, p);
    for (float x : {v, std::nextafter(v, 0.0f), std::nextafter(v, INFINITY)})
      ASSERT_EQ(EncodeRgb9e5(x, x * 0.3f, x * 0.9f), ReferenceEncode(x, x * 0.3f, x * 0.9f)) << x;
  }
}

TEST(Rgb9e5, MatchesReferenceOnRandomFloats) {
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<std::uint32_t> bits;
  std::uniform_real_distribution<float> mant(0.5f, 1.0f);
  std::uniform_int_distribution<int> expo(-30, 18);
  for (int n = 0; n < 300'000; ++n) {
    float c[3];
    for (float& x : c)
      x = n % 2 ? std::ldexp(mant(rng), expo(rng)) : std::bit_cast<float>(bits(rng));
    ASSERT_EQ(EncodeRgb9e5(c[0], c[1], c[2]), ReferenceEncode(c[0], c[1], c[2]))
        << c[0] << " " << c[1] << " " << c[2];
  }
}

TEST(Rgb9e5, DecodesExactlyAsTheSpecificationSays) {
  for (std::uint32_t e = 0; e < 32; ++e)
    for (std::uint32_t m = 0; m < 512; ++m) {
      const std::uint32_t w = Word(m, 511 - m, (m * 7) % 512, e);
      const auto rgb = DecodeRgb9e5(w);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(static_cast<double>(rgb[c]), ReferenceDecode(w, c));
    }
}

TEST(Rgb9e5, CanonicalMeansExponentZeroOrLargestMantissaAtLeast256) {
  // Independent definition: a word is canonical when the reference encoder reproduces it.
  for (std::uint32_t e = 0; e < 32; ++e)
    for (std::uint32_t m = 0; m < 512; ++m)
      for (std::uint32_t other : {0u, 1u, 255u, 256u, 511u}) {
        const std::uint32_t w = Word(m, other / 2, other, e);
        const auto rgb = DecodeRgb9e5(w);
        ASSERT_EQ(IsCanonicalRgb9e5(w), ReferenceEncode(rgb[0], rgb[1], rgb[2]) == w)
            << std::hex << w;
      }
}

TEST(Rgb9e5, DecodeThenEncodeIsIdentityOnEveryCanonicalWord) {
  // Every exponent × every R mantissa × every G mantissa, with B at values that are below,
  // at and above the normalisation threshold: 25 million words, the full two-channel space.
  std::uint64_t canonical = 0;
  for (std::uint32_t e = 0; e < 32; ++e)
    for (std::uint32_t r = 0; r < 512; ++r)
      for (std::uint32_t g = 0; g < 512; ++g)
        for (std::uint32_t b : {0u, 137u, 511u}) {
          const std::uint32_t w = Word(r, g, b, e);
          const auto rgb = DecodeRgb9e5(w);
          const std::uint32_t again = EncodeRgb9e5(rgb[0], rgb[1], rgb[2]);
          if (IsCanonicalRgb9e5(w)) {
            ++canonical;
            if (again != w) FAIL() << std::hex << "word 0x" << w << " re-encoded as 0x" << again;
          } else if (DecodeRgb9e5(again) != rgb) {
            FAIL() << std::hex << "word 0x" << w << " re-encoded to a different colour 0x" << again;
          }
        }
  EXPECT_GT(canonical, 12'000'000u);
}

TEST(Rgb9e5, DecodeThenEncodeIsIdentityOnRandomCanonicalWords) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> bits;
  int tested = 0;
  for (int n = 0; n < 4'000'000; ++n) {
    const std::uint32_t w = bits(rng);
    const auto rgb = DecodeRgb9e5(w);
    const std::uint32_t again = EncodeRgb9e5(rgb[0], rgb[1], rgb[2]);
    if (IsCanonicalRgb9e5(w)) {
      ++tested;
      ASSERT_EQ(again, w) << std::hex << w;
    } else {
      ASSERT_EQ(DecodeRgb9e5(again), rgb) << std::hex << w;
    }
  }
  EXPECT_GT(tested, 3'000'000);
}

TEST(Rgb9e5, QuantisationErrorIsAtMostHalfAStep) {
  // Round to nearest: |decode(encode(x)) − x| ≤ ½·2^(e−24) for the chosen exponent e.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> mant(0.5f, 1.0f);
  std::uniform_int_distribution<int> expo(-20, 15);
  for (int n = 0; n < 200'000; ++n) {
    const float x = std::ldexp(mant(rng), expo(rng));
    const std::uint32_t w = EncodeRgb9e5(x, 0, 0);
    const double step = std::ldexp(1.0, static_cast<int>(Rgb9e5Exponent(w)) - 24);
    ASSERT_LE(std::abs(static_cast<double>(DecodeRgb9e5(w)[0]) - x), 0.5 * step) << x;
  }
}

// docs/design.md §5 gives the per-material payload as 361·181·4 texels × 4 bytes (RGB9E5) =
// 1,045,456 bytes; the test asserts the product of the stated sizes.
TEST(Rgb9e5, PackedLutOfFourSlicesIs361By181By4TexelsOfFourBytes) {
  const Lut lut = test::PatternLut({0, 20, 40, 60}, 1);
  const PackedVolume v = PackLut(lut);
  EXPECT_EQ(v.ByteSize(), 1'045'456u);  // 361 · 181 · 4 · 4
  EXPECT_EQ(v.Bytes().size(), 1'045'456u);
  EXPECT_EQ(v.width, 361);
  EXPECT_EQ(v.height, 181);
  EXPECT_EQ(v.depth, 4);
  // Texel order: x fastest, then rows, then slices.
  EXPECT_EQ(v.words[(2u * 181 + 17) * 361 + 100],
            ReferenceEncode(lut.Texel(2, 17, 100)[0], lut.Texel(2, 17, 100)[1],
                            lut.Texel(2, 17, 100)[2]));
}

TEST(Rgb9e5, UnpackLutDecodesEveryTexel) {
  const Lut lut = test::PatternLut({0, 20}, 2);
  const Lut back = UnpackLut(PackLut(lut), lut.theta_in_deg);
  ASSERT_EQ(back.texels.size(), lut.texels.size());
  for (std::size_t t = 0; t < lut.texels.size() / 3; ++t) {
    const std::uint32_t w =
        ReferenceEncode(lut.texels[3 * t], lut.texels[3 * t + 1], lut.texels[3 * t + 2]);
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(static_cast<double>(back.texels[3 * t + c]), ReferenceDecode(w, c));
  }
}

TEST(Rgb9e5, PackLutRefusesUnevenThetaIn) {
  Lut lut = test::PatternLut({0, 20, 50}, 3);
  try {
    PackLut(lut);
    FAIL() << "uneven θin accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("0, 20, 50"), std::string::npos) << e.what();
  }
  Lut empty;
  EXPECT_THROW(PackLut(empty), InvalidArgument);
}

}  // namespace
}  // namespace brdf::exporter
