#include "brdf/exporter/ktx2.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/exporter/rgb9e5.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

using test::Le32;
using test::Le64;

// Offsets of the KTX 2.0 specification, section 3 ("File Structure"), written out here.
constexpr std::size_t kVkFormatAt = 12, kTypeSizeAt = 16, kWidthAt = 20, kHeightAt = 24,
                      kDepthAt = 28, kLayerCountAt = 32, kFaceCountAt = 36, kLevelCountAt = 40,
                      kSupercompressionAt = 44, kDfdOffsetAt = 48, kDfdLengthAt = 52,
                      kKvdOffsetAt = 56, kKvdLengthAt = 60, kSgdOffsetAt = 64, kSgdLengthAt = 72,
                      kLevel0At = 80;

TextureMetadata Meta(const std::string& name) {
  TextureMetadata m;
  m.name = name;
  m.source = "tests/export (analytic " + name + ")";
  m.extrapolation = ExtrapolationInfo{0.2, 0.3, 75.0};
  return m;
}

struct Written {
  Lut lut;
  std::string path;
  std::vector<std::uint8_t> bytes;
};

Written WriteGgx(const std::string& dir) {
  Written w;
  w.lut = test::AnalyticLut(test::Ggx03(), {0, 20, 40, 60});
  w.path = dir + "/ggx.ktx2";
  WriteKtx2(w.path, w.lut, Meta("ggx03"));
  w.bytes = test::ReadAll(w.path);
  return w;
}

std::string ExpectFormatError(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  try {
    ParseKtx2(bytes.data(), bytes.size(), name);
  } catch (const FormatError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a FormatError: " << e.what();
    return {};
  }
  ADD_FAILURE() << "accepted";
  return {};
}

