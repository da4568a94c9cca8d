// The compact form (brdf/exporter/compact_lut.h): what log-bilinear interpolation must
// reproduce exactly, the error target it is built to, and the container's refusals.
#include "brdf/exporter/compact_lut.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "brdf/core/error.h"

namespace brdf::exporter {
namespace {

// A 4-slice LUT with f = 2^(−3 − θd/40 + φd/400) · (1 + k/4) per texel and channel scale: log2 f
// is linear in θd and φd, so bilinear interpolation in log2 reproduces it from any grid.
Lut LogLinearLut() {
  Lut lut;
  lut.Resize(4);
  lut.theta_in_deg = {0, 20, 40, 60};
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i)
        for (int c = 0; c < 3; ++c)
          lut.Texel(k, j, i)[c] = static_cast<float>(std::exp2(-3.0 - j / 40.0 + i / 400.0) *
                                                     (1 + k / 4.0) * (1.0 - 0.2 * c));
  return lut;
}

TEST(CompactLut, LogLinearDataNeedsOnlyTheInitialGridAndDecodesToHalfPrecision) {
  const Lut lut = LogLinearLut();
  const CompactBuild b = BuildCompactLut(lut, 90.0, 0.01);
  // Not mirror-symmetric (φd enters linearly): columns over 0–360°, every 30°.
  EXPECT_FALSE(b.compact.mirrored);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(b.compact.rows[k].size(), 7u);   // 0, 30, …, 180
    EXPECT_EQ(b.compact.cols[k].size(), 13u);  // 0, 30, …, 360
  }
  // The stored g = log2(f/S + ε) rounded to half: relative error at most about 2^-11·|g|·ln 2
  // (|g| ≤ 8 here) plus ε's share, far below 1 %.
  EXPECT_TRUE(b.met_target);
  EXPECT_LT(b.error.measured.max, 0.004);
  // A value between texels reads the log-linear function too: θd 12.5°, φd 100.25°, slice 1.
  const double want = std::exp2(-3.0 - 12.5 / 40.0 + 100.25 / 400.0) * 1.25;
  EXPECT_NEAR(b.compact.SampleSlice(1, 12.5, 100.25)[0], want, 0.005 * want);
}

TEST(CompactLut, MirrorSymmetricDataKeepsHalfTheColumnsAndMeetsTheTarget) {
  Lut lut;
  lut.Resize(2);
  lut.theta_in_deg = {0, 20};
  // A narrow lobe at the pole, symmetric in φd: 1 + 50·exp(−(θd/3)²)·(1 + 0.3·cos φd).
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i)
        for (int c = 0; c < 3; ++c)
          lut.Texel(k, j, i)[c] = static_cast<float>(1 + 50 * std::exp(-(j / 3.0) * (j / 3.0)) *
                                                             (1 + 0.3 * std::cos(i * M_PI / 180)));
  const CompactBuild b = BuildCompactLut(lut, 75.0, 0.02);
  EXPECT_TRUE(b.compact.mirrored);
  for (int k = 0; k < 2; ++k) EXPECT_EQ(b.compact.cols[k].back(), 180);
  EXPECT_TRUE(b.met_target);
  EXPECT_LE(b.error.measured.max, 0.02);
  // The lobe needs rows near the pole: more than the initial seven.
  EXPECT_GT(b.compact.rows[0].size(), 7u);
  // φd and 360° − φd read the same.
  EXPECT_EQ(b.compact.SampleSlice(0, 2.5, 40.0), b.compact.SampleSlice(0, 2.5, 320.0));
}

TEST(CompactLut, ContainerRoundTripsAndRefusesDamage) {
  const CompactBuild b = BuildCompactLut(LogLinearLut(), 90.0, 0.02);
  const std::string bytes = SerializeCompactLut(b.compact, "{}");
  const std::vector<std::uint8_t> file(bytes.begin(), bytes.end());
  const LoadedCompact back = ParseCompactLut(file, "x.brdfc");
  EXPECT_EQ(back.sidecar_json, "{}");
  EXPECT_EQ(back.compact.rows, b.compact.rows);
  EXPECT_EQ(back.compact.cols, b.compact.cols);
  EXPECT_EQ(back.compact.values, b.compact.values);
  EXPECT_EQ(back.compact.theta_in_deg, b.compact.theta_in_deg);
  EXPECT_EQ(back.compact.PayloadBytes() + 2, file.size());
  // Cut inside the grid values: names the file and a byte.
  std::vector<std::uint8_t> cut(file.begin(), file.begin() + static_cast<long>(file.size() / 2));
  try {
    ParseCompactLut(cut, "x.brdfc");
    FAIL() << "a cut file was read";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), "x.brdfc");
    EXPECT_NE(e.position().find("byte"), std::string::npos);
  }
  // One flipped bit in a grid value: the checksum names it.
  std::vector<std::uint8_t> flipped = file;
  flipped[file.size() - 10] ^= 0x01;
  EXPECT_THROW(ParseCompactLut(flipped, "x.brdfc"), FormatError);
  // Another magic.
  std::vector<std::uint8_t> other = file;
  other[0] = 'X';
  EXPECT_THROW(ParseCompactLut(other, "x.brdfc"), FormatError);
  // Trailing bytes.
  std::vector<std::uint8_t> longer = file;
  longer.push_back(0);
  EXPECT_THROW(ParseCompactLut(longer, "x.brdfc"), FormatError);
}

// A file's θin list only has to be ascending k·Δ, so Δ may be tiny (10^-300 here): any θin then
// lies far beyond the last slice and reads it, as clamp-to-edge does, instead of converting a
// coordinate of 10^301 to an integer.
TEST(CompactLut, TinyThetaInStepReadsTheLastSlice) {
  CompactLut c;
  c.theta_in_deg = {0.0, 1e-300};
  c.scale = 1.0f;
  c.rows = {{0, 180}, {0, 180}};
  c.cols = {{0, 360}, {0, 360}};
  c.values = {std::vector<std::uint16_t>(12, 0xBC00),   // g = -1
              std::vector<std::uint16_t>(12, 0x0000)};  // g = 0
  const std::array<float, 3> f = c.SampleAngles(45.0, 30.0, 0.0);
  for (const float v : f) EXPECT_FLOAT_EQ(v, 1.0f - kCompactEpsilon);
}

}  // namespace
}  // namespace brdf::exporter
