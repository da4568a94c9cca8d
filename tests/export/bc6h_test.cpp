#include "brdf/exporter/bc6h.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/texture_file.h"

namespace brdf::exporter {
namespace {

// Sets `count` bits of `value` at bit `pos` (LSB first, as BPTC numbers a block's bits).
void PutBits(Bc6hBlock& block, int& pos, std::uint32_t value, int count) {
  for (int i = 0; i < count; ++i, ++pos)
    if ((value >> i) & 1u) block[pos / 8] |= static_cast<std::uint8_t>(1u << (pos % 8));
}

float RelativeError(float decoded, float reference) {
  return std::abs(decoded - reference) / std::max(reference, 1e-30f);
}

TEST(Bc6hHalf, KnownValuesAndRounding) {
  // binary16: 1.0 = 0x3C00, the largest finite 65504 = 0x7BFF, the smallest denormal 2^−24.
  EXPECT_EQ(HalfToFloat(0x3C00), 1.0f);
  EXPECT_EQ(HalfToFloat(0x7BFF), 65504.0f);
  EXPECT_EQ(HalfToFloat(0x0001), std::ldexp(1.0f, -24));
  EXPECT_EQ(HalfToFloat(0x0400), std::ldexp(1.0f, -14));
  EXPECT_EQ(FloatToHalfUnsigned(1.0f), 0x3C00);
  // Halfway between 1 and 1 + 2^−10 rounds to the even mantissa, 3/2 of a step rounds up.
  EXPECT_EQ(FloatToHalfUnsigned(1.0f + std::ldexp(1.0f, -11)), 0x3C00);
  EXPECT_EQ(FloatToHalfUnsigned(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3C02);
  EXPECT_EQ(FloatToHalfUnsigned(std::ldexp(1.0f, -25)), 0x0000);  // tie to even: 0
  EXPECT_EQ(FloatToHalfUnsigned(std::ldexp(3.0f, -25)), 0x0002);  // 1.5 steps: even 2
  EXPECT_EQ(FloatToHalfUnsigned(-1.0f), 0x0000);
  EXPECT_EQ(FloatToHalfUnsigned(std::numeric_limits<float>::quiet_NaN()), 0x0000);
  EXPECT_EQ(FloatToHalfUnsigned(std::numeric_limits<float>::infinity()), 0x7BFF);
  EXPECT_EQ(FloatToHalfUnsigned(1e6f), 0x7BFF);
  for (std::uint32_t h = 0; h < 0x7C00; ++h)
    ASSERT_EQ(FloatToHalfUnsigned(HalfToFloat(static_cast<std::uint16_t>(h))), h) << h;
}

// Mode 3 (one subset, raw 10-bit endpoints) built by hand: e0 = 0, e1 = 1023 in every channel;
// texel 0 has index 7 (its 3-bit anchor field), the others 15. By the specification:
// unquantize(0) = 0, unquantize(1023) = 0xFFFF; weight 30 for index 7 gives
// (34·0 + 30·65535 + 32) >> 6 = 30720, ×31 >> 6 = 14880 = 0x3A20 (0.765625); weight 64 gives
// 65535, ×31 >> 6 = 31743 = 0x7BFF (65504).
TEST(Bc6hDecode, HandMadeRawOneSubsetBlock) {
  Bc6hBlock block{};
  int pos = 0;
  PutBits(block, pos, 3, 5);                                  // mode 00011
  for (int c = 0; c < 3; ++c) PutBits(block, pos, 0, 10);     // r0 g0 b0
  for (int c = 0; c < 3; ++c) PutBits(block, pos, 1023, 10);  // r1 g1 b1
  ASSERT_EQ(pos, 65);
  PutBits(block, pos, 7, 3);
  for (int t = 1; t < 16; ++t) PutBits(block, pos, 15, 4);
  ASSERT_EQ(pos, 128);
  EXPECT_EQ(Bc6hBlockMode(block.data()), 3);
  const Bc6hHalfTexels texels = DecodeBc6hBlock(block.data());
  for (int c = 0; c < 3; ++c) EXPECT_EQ(texels[0][c], 0x3A20);
  for (int t = 1; t < 16; ++t)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(texels[t][c], 0x7BFF);
  EXPECT_EQ(HalfToFloat(0x3A20), 0.765625f);
}

TEST(Bc6hDecode, ReservedModesDecodeToBlack) {
  for (const int mode : {19, 23, 27, 31}) {
    Bc6hBlock block;
    block.fill(0xFF);
    block[0] = static_cast<std::uint8_t>(0xE0 | mode);
    EXPECT_EQ(Bc6hBlockMode(block.data()), mode);
    for (const auto& texel : DecodeBc6hBlock(block.data()))
      for (const std::uint16_t c : texel) EXPECT_EQ(c, 0);
  }
}

// A constant colour is exactly representable (mode 15's 16-bit endpoint e0 = ceil(h·64/31)
// gives (e0·31) >> 6 = h), so the encoder must reproduce the nearest half value, within the
// one step its unrounded target allows.
TEST(Bc6hEncode, ConstantBlocksWithinOneHalfStep) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> log_value(-12.0f, 15.0f);
  for (int trial = 0; trial < 200; ++trial) {
    float rgb[48];
    const float colour[3] = {std::exp2(log_value(rng)), std::exp2(log_value(rng)),
                             std::exp2(log_value(rng))};
    for (int t = 0; t < 16; ++t) std::copy(colour, colour + 3, rgb + 3 * t);
    const Bc6hBlock block = EncodeBc6hBlock(rgb);
    const Bc6hHalfTexels texels = DecodeBc6hBlock(block.data());
    for (int t = 0; t < 16; ++t)
      for (int c = 0; c < 3; ++c)
        ASSERT_LE(std::abs(static_cast<int>(texels[t][c]) - FloatToHalfUnsigned(colour[c])), 1)
            << "trial " << trial << " texel " << t << " channel " << c;
  }
}

// Smooth blocks: values spanning up to 10 % across a block (±2.4 % per texel step along x and
// y), nearly in proportion in R, G and B (a hue drift of ±0.2 % on top). From the format: a
// 10 % span is log2(1.1)·1024 ≈ 141–282 half steps (top/bottom of an octave); sixteen levels
// leave at most span/30 ≈ 5–9.4 steps, endpoint quantization (≤ 12 bits: 7.75 steps apart)
// about 4 more: at most ~13 steps, 0.65 % at the top of an octave and 1.3 % at its bottom (a
// step is 1/2048 to 1/1024 of the value), and much less typically.
TEST(Bc6hEncode, SmoothBlocksWithinTheFormatsBound) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> level(-6.0f, 8.0f), slope(-0.008f, 0.008f),
      drift(-0.002f, 0.002f);
  std::vector<float> errors;
  for (int trial = 0; trial < 500; ++trial) {
    float rgb[48];
    const float sx = slope(rng), sy = slope(rng);
    for (int c = 0; c < 3; ++c) {
      const float base = std::exp2(level(rng)), dx = drift(rng);
      for (int t = 0; t < 16; ++t)
        rgb[3 * t + c] = base * (1.0f + (sx + dx) * static_cast<float>(t % 4 - 1.5) * 2.0f +
                                 sy * static_cast<float>(t / 4 - 1.5) * 2.0f);
    }
    const Bc6hHalfTexels texels = DecodeBc6hBlock(EncodeBc6hBlock(rgb).data());
    for (int t = 0; t < 16; ++t) {
      // The certified metric (brdf/exporter/metadata.h): the channel error relative to the
      // texel's largest channel, whose own relative error the bound above is for; the encoder
      // weighs the channels by this metric, so a minor channel's own relative error may exceed
      // the bound where it costs less than that of the largest.
      const float scale = std::max({rgb[3 * t], rgb[3 * t + 1], rgb[3 * t + 2]});
      float e = 0.0f;
      for (int c = 0; c < 3; ++c)
        e = std::max(e, std::abs(HalfToFloat(texels[t][c]) - rgb[3 * t + c]) / scale);
      errors.push_back(e);
    }
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LE(errors.back(), 0.013f);
  EXPECT_LE(errors[errors.size() / 2], 0.002f);
}

// An edge no single line holds: columns 0–1 a grey ramp, columns 2–3 (partition 0's second
// subset) a flat colour off that line. Two subsets hold each side up to their quantization
// (EPB 10 or 11 over a 20 % span: a few half steps); the encoder must find that form.
TEST(Bc6hEncode, EdgeBlockUsesTwoSubsets) {
  float rgb[48];
  for (int t = 0; t < 16; ++t) {
    const bool right = t % 4 >= 2;
    const float ramp = 1.0f + 0.06f * static_cast<float>(t / 4);
    rgb[3 * t] = right ? 1.2f : ramp;
    rgb[3 * t + 1] = right ? 0.85f : ramp;
    rgb[3 * t + 2] = right ? 1.0f : ramp;
  }
  const Bc6hBlock block = EncodeBc6hBlock(rgb);
  const int mode = Bc6hBlockMode(block.data());
  for (const int one_subset : {3, 7, 11, 15}) EXPECT_NE(mode, one_subset);
  const Bc6hHalfTexels texels = DecodeBc6hBlock(block.data());
  for (int t = 0; t < 16; ++t)
    for (int c = 0; c < 3; ++c)
      EXPECT_LE(RelativeError(HalfToFloat(texels[t][c]), rgb[3 * t + c]), 0.01f)
          << "texel " << t << " channel " << c;
}

std::vector<float> SmoothVolume(int width, int height, int depth) {
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * depth * 3);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  for (int z = 0; z < depth; ++z)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const double th = y * 0.0174533, ph = x * 0.0174533;
        const double lobe =
            20.0 * std::exp(-th * th / (0.02 * (1 + z))) + 0.2 + 0.02 * std::cos(ph);
        float* p = &rgb[((static_cast<std::size_t>(z) * height + y) * width + x) * 3];
        p[0] = static_cast<float>(lobe * 0.9) * (1.0f + noise(rng));
        p[1] = static_cast<float>(lobe * 0.7);
        p[2] = static_cast<float>(lobe * 0.4);
      }
  return rgb;
}

