#include "brdf/exporter/exr.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/rgb9e5.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

TextureMetadata Meta() {
  TextureMetadata m;
  m.name = "ggx03";
  m.source = "analytic GGX alpha 0.3";
  return m;
}

TEST(Composite, GridIsCeilSqrtColumnsByCeilRatioRows) {
  for (int k = 1; k <= 40; ++k) {
    const int c = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(k))));
    const int r = static_cast<int>(std::ceil(static_cast<double>(k) / c));
    const GridLayout g = SquareishGrid(k);
    EXPECT_EQ(g.columns, c) << k;
    EXPECT_EQ(g.rows, r) << k;
  }
  EXPECT_EQ(SquareishGrid(4).columns, 2);
  EXPECT_EQ(SquareishGrid(4).rows, 2);
  EXPECT_EQ(SquareishGrid(5).columns, 3);
  EXPECT_EQ(SquareishGrid(5).rows, 2);
}

TEST(Composite, FourSlicesMake722By362RowMajorTopLeftFirst) {
  const Lut lut = test::PatternLut({0, 20, 40, 60}, 21);
  const FloatImage image = CompositeImage(lut);
  ASSERT_EQ(image.width, 722);
  ASSERT_EQ(image.height, 362);
  // Slice k at column k mod 2, row k div 2.
  const int origin[4][2] = {{0, 0}, {361, 0}, {0, 181}, {361, 181}};
  for (int k = 0; k < 4; ++k)
    for (int j : {0, 90, 180})
      for (int i : {0, 1, 200, 360})
        for (int c = 0; c < 3; ++c) {
          const float want = lut.Texel(k, j, i)[c];
          const float got = image.Pixel(origin[k][0] + i, origin[k][1] + j)[c];
          if (std::isnan(want)) {
            EXPECT_TRUE(std::isnan(got));
          } else {
            EXPECT_EQ(got, want) << "k=" << k << " j=" << j << " i=" << i;
          }
        }
}

TEST(Composite, CellsPastTheLastSliceAreBlack) {
  const Lut lut = test::AnalyticLut(test::Lambert(0.8), {0, 30, 60});  // 2 × 2 grid, 3 used
  const FloatImage image = CompositeImage(lut);
  ASSERT_EQ(image.width, 722);
  ASSERT_EQ(image.height, 362);
  for (int y = 181; y < 362; ++y)
    for (int x = 361; x < 722; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(image.Pixel(x, y)[c], 0.0f);
  EXPECT_GT(image.Pixel(0, 181)[0], 0.0f);  // slice 2 is at the bottom left
}

TEST(Exr, Ktx2DecodesToTheExrValuesAfterRgb9e5Quantisation) {
  const std::string dir = test::TestDir("exr_vs_ktx2");
  const Lut lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  WriteKtx2(dir + "/ggx.ktx2", lut, Meta());
  WriteExrComposite(dir + "/ggx.exr", lut, Meta(), ExrPixelType::kFloat);
  const LoadedTexture ktx2 = ReadKtx2(dir + "/ggx.ktx2");
  const ExrFile exr = ReadExr(dir + "/ggx.exr");
  ASSERT_EQ(exr.image.width, 722);
  ASSERT_EQ(exr.image.height, 362);
  EXPECT_EQ(exr.pixel_type, ExrPixelType::kFloat);
  // Texel for texel, in the composite's own coordinates.
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 181; ++j)
      for (int i = 0; i < 361; ++i) {
        const float* e = exr.image.Pixel((k % 2) * 361 + i, (k / 2) * 181 + j);
        const auto quantised = DecodeRgb9e5(EncodeRgb9e5(e[0], e[1], e[2]));
        const float* t = ktx2.lut.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(t[c], quantised[c]) << i << " " << j << " " << k;
      }
}

TEST(Exr, HeaderCarriesTheSidecarMetadata) {
  const std::string dir = test::TestDir("exr_header");
  const Lut lut = test::AnalyticLut(test::Lafortune20(), {0, 20, 40, 60});
  WriteExrComposite(dir + "/m.exr", lut, Meta());
  const ExrFile exr = ReadExr(dir + "/m.exr");
  const std::string sidecar = exr.Attribute("brdf:sidecar");
  ASSERT_FALSE(sidecar.empty());
  const auto j = nlohmann::json::parse(sidecar);
  EXPECT_EQ(j["theta_in_deg"], nlohmann::json::array({0, 20, 40, 60}));
  EXPECT_EQ(j["source"], "analytic GGX alpha 0.3");
  EXPECT_EQ(exr.Attribute("brdf:theta_in_deg"), "0, 20, 40, 60");
  EXPECT_EQ(exr.Attribute("brdf:payload_crc32"), j["payload"]["checksum"]["value"]);
  EXPECT_NE(exr.Attribute("brdf:texel_convention").find("+ 0.5"), std::string::npos);
  EXPECT_NE(exr.Attribute("Software").find("brdf-toolchain"), std::string::npos);
}

