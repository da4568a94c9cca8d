// brdf::image_io: the OpenEXR and libpng writers checked through a different reader
// (OpenImageIO, via ReadRgbImage), ReadRgbImage checked against a Radiance HDR file written here
// byte by byte from the format's definition, and the OpenImageIO module loaded only on first
// use. This test program does not link OpenImageIO itself.
#include "brdf/image_io/image_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "brdf/core/error.h"

namespace brdf::image_io {
namespace {

namespace fs = std::filesystem;

class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "brdf_image_io_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

bool ProcessMaps(const std::string& needle) {
  std::ifstream maps("/proc/self/maps");
  const std::string text((std::istreambuf_iterator<char>(maps)), std::istreambuf_iterator<char>());
  return text.find(needle) != std::string::npos;
}

// A 3 × 2 image with distinct, exactly representable values (some above the half range).
RgbImage TestImage() {
  RgbImage image;
  image.width = 3;
  image.height = 2;
  for (int p = 0; p < 6; ++p)
    for (int c = 0; c < 3; ++c)
      image.rgb.push_back(std::ldexp(1.0f + 0.125f * static_cast<float>(c), p * 4 - 8));
  return image;
}

// Radiance RGBE (Greg Ward, "Real Pixels", Graphics Gems II): a text header, a blank line, the
// resolution string "-Y H +X W" (rows top to bottom), then per pixel R, G, B mantissas and one
// shared exponent byte; flat (not run-length encoded) scanlines are legal below width 8. A pixel
// decodes to m · 2^(e − 136) (Walter's rgbe.c, which OpenImageIO uses) or (m + 0.5) ·
// 2^(e − 136) (Radiance's own colr.c): the test accepts both, half a step apart.
TEST_F(ImageIoTest, ReadRgbImageLoadsOpenImageIoOnFirstUseAndDecodesRadianceHdr) {
  // This test runs first in the program (and alone under ctest), so nothing has loaded the
  // module yet.
  EXPECT_FALSE(OpenImageIoLoaded());
  EXPECT_FALSE(ProcessMaps("libOpenImageIO"));
  const unsigned char pixels[2][3][4] = {
      {{128, 64, 32, 129}, {255, 0, 1, 128}, {200, 100, 50, 140}},
      {{1, 2, 3, 100}, {128, 128, 128, 136}, {0, 0, 0, 0}},
  };
  {
    std::ofstream out(Path("sky.hdr"), std::ios::binary);
    out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 3\n";
    out.write(reinterpret_cast<const char*>(pixels), sizeof pixels);
  }
  const RgbImage image = ReadRgbImage(Path("sky.hdr"));
  EXPECT_TRUE(OpenImageIoLoaded());
  EXPECT_TRUE(ProcessMaps("libOpenImageIO"));
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) {
        const int e = pixels[y][x][3];
        const double step = e == 0 ? 0.0 : std::ldexp(1.0, e - 136);
        const double low = pixels[y][x][c] * step;
        const float got = image.Pixel(x, y)[c];
        EXPECT_GE(got, low * (1 - 1e-6)) << x << "," << y << " channel " << c;
        EXPECT_LE(got, (low + 0.5 * step) * (1 + 1e-6)) << x << "," << y << " channel " << c;
      }
  EXPECT_EQ(image.Pixel(2, 1)[0], 0.0f);  // exponent 0 is black
}

TEST_F(ImageIoTest, FloatExrFromOpenExrReadsBackExactlyThroughOpenImageIo) {
  const RgbImage image = TestImage();
  WriteExrImage(Path("f.exr"), image, ExrPixelType::kFloat, ExrCompression::kZip,
                {{"Software", "image_io_test"}, {"brdf:note", "θin list: 0, 20"}});
  EXPECT_EQ(ReadRgbImage(Path("f.exr")).rgb, image.rgb);
  const ExrImage exr = ReadExrImage(Path("f.exr"));
  EXPECT_EQ(exr.image.rgb, image.rgb);
  EXPECT_EQ(exr.pixel_type, ExrPixelType::kFloat);
  EXPECT_EQ(exr.compression, ExrCompression::kZip);
  EXPECT_EQ(exr.Attribute("brdf:note"), "θin list: 0, 20");
  EXPECT_EQ(exr.Attribute("Software"), "image_io_test");
}

TEST_F(ImageIoTest, HalfExrRoundsToNearestAndOverflowsToInfinity) {
  RgbImage image;
  image.width = 2;
  image.height = 1;
  // 1 + 2^-11 lies exactly between the halfs 1 and 1 + 2^-10: ties go to even, i.e. 1.
  // 1 + 3·2^-11 lies between 1 + 2^-10 and 1 + 2^-9: ties to even give 1 + 2^-9.
  // 65504 is the largest half; 65536 and above (beyond 65520) overflow to +inf.
  image.rgb = {
      1.0f + std::ldexp(1.0f, -11), 1.0f + 3 * std::ldexp(1.0f, -11), 65504.0f, 70000.0f, 0.1f,
      std::ldexp(1.0f, -24)};
  WriteExrImage(Path("h.exr"), image, ExrPixelType::kHalf, ExrCompression::kNone, {});
  const RgbImage back = ReadRgbImage(Path("h.exr"));
  ASSERT_EQ(back.rgb.size(), 6u);
  EXPECT_EQ(back.rgb[0], 1.0f);
  EXPECT_EQ(back.rgb[1], 1.0f + std::ldexp(1.0f, -9));
  EXPECT_EQ(back.rgb[2], 65504.0f);
  EXPECT_TRUE(std::isinf(back.rgb[3]));
  EXPECT_EQ(back.rgb[4], 1638.0f / 16384.0f);     // 0.1 → 0x2E66 = 1.599609375 · 2^-4
  EXPECT_EQ(back.rgb[5], std::ldexp(1.0f, -24));  // the smallest subnormal half
  EXPECT_EQ(ReadExrImage(Path("h.exr")).pixel_type, ExrPixelType::kHalf);
  EXPECT_EQ(ReadExrImage(Path("h.exr")).compression, ExrCompression::kNone);
}

TEST_F(ImageIoTest, EqualImagesGiveByteIdenticalExrFiles) {
  WriteExrImage(Path("a.exr"), TestImage(), ExrPixelType::kFloat, ExrCompression::kZip, {});
  WriteExrImage(Path("b.exr"), TestImage(), ExrPixelType::kFloat, ExrCompression::kZip, {});
  std::ifstream a(Path("a.exr"), std::ios::binary), b(Path("b.exr"), std::ios::binary);
  const std::string bytes_a((std::istreambuf_iterator<char>(a)), {});
  const std::string bytes_b((std::istreambuf_iterator<char>(b)), {});
  EXPECT_EQ(bytes_a, bytes_b);
  EXPECT_EQ(bytes_a.substr(0, 4), std::string("\x76\x2f\x31\x01", 4));  // EXR magic
}

TEST_F(ImageIoTest, PngReadsBackAsCodesOver255ThroughOpenImageIo) {
  std::vector<unsigned char> rgb8;
  for (int p = 0; p < 4 * 3; ++p)
    for (int c = 0; c < 3; ++c) rgb8.push_back(static_cast<unsigned char>(p * 21 + c * 7));
  WritePng8(Path("p.png"), 4, 3, rgb8, 3, {{"Software", "image_io_test"}});
  const RgbImage back = ReadRgbImage(Path("p.png"));
  ASSERT_EQ(back.width, 4);
  ASSERT_EQ(back.height, 3);
  ASSERT_EQ(back.rgb.size(), rgb8.size());
  for (std::size_t i = 0; i < rgb8.size(); ++i) EXPECT_FLOAT_EQ(back.rgb[i], rgb8[i] / 255.0f) << i;
  // The PNG signature and a tEXt chunk with the keyword (PNG 1.2, §11.3.4.3).
  std::ifstream in(Path("p.png"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_NE(bytes.find(std::string("tEXtSoftware\0image_io_test", 26)), std::string::npos);
}

TEST_F(ImageIoTest, ReadersNameTheFileForContentThatIsNotAnImage) {
  std::ofstream(Path("notes.exr")) << "this is not an image\n";
  try {
    ReadExrImage(Path("notes.exr"));
    FAIL() << "ReadExrImage accepted a text file";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), Path("notes.exr"));
  }
  try {
    ReadRgbImage(Path("notes.exr"));
    FAIL() << "ReadRgbImage accepted a text file";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), Path("notes.exr"));
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

TEST_F(ImageIoTest, MissingFilesFoldersAndFifosAreRefusedWithoutBlocking) {
  ASSERT_EQ(::mkfifo(Path("pipe.exr").c_str(), 0600), 0);
  fs::create_directory(Path("folder.exr"));
  for (const std::string name : {"absent.exr", "pipe.exr", "folder.exr"}) {
    EXPECT_THROW(ReadExrImage(Path(name)), IoError) << name;
    EXPECT_THROW(ReadRgbImage(Path(name)), IoError) << name;
  }
}

TEST_F(ImageIoTest, InconsistentImagesAreRefusedBeforeAnythingIsWritten) {
  RgbImage image = TestImage();
  image.rgb.pop_back();
  EXPECT_THROW(WriteExrImage(Path("x.exr"), image, ExrPixelType::kFloat, ExrCompression::kNone, {}),
               InvalidArgument);
  EXPECT_THROW(WritePng8(Path("x.png"), 2, 2, std::vector<unsigned char>(11), 3, {}),
               InvalidArgument);
  EXPECT_FALSE(fs::exists(Path("x.exr")));
  EXPECT_FALSE(fs::exists(Path("x.png")));
}

}  // namespace
}  // namespace brdf::image_io