TEST(Bc6hVolume, SameBytesForAnyThreadCount) {
  const std::vector<float> rgb = SmoothVolume(361, 181, 2);
  const Bc6hVolume one = EncodeBc6hVolume(rgb.data(), 361, 181, 2, 1);
  const Bc6hVolume three = EncodeBc6hVolume(rgb.data(), 361, 181, 2, 3);
  EXPECT_EQ(one.ByteSize(), 91u * 46u * 16u * 2u);
  EXPECT_EQ(one.bytes, three.bytes);
}

// Padding: a 5 × 6 slice is 2 × 2 blocks; texel (4, 5) lives in block (1, 1) at (0, 1), and the
// decoder returns only the 30 texels of the image.
TEST(Bc6hVolume, PaddedBlocksAndLayout) {
  const int w = 5, h = 6, d = 2;
  std::vector<float> rgb(w * h * d * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i)
    rgb[i] = 1.0f + 0.01f * static_cast<float>(i / 3) + 0.2f * static_cast<float>(i % 3);
  const Bc6hVolume v = EncodeBc6hVolume(rgb.data(), w, h, d);
  EXPECT_EQ(v.BlocksWide(), 2);
  EXPECT_EQ(v.BlocksHigh(), 2);
  EXPECT_EQ(v.ByteSize(), 2u * 2u * 2u * 16u);
  EXPECT_EQ(v.BlockOffset(4, 5, 1), ((1u * 2 + 1) * 2 + 1) * 16u);
  const std::vector<float> decoded = DecodeBc6hVolume(v);
  ASSERT_EQ(decoded.size(), rgb.size());
  const Bc6hHalfTexels block = DecodeBc6hBlock(v.bytes.data() + v.BlockOffset(4, 5, 1));
  const std::size_t at = ((1u * h + 5) * w + 4) * 3;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(decoded[at + c], HalfToFloat(block[1 * 4 + 0][c]));
  for (std::size_t i = 0; i < rgb.size(); ++i) EXPECT_LE(RelativeError(decoded[i], rgb[i]), 0.01f);
}

