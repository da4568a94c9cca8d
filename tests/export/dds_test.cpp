#include "brdf/exporter/dds.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "brdf/core/error.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/sidecar.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

using test::Le32;
using test::Le64;

// The documented Microsoft layout, written out independently of the writer:
// DWORD magic; DDS_HEADER { dwSize, dwFlags, dwHeight, dwWidth, dwPitchOrLinearSize, dwDepth,
// dwMipMapCount, dwReserved1[11], DDS_PIXELFORMAT { dwSize, dwFlags, dwFourCC, dwRGBBitCount,
// dwRBitMask, dwGBitMask, dwBBitMask, dwABitMask }, dwCaps, dwCaps2, dwCaps3, dwCaps4,
// dwReserved2 }; DDS_HEADER_DXT10 { dxgiFormat, resourceDimension, miscFlag, arraySize,
// miscFlags2 }.
constexpr std::size_t kMagicAt = 0, kSizeAt = 4, kFlagsAt = 8, kHeightAt = 12, kWidthAt = 16,
                      kPitchAt = 20, kDepthAt = 24, kMipCountAt = 28, kReserved1At = 32,
                      kPfSizeAt = 76, kPfFlagsAt = 80, kFourCcAt = 84, kPfBitCountAt = 88,
                      kCapsAt = 108, kCaps2At = 112, kDxgiAt = 128, kDimensionAt = 132,
                      kMiscFlagAt = 136, kArraySizeAt = 140, kMiscFlags2At = 144, kDataAt = 148;
constexpr std::uint32_t DDSD_CAPS = 0x1, DDSD_HEIGHT = 0x2, DDSD_WIDTH = 0x4, DDSD_PITCH = 0x8,
                        DDSD_PIXELFORMAT = 0x1000, DDSD_MIPMAPCOUNT = 0x20000,
                        DDSD_LINEARSIZE = 0x80000, DDSD_DEPTH = 0x800000, DDPF_FOURCC = 0x4,
                        DDSCAPS_TEXTURE = 0x1000, DDSCAPS2_VOLUME = 0x200000,
                        DXGI_FORMAT_R9G9B9E5_SHAREDEXP = 67, D3D10_RESOURCE_DIMENSION_TEXTURE3D = 4;

std::uint32_t FourCc(const char* s) {
  return static_cast<std::uint32_t>(s[0]) | (static_cast<std::uint32_t>(s[1]) << 8) |
         (static_cast<std::uint32_t>(s[2]) << 16) | (static_cast<std::uint32_t>(s[3]) << 24);
}

std::string ExpectFormatError(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  try {
    ParseDds(bytes.data(), bytes.size(), name);
  } catch (const FormatError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a FormatError: " << e.what();
    return {};
  }
  ADD_FAILURE() << "accepted";
  return {};
}

struct Files {
  Lut lut;
  std::string dir;
  std::vector<std::uint8_t> dds, ktx2;
};

Files WriteBoth(const std::string& name) {
  Files f;
  f.dir = test::TestDir(name);
  f.lut = test::AnalyticLut(test::Lafortune20(), {0, 20, 40, 60});
  const PackedVolume packed = PackLut(f.lut);
  TextureMetadata meta;
  meta.name = "lafortune20";
  meta.source = "analytic";
  WriteDds(f.dir + "/m.dds", packed);
  WriteKtx2(f.dir + "/m.ktx2", packed, f.lut.theta_in_deg, meta);
  WriteSidecar(f.dir + "/m.json", packed, f.lut.theta_in_deg, meta);
  f.dds = test::ReadAll(f.dir + "/m.dds");
  f.ktx2 = test::ReadAll(f.dir + "/m.ktx2");
  return f;
}

TEST(Dds, HeaderFieldsMatchTheDocumentedLayout) {
  const Files f = WriteBoth("dds_header");
  const auto& b = f.dds;
  ASSERT_GE(b.size(), kDataAt);
  EXPECT_EQ(Le32(b, kMagicAt), FourCc("DDS "));
  EXPECT_EQ(Le32(b, kSizeAt), 124u);
  const std::uint32_t flags = Le32(b, kFlagsAt);
  for (std::uint32_t bit :
       {DDSD_CAPS, DDSD_HEIGHT, DDSD_WIDTH, DDSD_PITCH, DDSD_PIXELFORMAT, DDSD_DEPTH})
    EXPECT_TRUE(flags & bit) << std::hex << "flag 0x" << bit << " missing in 0x" << flags;
  EXPECT_FALSE(flags & DDSD_LINEARSIZE);  // uncompressed: a pitch, not a linear size
  EXPECT_EQ(Le32(b, kHeightAt), 181u);
  EXPECT_EQ(Le32(b, kWidthAt), 361u);
  EXPECT_EQ(Le32(b, kPitchAt), 361u * 4u);  // (width · 32 bits + 7) / 8
  EXPECT_EQ(Le32(b, kDepthAt), 4u);
  EXPECT_LE(Le32(b, kMipCountAt), 1u);
  if (flags & DDSD_MIPMAPCOUNT) {
    EXPECT_EQ(Le32(b, kMipCountAt), 1u);
  }
  for (std::size_t at = kReserved1At; at < kPfSizeAt; at += 4) EXPECT_EQ(Le32(b, at), 0u);
  EXPECT_EQ(Le32(b, kPfSizeAt), 32u);
  EXPECT_EQ(Le32(b, kPfFlagsAt), DDPF_FOURCC);
  EXPECT_EQ(Le32(b, kFourCcAt), FourCc("DX10"));
  EXPECT_EQ(Le32(b, kPfBitCountAt), 0u);
  EXPECT_TRUE(Le32(b, kCapsAt) & DDSCAPS_TEXTURE);
  EXPECT_TRUE(Le32(b, kCaps2At) & DDSCAPS2_VOLUME);
  EXPECT_EQ(Le32(b, kDxgiAt), DXGI_FORMAT_R9G9B9E5_SHAREDEXP);
  EXPECT_EQ(Le32(b, kDimensionAt), D3D10_RESOURCE_DIMENSION_TEXTURE3D);
  EXPECT_EQ(Le32(b, kMiscFlagAt), 0u);    // not a cube map
  EXPECT_EQ(Le32(b, kArraySizeAt), 1u);   // 3D textures are never arrays
  EXPECT_LE(Le32(b, kMiscFlags2At), 4u);  // a DDS_ALPHA_MODE value
  EXPECT_EQ(b.size(), kDataAt + 361u * 181u * 4u * 4u);
}

