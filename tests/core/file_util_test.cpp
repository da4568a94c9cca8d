#include "brdf/core/file_util.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

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

TEST(Crc32, AgreesWithZlibAtEveryLengthAlignmentAndSplit) {
  // zlib's crc32 is an independent implementation of the same CRC. Lengths cover the table
  // path (< 64 bytes), the carry-less folds (64-byte blocks, 16-byte tails, byte tails) and
  // misaligned starts; the running form is checked across a split at every place.
  std::vector<std::uint8_t> bytes(1100);
  std::uint32_t x = 12345;
  for (std::uint8_t& b : bytes) {
    x = x * 1664525u + 1013904223u;
    b = static_cast<std::uint8_t>(x >> 24);
  }
  for (std::size_t offset = 0; offset < 4; ++offset)
    for (std::size_t n = 0; n + offset <= bytes.size(); ++n)
      ASSERT_EQ(Crc32(bytes.data() + offset, n),
                crc32(0, bytes.data() + offset, static_cast<uInt>(n)))
          << "offset " << offset << ", length " << n;
  const std::uint32_t whole = crc32(0, bytes.data(), static_cast<uInt>(bytes.size()));
  for (std::size_t split = 0; split <= bytes.size(); ++split)
    ASSERT_EQ(Crc32(bytes.data() + split, bytes.size() - split, Crc32(bytes.data(), split)), whole)
        << "split at " << split;
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

// A legal file name is at most 255 bytes (NAME_MAX on Linux); the temporary name must not
// make it fail.
TEST(AtomicWrite, WritesAFileWhoseNameHasTheLongestLegalLength) {
  const auto dir = brdf::test::NewTempDir("atomic-long");
  const std::string name(255 - 4, 'n');
  const std::string path = (dir / (name + ".bin")).string();
  ASSERT_EQ(std::filesystem::path(path).filename().string().size(), 255u);
  WriteFileAtomically(path, "long");
  EXPECT_EQ(ReadFileText(path, 100), "long");
}

// A process id that no longer runs: a child that has exited and been reaped.
pid_t DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(AtomicWrite, TemporariesOfKilledRunsAreRemovedByTheNextCheckOfThatFolder) {
  const auto dir = brdf::test::NewTempDir("atomic-stale");
  const pid_t dead = DeadPid();
  const auto touch = [&](const std::string& name) {
    std::ofstream(dir / name) << "partial";
    return (dir / name).string();
  };
  const std::string stale = touch(".brdf-" + std::to_string(dead) + "-0.tmp");
  const std::string legacy = touch(".gold.ktx2.tmp-" + std::to_string(dead) + "-3");
  const std::string live = touch(".brdf-" + std::to_string(::getppid()) + "-0.tmp");
  const std::string mine = touch(".brdf-" + std::to_string(::getpid()) + "-7.tmp");
  const std::string other = touch(".brdf-notes.tmp");

  std::vector<std::string> removed = CheckWritableOutput((dir / "gold.ktx2").string(), false);
  std::sort(removed.begin(), removed.end());
  std::vector<std::string> expected = {stale, legacy};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(removed, expected);
  EXPECT_FALSE(std::filesystem::exists(stale));
  EXPECT_FALSE(std::filesystem::exists(legacy));
  EXPECT_TRUE(std::filesystem::exists(live)) << "a running process's file was removed";
  EXPECT_TRUE(std::filesystem::exists(mine));
  EXPECT_TRUE(std::filesystem::exists(other));
}

TEST(OverwriteRule, RefusesExistingFilesAndNonRegularPaths) {
  const auto dir = brdf::test::NewTempDir("overwrite");
  const std::string file = (dir / "a.bin").string();
  EXPECT_NO_THROW(CheckWritableOutput(file, false));
  WriteFileAtomically(file, "x");
  try {
    CheckWritableOutputs({(dir / "new.bin").string(), file}, false);
    FAIL();
  } catch (const OutputExistsError& e) {
    EXPECT_EQ(e.paths(), std::vector<std::string>{file});
    EXPECT_EQ(std::string(e.what()), file + ": already exists");
  }
  EXPECT_NO_THROW(CheckWritableOutput(file, true));
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  std::filesystem::create_directory(dir / "folder");
  for (const auto& [name, kind] :
       {std::pair{"fifo", "a FIFO (named pipe)"}, std::pair{"folder", "a folder"}}) {
    try {
      CheckWritableOutput((dir / name).string(), true);
      FAIL() << name;
    } catch (const IoError& e) {
      EXPECT_EQ(std::string(e.what()), (dir / name).string() + ": exists and is " + kind +
                                           ", not a file; choose another output name");
    }
  }
}

// Reading a FIFO that nobody writes to would block forever with a plain open(2).
TEST(RegularFiles, FifosFoldersAndDevicesAreRefusedWithoutBlocking) {
  const auto dir = brdf::test::NewTempDir("special");
  const std::string fifo = (dir / "cap.bpc").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string expected = fifo + ": is a FIFO (named pipe), not a file";
  const auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { ReadFileBytes(fifo, 100); }), expected);
  EXPECT_EQ(message([&] { ReadFileHead(fifo, 100); }), expected);
  EXPECT_EQ(message([&] { MappedFile(fifo, 100); }), expected);
  EXPECT_EQ(message([&] { CheckRegularFile(fifo); }), expected);
  EXPECT_EQ(message([&] { CheckRegularFile((dir / "none").string()); }),
            (dir / "none").string() + ": no such file");
  EXPECT_EQ(message([&] { ReadFileBytes(dir.string(), 100); }),
            dir.string() + ": is a folder, not a file");
  EXPECT_EQ(message([&] { ReadFileBytes("/dev/null", 100); }),
            "/dev/null: is a device, not a file");
}

TEST(RegularFiles, MappedFileSeesTheBytesAndHonoursTheCap) {
  const auto dir = brdf::test::NewTempDir("mapped");
  const std::string path = (dir / "m.bin").string();
  WriteFileAtomically(path, "abc");
  const MappedFile m(path, 3);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data()), 3), "abc");
  EXPECT_THROW(MappedFile(path, 2), FormatError);
}

}  // namespace
}  // namespace brdf