TEST(Ktx2, HeaderFieldsFollowTheSpecification) {
  const Written w = WriteGgx(test::TestDir("ktx2_header"));
  const auto& b = w.bytes;
  const std::uint8_t id[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32,
                               0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
  ASSERT_GE(b.size(), 104u);
  EXPECT_TRUE(std::equal(id, id + 12, b.begin()));
  EXPECT_EQ(Le32(b, kVkFormatAt), 123u);  // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
  EXPECT_EQ(Le32(b, kTypeSizeAt), 4u);    // _PACK32
  EXPECT_EQ(Le32(b, kWidthAt), 361u);
  EXPECT_EQ(Le32(b, kHeightAt), 181u);
  EXPECT_EQ(Le32(b, kDepthAt), 4u);
  EXPECT_EQ(Le32(b, kLayerCountAt), 0u);
  EXPECT_EQ(Le32(b, kFaceCountAt), 1u);
  EXPECT_EQ(Le32(b, kLevelCountAt), 1u);
  EXPECT_EQ(Le32(b, kSupercompressionAt), 0u);
  EXPECT_EQ(Le32(b, kDfdOffsetAt), 104u);  // right after the one-entry level index
  EXPECT_EQ(Le32(b, kDfdLengthAt), 124u);
  EXPECT_EQ(Le32(b, kKvdOffsetAt), 104u + 124u);
  EXPECT_EQ(Le64(b, kSgdOffsetAt), 0u);
  EXPECT_EQ(Le64(b, kSgdLengthAt), 0u);
  const std::uint64_t level_offset = Le64(b, kLevel0At), level_length = Le64(b, kLevel0At + 8);
  EXPECT_EQ(level_length, 361u * 181u * 4u * 4u);
  EXPECT_EQ(Le64(b, kLevel0At + 16), level_length);  // uncompressedByteLength
  EXPECT_EQ(level_offset % 4, 0u);
  // The level follows the key/value data after at most 3 bytes of mipPadding.
  const std::uint64_t kvd_end = Le32(b, kKvdOffsetAt) + Le32(b, kKvdLengthAt);
  EXPECT_GE(level_offset, kvd_end);
  EXPECT_LT(level_offset - kvd_end, 4u);
  EXPECT_EQ(b.size(), level_offset + level_length);
}

TEST(Ktx2, DataFormatDescriptorIsTheKhronosE5B9G9R9Descriptor) {
  // Khronos Data Format Specification 1.3 basic descriptor block for
  // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 as libktx (KTX-Software lib/texture2.c,
  // e5b9g9r9_ufloat_comparator) requires it: RGBSDA, BT.709, linear, 4 bytes per texel;
  // per channel a 9-bit mantissa sample (upper 8448) and a 5-bit exponent sample (lower 15,
  // upper 31, qualifier EXPONENT 0x20). Bit lengths are stored minus one.
  const std::uint32_t expected[31] = {
      124,                                       // dfdTotalSize
      0,                                         // vendorId 0 | descriptorType 0
      2u | (120u << 16),                         // versionNumber 2 | descriptorBlockSize 120
      1u | (1u << 8) | (1u << 16) | (0u << 24),  // model, primaries, transfer, flags
      0,                                         // texelBlockDimension 0,0,0,0
      4,                                         // bytesPlane0 = 4
      0,                                         // bytesPlane4..7
      0u | (8u << 16) | (0x00u << 24),
      0,
      0,
      8448,  // R mantissa: bits 0..8
      27u | (4u << 16) | (0x20u << 24),
      0,
      15,
      31,  // R exponent: bits 27..31
      9u | (8u << 16) | (0x01u << 24),
      0,
      0,
      8448,  // G mantissa: bits 9..17
      27u | (4u << 16) | (0x21u << 24),
      0,
      15,
      31,  // G exponent
      18u | (8u << 16) | (0x02u << 24),
      0,
      0,
      8448,  // B mantissa: bits 18..26
      27u | (4u << 16) | (0x22u << 24),
      0,
      15,
      31};  // B exponent
  const Written w = WriteGgx(test::TestDir("ktx2_dfd"));
  const std::size_t at = Le32(w.bytes, kDfdOffsetAt);
  for (int i = 0; i < 31; ++i)
    EXPECT_EQ(Le32(w.bytes, at + 4 * i), expected[i]) << "DFD word " << i;
}

TEST(Ktx2, KeyValueDataIsSortedNulTerminatedAndCarriesTheSidecar) {
  const Written w = WriteGgx(test::TestDir("ktx2_kvd"));
  const auto& b = w.bytes;
  std::size_t at = Le32(b, kKvdOffsetAt);
  const std::size_t end = at + Le32(b, kKvdLengthAt);
  std::vector<std::string> keys;
  std::string writer, orientation, sidecar;
  while (at < end) {
    const std::uint32_t length = Le32(b, at);
    const std::string entry(b.begin() + at + 4, b.begin() + at + 4 + length);
    const std::size_t nul = entry.find('\0');
    ASSERT_NE(nul, std::string::npos);
    ASSERT_EQ(entry.back(), '\0') << "value not NUL-terminated";
    const std::string key = entry.substr(0, nul),
                      value = entry.substr(nul + 1, entry.size() - nul - 2);
    keys.push_back(key);
    if (key == "KTXwriter") writer = value;
    if (key == "KTXorientation") orientation = value;
    if (key == "brdf.sidecar") sidecar = value;
    at += 4 + length;
    while (at % 4 != 0) EXPECT_EQ(b[at++], 0) << "valuePadding must be zero";
  }
  EXPECT_EQ(at, end);
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  EXPECT_EQ(writer.rfind("brdf-toolchain ", 0), 0u) << writer;
  EXPECT_EQ(orientation, "rdi");
  const auto j = nlohmann::json::parse(sidecar);
  EXPECT_EQ(j["theta_in_deg"], nlohmann::json::array({0, 20, 40, 60}));
  EXPECT_EQ(j["name"], "ggx03");
  EXPECT_EQ(j["extrapolation"]["p"], 0.2);
}

TEST(Ktx2, LevelImageIsEveryTexelEncodedInRowMajorSliceOrder) {
  const Written w = WriteGgx(test::TestDir("ktx2_payload"));
  const std::size_t base = Le64(w.bytes, kLevel0At);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 181; ++j)
      for (int i = 0; i < 361; ++i) {
        const std::size_t at = base + 4 * ((static_cast<std::size_t>(k) * 181 + j) * 361 + i);
        const float* t = w.lut.Texel(k, j, i);
        ASSERT_EQ(Le32(w.bytes, at), EncodeRgb9e5(t[0], t[1], t[2])) << i << " " << j << " " << k;
      }
}