TEST(Dds, CarriesTheIdenticalPayloadToTheKtx2) {
  const Files f = WriteBoth("dds_payload");
  const std::uint64_t level_offset = Le64(f.ktx2, 80), level_length = Le64(f.ktx2, 88);
  ASSERT_EQ(f.dds.size() - kDataAt, level_length);
  EXPECT_TRUE(std::equal(f.dds.begin() + kDataAt, f.dds.end(), f.ktx2.begin() + level_offset));
}

TEST(Dds, ReadsBackWithThetaFromTheSidecarBesideIt) {
  const Files f = WriteBoth("dds_read");
  const LoadedTexture alone = ReadDds(f.dir + "/m.dds");
  EXPECT_EQ(alone.container, TextureContainer::kDds);
  EXPECT_FALSE(alone.theta_in_from_metadata);
  EXPECT_EQ(alone.theta_in_deg, (std::vector<double>{0, 20, 40, 60}));  // k·20° default
  const LoadedTexture with = ReadTextureFile(f.dir + "/m.dds");
  EXPECT_TRUE(with.theta_in_from_metadata);
  EXPECT_EQ(with.volume.words, ReadKtx2(f.dir + "/m.ktx2").volume.words);
  ASSERT_TRUE(with.IsSingleLut());
  const LoadedTexture given = ReadDds(f.dir + "/m.dds", {0, 15, 30, 45});
  EXPECT_EQ(given.lut.theta_in_deg, (std::vector<double>{0, 15, 30, 45}));
}

TEST(Dds, AStaleSidecarIsReportedByItsChecksum) {
  const Files f = WriteBoth("dds_stale");
  std::vector<std::uint8_t> b = f.dds;
  b[kDataAt + 4 * 5000] ^= 0x01;
  test::WriteAll(f.dir + "/m.dds", b);
  try {
    ReadTextureFile(f.dir + "/m.dds");
    FAIL() << "damaged payload accepted";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("CRC-32"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("m.dds"), std::string::npos) << e.what();
  }
}

TEST(Dds, RejectsWrongMagic) {
  Files f = WriteBoth("dds_magic");
  f.dds[0] = 'X';
  const std::string msg = ExpectFormatError(f.dds, "bad.dds");
  EXPECT_NE(msg.find("byte 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("DDS magic"), std::string::npos) << msg;
}

TEST(Dds, RejectsOtherDxgiFormatsNamingThem) {
  Files f = WriteBoth("dds_dxgi");
  test::SetLe32(f.dds, kDxgiAt, 71);  // DXGI_FORMAT_BC1_UNORM
  const std::string msg = ExpectFormatError(f.dds, "bc1.dds");
  EXPECT_NE(msg.find("byte 128"), std::string::npos) << msg;
  EXPECT_NE(msg.find("DXGI format 71"), std::string::npos) << msg;
  EXPECT_NE(msg.find("67"), std::string::npos) << msg;
}

TEST(Dds, RejectsLegacyHeadersWithoutDx10) {
  Files f = WriteBoth("dds_fourcc");
  test::SetLe32(f.dds, kFourCcAt, FourCc("DXT1"));
  const std::string msg = ExpectFormatError(f.dds, "dxt1.dds");
  EXPECT_NE(msg.find("DX10"), std::string::npos) << msg;
  EXPECT_NE(msg.find("DXT1"), std::string::npos) << msg;
}

TEST(Dds, RejectsTwoDimensionalTextures) {
  Files f = WriteBoth("dds_2d");
  test::SetLe32(f.dds, kDimensionAt, 3);  // TEXTURE2D
  EXPECT_NE(ExpectFormatError(f.dds, "2d.dds").find("TEXTURE3D"), std::string::npos);
}

TEST(Dds, RejectsTruncatedFiles) {
  const Files f = WriteBoth("dds_truncated");
  for (std::size_t keep : {std::size_t{0}, std::size_t{3}, std::size_t{60}, std::size_t{130},
                           std::size_t{147}, std::size_t{148}, f.dds.size() - 4}) {
    const std::vector<std::uint8_t> cut(f.dds.begin(), f.dds.begin() + keep);
    const std::string msg = ExpectFormatError(cut, "cut.dds");
    EXPECT_NE(msg.find("cut.dds: byte"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace brdf::exporter