TEST(Exr, LutFromCompositeInvertsTheLayout) {
  const std::string dir = test::TestDir("exr_invert");
  const Lut lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60, 80});  // 3 × 2 grid
  WriteExrComposite(dir + "/five.exr", lut, Meta());
  const ExrFile exr = ReadExr(dir + "/five.exr");
  EXPECT_EQ(exr.image.width, 3 * 361);
  EXPECT_EQ(exr.image.height, 2 * 181);
  const Lut back = LutFromComposite(exr.image, lut.theta_in_deg);
  EXPECT_EQ(back.texels, lut.texels);
}

TEST(Exr, HalfPrecisionStoresHalfsWithinTheirRounding) {
  const std::string dir = test::TestDir("exr_half");
  const Lut lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  WriteExrComposite(dir + "/half.exr", lut, Meta(), ExrPixelType::kHalf);
  const ExrFile exr = ReadExr(dir + "/half.exr");
  EXPECT_EQ(exr.pixel_type, ExrPixelType::kHalf);
  const Lut back = LutFromComposite(exr.image, lut.theta_in_deg);
  for (std::size_t n = 0; n < lut.texels.size(); ++n) {
    const float v = lut.texels[n];
    // binary16: 11 significant bits, so round-to-nearest is within 2^-11 relative for normal
    // values and within half the subnormal step 2^-24 / 2 below 2^-14.
    const float tolerance = std::max(std::abs(v) * std::ldexp(1.0f, -11), std::ldexp(1.0f, -25));
    ASSERT_NEAR(back.texels[n], v, tolerance) << n;
  }
}

TEST(Exr, UncompressedFilesHoldTheSameValues) {
  const std::string dir = test::TestDir("exr_raw");
  const Lut lut = test::AnalyticLut(test::Lafortune20(), {0, 20, 40, 60});
  WriteExrComposite(dir + "/zip.exr", lut, Meta());
  WriteExrComposite(dir + "/raw.exr", lut, Meta(), {ExrPixelType::kFloat, ExrCompression::kNone});
  EXPECT_EQ(ReadExr(dir + "/raw.exr").image.rgb, ReadExr(dir + "/zip.exr").image.rgb);
  // Uncompressed float RGB: at least 722·362·3·4 bytes of pixels.
  EXPECT_GE(std::filesystem::file_size(dir + "/raw.exr"), 722u * 362u * 12u);
  EXPECT_LT(std::filesystem::file_size(dir + "/zip.exr"), 722u * 362u * 12u);
}

TEST(Png, ToneMappedCompositeIs722By362EightBitRgb) {
  const std::string dir = test::TestDir("png");
  const Lut lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  WritePngComposite(dir + "/ggx.png", lut);
  auto in = OIIO::ImageInput::open(dir + "/ggx.png");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 722);
  EXPECT_EQ(in->spec().height, 362);
  EXPECT_EQ(in->spec().nchannels, 3);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
}

TEST(Png, ToneMapSendsThe99thPercentileToWhiteAndZeroToBlack) {
  // 100 grey pixels of luminance 1..100: L99 = 99 (index round(0.99·99) = 98 of the sorted
  // list), so grey 99 → 2·1/(1+1) = 1 → 255; grey 33 → x = 1/3 → 0.5 → sRGB 0.7354 → 188;
  // 0 → 0; anything above L99 clips to 255.
  FloatImage image;
  image.width = 101;
  image.height = 1;
  for (int p = 0; p <= 100; ++p)
    for (int c = 0; c < 3; ++c) image.rgb.push_back(static_cast<float>(p));
  const std::vector<unsigned char> out = ToneMapForPng(image);
  EXPECT_EQ(out[0], 0);
  EXPECT_EQ(out[3 * 99], 255);
  EXPECT_EQ(out[3 * 100], 255);
  const double srgb_half = 1.055 * std::pow(0.5, 1.0 / 2.4) - 0.055;
  EXPECT_EQ(out[3 * 33], static_cast<unsigned char>(std::lround(255 * srgb_half)));
  for (int p = 1; p <= 100; ++p) EXPECT_GE(out[3 * p], out[3 * (p - 1)]);  // monotone
}

TEST(Png, ToneMapFollowsTheDocumentedFormulaAcrossTheRange) {
  // Two grey pixels: g and 1. L99 is the larger (index round(0.99 · 1) = 1), so s = 1 and
  // pixel 0 becomes round(255 · sRGB(2g / (1 + g))), computed here in double.
  int exact = 0, total = 0;
  for (int n = 1; n <= 20000; ++n) {
    const double g = n / 20000.0;
    FloatImage image;
    image.width = 2;
    image.height = 1;
    image.rgb = {static_cast<float>(g), static_cast<float>(g), static_cast<float>(g), 1, 1, 1};
    const double mapped = 2 * g / (1 + g);
    const double srgb =
        mapped <= 0.0031308 ? 12.92 * mapped : 1.055 * std::pow(mapped, 1 / 2.4) - 0.055;
    const long want = std::lround(255 * srgb);
    const int got = ToneMapForPng(image)[0];
    ASSERT_LE(std::abs(got - want), 1) << g;  // float vs double at a rounding boundary
    exact += got == want;
    ++total;
  }
  EXPECT_GE(exact, total - total / 1000);
}

}  // namespace
}  // namespace brdf::exporter