TEST(Ktx2, ReadsBackTheQuantisedLutAndItsMetadata) {
  const Written w = WriteGgx(test::TestDir("ktx2_read"));
  const LoadedTexture t = ReadKtx2(w.path);
  EXPECT_EQ(t.container, TextureContainer::kKtx2);
  EXPECT_TRUE(t.theta_in_from_metadata);
  EXPECT_EQ(t.theta_in_deg, (std::vector<double>{0, 20, 40, 60}));
  ASSERT_TRUE(t.IsSingleLut());
  ASSERT_EQ(t.lut.texels.size(), w.lut.texels.size());
  for (std::size_t n = 0; n < w.lut.texels.size(); n += 3) {
    const auto q = DecodeRgb9e5(EncodeRgb9e5(&w.lut.texels[n]));
    for (int c = 0; c < 3; ++c) ASSERT_EQ(t.lut.texels[n + c], q[c]);
  }
  EXPECT_FALSE(t.sidecar_json.empty());
  EXPECT_EQ(ReadTextureFile(w.path).volume.words, t.volume.words);
}

TEST(Ktx2, SingleSliceAndManySlicesRoundTrip) {
  const std::string dir = test::TestDir("ktx2_slices");
  for (std::vector<double> theta :
       {std::vector<double>{0}, std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80}}) {
    const Lut lut = test::PatternLut(theta, static_cast<std::uint32_t>(theta.size()));
    const std::string path = dir + "/n" + std::to_string(theta.size()) + ".ktx2";
    WriteKtx2(path, lut, Meta("pattern"));
    const LoadedTexture t = ReadKtx2(path);
    EXPECT_EQ(t.volume.depth, static_cast<int>(theta.size()));
    EXPECT_EQ(t.theta_in_deg, theta);
    EXPECT_EQ(t.volume.words, PackLut(lut).words);
  }
}

TEST(Ktx2, RejectsTruncatedFilesWithPositionAndExpectation) {
  const Written w = WriteGgx(test::TestDir("ktx2_truncated"));
  for (std::size_t keep :
       {std::size_t{0}, std::size_t{5}, std::size_t{11}, std::size_t{40}, std::size_t{90},
        std::size_t{150}, w.bytes.size() / 2, w.bytes.size() - 1}) {
    const std::vector<std::uint8_t> cut(w.bytes.begin(), w.bytes.begin() + keep);
    const std::string msg = ExpectFormatError(cut, "cut.ktx2");
    EXPECT_NE(msg.find("cut.ktx2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected"), std::string::npos) << msg;
  }
  // Past the header, the message says which range falls outside the file.
  const std::vector<std::uint8_t> cut(w.bytes.begin(), w.bytes.end() - 1);
  const std::string msg = ExpectFormatError(cut, "cut.ktx2");
  EXPECT_NE(msg.find("level 0 image inside the file"), std::string::npos) << msg;
}

