#include "brdf/core/file_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "brdf/core/error.h"
#include "test_support.h"

namespace brdf {
namespace {

TEST(Crc32, MatchesTheStandardCheckValue) {
  // The CRC-32/ISO-HDLC check value of "123456789" is 0xCBF43926 (published catalogue).
  const std::string s = "123456789";
  EXPECT_EQ(Crc32(s.data(), s.size()), 0xCBF43926u);
  // Running form: two halves give the same result.
  EXPECT_EQ(Crc32(s.data() + 4, 5, Crc32(s.data(), 4)), 0xCBF43926u);
  EXPECT_EQ(Crc32(nullptr, 0), 0u);
}

TEST(ByteReader, ReadsLittleEndianAndReportsOffsetsPastEnd) {
  const std::uint8_t data[] = {0x01, 0x02, 0x03, 0x04, 0x05};
  ByteReader r(data, sizeof data, "x.bin", 100);
  EXPECT_EQ(r.U32("a"), 0x04030201u);
  EXPECT_EQ(r.offset(), 104u);
  try {
    r.U32("the count");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "x.bin: byte 104: expected 4 more bytes for the count, got end of data after 1 bytes");
  }
}

TEST(AtomicWrite, ReplacesWholeFileAndLeavesNoTemporary) {
  const auto dir = brdf::test::NewTempDir("atomic");
  const std::string path = (dir / "out.bin").string();
  WriteFileAtomically(path, "first");
  WriteFileAtomically(path, "second!");
  EXPECT_EQ(ReadFileText(path, 100), "second!");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
  EXPECT_THROW(ReadFileBytes(path, 3), FormatError);
  {
    AtomicOutputPath abandoned((dir / "never.bin").string());
    WriteFileAtomically(abandoned.temp_path(), "x");
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "never.bin"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace brdf