TEST(Bc6hVolume, RejectsWrongSizes) {
  Bc6hVolume v;
  v.width = 8, v.height = 4, v.depth = 1;
  v.bytes.resize(16);  // needs two blocks
  EXPECT_THROW(DecodeBc6hVolume(v), InvalidArgument);
  const float rgb[3] = {1, 1, 1};
  EXPECT_THROW(EncodeBc6hVolume(rgb, 0, 1, 1), InvalidArgument);
}

// The containers: the KTX2 header fields and DFD the KTX 2.0 and Data Format specifications give
// for VK_FORMAT_BC6H_UFLOAT_BLOCK, the DDS DXGI format 95, and the blocks read back unchanged.
TEST(Bc6hContainers, Ktx2AndDdsHoldTheBlocks) {
  const std::vector<float> rgb = SmoothVolume(361, 181, 2);
  const Bc6hVolume v = EncodeBc6hVolume(rgb.data(), 361, 181, 2);
  const std::string ktx2 = EncodeKtx2(v, {});
  const auto u32 = [&](const std::string& b, std::size_t at) {
    std::uint32_t x = 0;
    for (int i = 0; i < 4; ++i) x |= std::uint32_t{static_cast<std::uint8_t>(b[at + i])} << (8 * i);
    return x;
  };
  EXPECT_EQ(u32(ktx2, 12), 131u);  // vkFormat
  EXPECT_EQ(u32(ktx2, 16), 1u);    // typeSize of a block-compressed format
  EXPECT_EQ(u32(ktx2, 20), 361u);  // pixelWidth: the image, not the padded blocks
  EXPECT_EQ(u32(ktx2, 24), 181u);
  EXPECT_EQ(u32(ktx2, 28), 2u);
  const std::uint32_t dfd = u32(ktx2, 48);
  EXPECT_EQ(u32(ktx2, 52), 44u);                // dfdByteLength: one sample
  EXPECT_EQ(u32(ktx2, dfd + 12) & 0xff, 131u);  // colorModel KHR_DF_MODEL_BC6H
  EXPECT_EQ(u32(ktx2, dfd + 16), 0x0303u);      // texelBlockDimension 4 × 4 × 1
  EXPECT_EQ(u32(ktx2, dfd + 20), 16u);          // bytesPlane0
  EXPECT_EQ(u32(ktx2, dfd + 28), 0x807F0000u);  // bits 0..127, channel 0, FLOAT
  EXPECT_EQ(u32(ktx2, dfd + 40), 0x3F800000u);  // sampleUpper 1.0f
  const std::uint32_t level = u32(ktx2, 80);
  EXPECT_EQ(level % 16, 0u);
  EXPECT_EQ(u32(ktx2, 88), v.ByteSize());
  const LoadedTexture k =
      ParseKtx2(reinterpret_cast<const std::uint8_t*>(ktx2.data()), ktx2.size(), "t.ktx2");
  EXPECT_EQ(k.format, TexelFormat::kBc6hUfloat);
  EXPECT_EQ(k.bc6h.bytes, v.bytes);
  ASSERT_TRUE(k.IsSingleLut());
  EXPECT_EQ(k.lut.texels, DecodeBc6hVolume(v));

  const std::string dds = EncodeDds(v);
  EXPECT_EQ(u32(dds, 128), 95u);             // DXGI_FORMAT_BC6H_UF16
  EXPECT_EQ(u32(dds, 20), 91u * 46u * 16u);  // linear size: one slice of blocks
  const LoadedTexture d =
      ParseDds(reinterpret_cast<const std::uint8_t*>(dds.data()), dds.size(), "t.dds");
  EXPECT_EQ(d.format, TexelFormat::kBc6hUfloat);
  EXPECT_EQ(d.bc6h.bytes, v.bytes);
  EXPECT_EQ(d.TexelValue(200, 100, 1)[0], k.lut.Texel(1, 100, 200)[0]);

  // A damaged DFD is named: the colour model word.
  std::string bad = ktx2;
  bad[dfd + 12] = 1;
  try {
    ParseKtx2(reinterpret_cast<const std::uint8_t*>(bad.data()), bad.size(), "bad.ktx2");
    FAIL() << "accepted a BC6H file with an RGBSDA colour model";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("colour model"), std::string::npos) << e.what();
  }
  // A truncated level is refused with the expected size.
  std::string short_file = ktx2.substr(0, ktx2.size() - 16);
  EXPECT_THROW(ParseKtx2(reinterpret_cast<const std::uint8_t*>(short_file.data()),
                         short_file.size(), "short.ktx2"),
               FormatError);
}

}  // namespace
}  // namespace brdf::exporter