TEST(Ktx2, RejectsWrongIdentifier) {
  Written w = WriteGgx(test::TestDir("ktx2_magic"));
  w.bytes[5] = '1';  // «KTX 10»: a KTX 1 file
  const std::string msg = ExpectFormatError(w.bytes, "old.ktx");
  EXPECT_NE(msg.find("byte 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("KTX 2.0 identifier"), std::string::npos) << msg;
}

TEST(Ktx2, RejectsOtherFormatsNamingTheVkFormat) {
  Written w = WriteGgx(test::TestDir("ktx2_format"));
  test::SetLe32(w.bytes, kVkFormatAt, 97);  // VK_FORMAT_R16G16B16A16_SFLOAT
  const std::string msg = ExpectFormatError(w.bytes, "rgba16f.ktx2");
  EXPECT_NE(msg.find("byte 12"), std::string::npos) << msg;
  EXPECT_NE(msg.find("vkFormat 123"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got 97"), std::string::npos) << msg;
}

TEST(Ktx2, RejectsAForeignDataFormatDescriptor) {
  Written w = WriteGgx(test::TestDir("ktx2_bad_dfd"));
  const std::size_t dfd = Le32(w.bytes, kDfdOffsetAt);
  test::SetLe32(w.bytes, dfd + 4 * 10, 511);  // R mantissa sampleUpper
  const std::string msg = ExpectFormatError(w.bytes, "dfd.ktx2");
  EXPECT_NE(msg.find("R mantissa"), std::string::npos) << msg;
  EXPECT_NE(msg.find("8448"), std::string::npos) << msg;
}

TEST(Ktx2, RejectsLevelLengthThatDoesNotMatchTheDimensions) {
  Written w = WriteGgx(test::TestDir("ktx2_level"));
  test::SetLe32(w.bytes, kDepthAt, 5);
  const std::string msg = ExpectFormatError(w.bytes, "depth.ktx2");
  EXPECT_NE(msg.find("byteLength"), std::string::npos) << msg;
}

TEST(Ktx2, RejectsDamagedTexelsThroughTheChecksum) {
  Written w = WriteGgx(test::TestDir("ktx2_crc"));
  w.bytes[Le64(w.bytes, kLevel0At) + 1000] ^= 0x40;
  const std::string msg = ExpectFormatError(w.bytes, "damaged.ktx2");
  EXPECT_NE(msg.find("CRC-32"), std::string::npos) << msg;
}

TEST(Ktx2, SurvivesRandomCorruptionOfTheHeaders) {
  const Written w = WriteGgx(test::TestDir("ktx2_fuzz"));
  std::mt19937 rng(11);
  const std::size_t header_bytes = Le64(w.bytes, kLevel0At);
  std::uniform_int_distribution<std::size_t> where(0, header_bytes - 1);
  std::uniform_int_distribution<int> value(0, 255);
  int rejected = 0;
  for (int n = 0; n < 300; ++n) {
    std::vector<std::uint8_t> b = w.bytes;
    for (int f = 0; f < 3; ++f) b[where(rng)] = static_cast<std::uint8_t>(value(rng));
    try {
      ParseKtx2(b.data(), b.size(), "fuzz.ktx2");
    } catch (const Error&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
}

TEST(Ktx2, KeysAreValidated) {
  PackedVolume v;
  v.width = v.height = v.depth = 1;
  v.words = {0};
  EXPECT_THROW(EncodeKtx2(v, {{"", "x"}}), InvalidArgument);
  EXPECT_THROW(EncodeKtx2(v, {{"a", "1"}, {"a", "2"}}), InvalidArgument);
  // A user-supplied KTXwriter is replaced by ours, not duplicated.
  const std::string file = EncodeKtx2(v, {{"KTXwriter", "someone else"}, {"zz", "last"}});
  const auto t =
      ParseKtx2(reinterpret_cast<const std::uint8_t*>(file.data()), file.size(), "tiny.ktx2");
  int writers = 0;
  for (const auto& [k, val] : t.key_values) writers += k == "KTXwriter";
  EXPECT_EQ(writers, 1);
  EXPECT_EQ(t.key_values.back().first, "zz");
}

TEST(Ktx2, WritingIntoAMissingFolderFailsAndLeavesNothing) {
  const std::string dir = test::TestDir("ktx2_atomic");
  const Lut lut = test::PatternLut({0, 20}, 5);
  EXPECT_THROW(WriteKtx2(dir + "/missing/x.ktx2", lut, Meta("x")), IoError);
  WriteKtx2(dir + "/x.ktx2", lut, Meta("x"));
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"x.ktx2"});  // no temporary left behind
}

}  // namespace
}  // namespace brdf::exporter
