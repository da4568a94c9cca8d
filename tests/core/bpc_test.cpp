#include "brdf/core/bpc.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <bit>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

// Sizes from docs/formats/bpc.md, written out here independently of the implementation.
constexpr std::size_t kPreamble = 12;
constexpr std::size_t kChunkHeader = 24;
constexpr std::size_t kSliceHeader = 32;
std::size_t SliceChunkBytes(const Slice& s) {
  return kChunkHeader + kSliceHeader + s.samples.size() * (s.has_sigma ? 44 : 32);
}

float FloatFromBits(std::uint32_t bits) { return std::bit_cast<float>(bits); }
std::uint32_t Bits(float v) { return std::bit_cast<std::uint32_t>(v); }
std::uint64_t Bits(double v) { return std::bit_cast<std::uint64_t>(v); }

Metadata TestMetadata() {
  Metadata m;
  m.sample_name = "Kupfer gebürstet – 銅 ✓";
  m.instrument_model = "MiniDiff V2 (simulated)";
  m.instrument_serial = "SIM-0001";
  m.firmware_version = "2.3.1";
  m.protocol_version = "1";
  m.calibration_reference = "Spectralon SRS-99";
  m.calibration_time = "2026-11-22T09:00:00Z";
  m.capture_start = "2026-11-22T10:00:00Z";
  m.operator_notes = "line one\nline \"two\"\t\\ end";
  m.software_version = "0.1.0";
  m.extra["seed"] = "42";
  m.extra["source file"] = "données/copper.json";
  return m;
}

// A small capture whose values exercise every float class: signed zeros, denormals, the
// extremes, infinities and NaNs with payloads, and every flag byte.
Measurement TestMeasurement(int slices = 4, int samples_per_slice = 37) {
  Measurement m;
  m.metadata = TestMetadata();
  m.metadata.capture_end = "2026-11-22T10:05:00Z";
  const std::uint32_t specials[] = {
      0x00000000u, 0x80000000u,  // +0, -0
      0x00000001u, 0x807fffffu,  // smallest and largest-magnitude negative denormal
      0x00800000u, 0x7f7fffffu,  // FLT_MIN, FLT_MAX
      0x7f800000u, 0xff800000u,  // ±inf
      0x7fc12345u, 0xffa00001u,  // quiet NaNs with payloads
      0x7f812345u,               // signalling NaN pattern
  };
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u(0.0f, 10.0f);
  int k = 0;
  for (int i = 0; i < slices; ++i) {
    Slice s;
    s.theta_in_deg = 20.0 * i + (i == 1 ? 1e-12 : 0.0);
    s.phi_in_deg = i == 2 ? -0.0 : 0.0;
    s.has_sigma = i % 2 == 0;
    s.complete = i != 3;
    for (int j = 0; j < samples_per_slice; ++j, ++k) {
      Sample p;
      p.theta_in_deg = static_cast<float>(s.theta_in_deg);
      p.phi_in_deg = 0.0f;
      p.theta_out_deg = static_cast<float>(j % 76);
      p.phi_out_deg = static_cast<float>(j) * 0.5f;
      for (int c = 0; c < 3; ++c) {
        p.rgb[c] =
            (j + c) % 5 == 0 ? FloatFromBits(specials[(k + c) % std::size(specials)]) : u(rng);
        p.sigma[c] =
            s.has_sigma ? FloatFromBits(specials[(k + 3 * c) % std::size(specials)]) : 0.0f;
      }
      p.flags = static_cast<std::uint8_t>(k % 256);
      s.samples.push_back(p);
    }
    m.slices.push_back(std::move(s));
  }
  return m;
}

void ExpectSameMetadata(const Metadata& a, const Metadata& b) {
  EXPECT_EQ(a.sample_name, b.sample_name);
  EXPECT_EQ(a.instrument_model, b.instrument_model);
  EXPECT_EQ(a.instrument_serial, b.instrument_serial);
  EXPECT_EQ(a.firmware_version, b.firmware_version);
  EXPECT_EQ(a.protocol_version, b.protocol_version);
  EXPECT_EQ(a.calibration_reference, b.calibration_reference);
  EXPECT_EQ(a.calibration_time, b.calibration_time);
  EXPECT_EQ(a.capture_start, b.capture_start);
  EXPECT_EQ(a.capture_end, b.capture_end);
  EXPECT_EQ(a.operator_notes, b.operator_notes);
  EXPECT_EQ(a.units, b.units);
  EXPECT_EQ(a.software_version, b.software_version);
  EXPECT_EQ(a.extra, b.extra);
}

// Bit-exact comparison; sigma is only carried when the slice says so (zero otherwise).
void ExpectSameSlice(const Slice& want, const Slice& got) {
  EXPECT_EQ(Bits(want.theta_in_deg), Bits(got.theta_in_deg));
  EXPECT_EQ(Bits(want.phi_in_deg), Bits(got.phi_in_deg));
  EXPECT_EQ(want.has_sigma, got.has_sigma);
  EXPECT_EQ(want.complete, got.complete);
  ASSERT_EQ(want.samples.size(), got.samples.size());
  for (std::size_t i = 0; i < want.samples.size(); ++i) {
    const Sample& a = want.samples[i];
    const Sample& b = got.samples[i];
    SCOPED_TRACE("sample " + std::to_string(i));
    EXPECT_EQ(Bits(a.theta_in_deg), Bits(b.theta_in_deg));
    EXPECT_EQ(Bits(a.phi_in_deg), Bits(b.phi_in_deg));
    EXPECT_EQ(Bits(a.theta_out_deg), Bits(b.theta_out_deg));
    EXPECT_EQ(Bits(a.phi_out_deg), Bits(b.phi_out_deg));
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(Bits(a.rgb[c]), Bits(b.rgb[c]));
      EXPECT_EQ(want.has_sigma ? Bits(a.sigma[c]) : 0u, Bits(b.sigma[c]));
    }
    EXPECT_EQ(a.flags, b.flags);
  }
}

class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(brdf::test::ScopedTempDir::MakeTempDir("bpc-" + name)) {}
  ~TempDir() { fs::remove_all(path_); }
  std::string File(const std::string& name) const { return (path_ / name).string(); }
  std::vector<std::string> Entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(path_)) out.push_back(e.path().filename());
    return out;
  }

 private:
  fs::path path_;
};

std::vector<std::uint8_t> Bytes(const std::string& s) { return {s.begin(), s.end()}; }

BpcReadResult Parse(const std::vector<std::uint8_t>& bytes, std::size_t size) {
  return ParseBpc(bytes.data(), size, "mem.bpc");
}

// Chunk boundaries of an encoded measurement, from the documented layout: the end of the
// header chunk, then the end of each slice chunk, then the end of the file.
std::vector<std::size_t> Boundaries(const Measurement& m, std::size_t file_size) {
  const std::uint64_t header_json = [&] {
    const std::string bytes = EncodeBpc(m);
    std::uint64_t n = 0;
    std::memcpy(&n, bytes.data() + kPreamble + 8, 8);  // little-endian host (x86-64, arm64)
    return n;
  }();
  std::vector<std::size_t> b = {kPreamble + kChunkHeader + header_json};
  for (const Slice& s : m.slices) b.push_back(b.back() + SliceChunkBytes(s));
  b.push_back(file_size);
  return b;
}

TEST(Bpc, RoundTripIsBitExact) {
  TempDir dir("roundtrip");
  const Measurement m = TestMeasurement();
  WriteBpc(dir.File("a.bpc"), m);
  const BpcReadResult r = ReadBpc(dir.File("a.bpc"));
  EXPECT_TRUE(r.problems.empty());
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.valid_bytes, fs::file_size(dir.File("a.bpc")));
  ASSERT_EQ(r.measurement.slices.size(), m.slices.size());
  for (std::size_t i = 0; i < m.slices.size(); ++i)
    ExpectSameSlice(m.slices[i], r.measurement.slices[i]);
  ExpectSameMetadata(m.metadata, r.measurement.metadata);
  EXPECT_EQ(r.slice_indices, (std::vector<int>{0, 1, 2, 3}));
}

TEST(Bpc, EveryPrefixEndingOnAChunkBoundaryIsAnIntactFile) {
  const Measurement m = TestMeasurement();
  const std::vector<std::uint8_t> bytes = Bytes(EncodeBpc(m));
  const std::vector<std::size_t> b = Boundaries(m, bytes.size());
  for (std::size_t k = 0; k < b.size(); ++k) {
    SCOPED_TRACE("boundary " + std::to_string(b[k]));
    const BpcReadResult r = Parse(bytes, b[k]);
    EXPECT_TRUE(r.problems.empty()) << (r.problems.empty() ? "" : r.problems[0].message);
    EXPECT_EQ(r.valid_bytes, b[k]);
    EXPECT_EQ(r.finished, k + 1 == b.size());
    ASSERT_EQ(r.measurement.slices.size(), std::min(k, m.slices.size()));
    for (std::size_t i = 0; i < r.measurement.slices.size(); ++i)
      ExpectSameSlice(m.slices[i], r.measurement.slices[i]);
  }
}

// What a cut at byte `cut` must give, from the chunk boundaries alone (docs/formats/bpc.md,
// "Reading a damaged file").
void ExpectCutReadsAsTruncated(const Measurement& m, const std::vector<std::size_t>& b,
                               const BpcReadResult& r, std::size_t cut) {
  std::size_t k = 0;  // boundaries at or before the cut
  while (k < b.size() && b[k] <= cut) ++k;
  ASSERT_GE(k, 1u);
  const std::size_t complete_slices = std::min(k - 1, m.slices.size());
  ASSERT_EQ(r.measurement.slices.size(), complete_slices);
  for (std::size_t i = 0; i < complete_slices; ++i)
    ExpectSameSlice(m.slices[i], r.measurement.slices[i]);
  const std::size_t last = b[k - 1];
  EXPECT_EQ(r.valid_bytes, last);
  EXPECT_EQ(r.finished, cut == b.back());
  if (last == cut) {
    EXPECT_TRUE(r.problems.empty());
    return;
  }
  ASSERT_EQ(r.problems.size(), 1u);
  const BpcProblem& p = r.problems[0];
  EXPECT_EQ(p.kind, BpcProblemKind::kTruncated);
  EXPECT_EQ(p.offset, last);
  EXPECT_EQ(p.offset + p.size, cut);
  // The slice is known once its whole 24-byte chunk header is there.
  const bool in_slice = k - 1 < m.slices.size();
  EXPECT_EQ(p.slice_index, in_slice && cut - last >= kChunkHeader ? static_cast<int>(k - 1) : -1);
  EXPECT_NE(p.message.find("byte " + std::to_string(last)), std::string::npos) << p.message;
  EXPECT_NE(p.message.find(std::to_string(cut)), std::string::npos) << p.message;
  // The library says what happened in the format's terms; what to do is the tool's to say.
  EXPECT_NE(p.message.find("interrupted capture"), std::string::npos) << p.message;
  EXPECT_EQ(p.message.find("--"), std::string::npos) << p.message;
}

TEST(Bpc, ACutAtAnyByteKeepsTheCompleteSlicesAndReportsTheTail) {
  const Measurement m = TestMeasurement();
  const std::vector<std::uint8_t> bytes = Bytes(EncodeBpc(m));
  const std::vector<std::size_t> b = Boundaries(m, bytes.size());
  for (std::size_t cut = 0; cut < b[0]; ++cut)
    EXPECT_THROW(Parse(bytes, cut), FormatError) << "cut " << cut;
  for (std::size_t cut = b[0]; cut <= bytes.size(); ++cut) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    ExpectCutReadsAsTruncated(m, b, Parse(bytes, cut), cut);
    if (HasFailure()) return;  // one diagnosis is enough
  }
}

TEST(Bpc, FilesCutAtRandomOffsetsOpenFromDisk) {
  TempDir dir("cut");
  const Measurement m = TestMeasurement(4, 200);
  const std::string full = EncodeBpc(m);
  const std::vector<std::size_t> b = Boundaries(m, full.size());
  std::mt19937 rng(20261122);
  std::uniform_int_distribution<std::size_t> pick(b[0], full.size() - 1);
  for (int i = 0; i < 25; ++i) {
    const std::size_t cut = pick(rng);
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    const std::string path = dir.File("cut.bpc");
    WriteFileAtomically(path, std::string_view(full).substr(0, cut));
    ExpectCutReadsAsTruncated(m, b, ReadBpc(path), cut);
    if (cut != *std::upper_bound(b.begin(), b.end(), cut) && cut != b[0]) {
      try {
        LoadBpc(path);
        ADD_FAILURE() << "LoadBpc accepted a truncated file";
      } catch (const FormatError& e) {
        EXPECT_EQ(e.file(), path);
      }
    }
  }
}

TEST(Bpc, AFlippedByteIsReportedWithTheSliceItBelongsTo) {
  const Measurement m = TestMeasurement(3, 20);
  const std::vector<std::uint8_t> clean = Bytes(EncodeBpc(m));
  const std::vector<std::size_t> b = Boundaries(m, clean.size());
  for (const std::uint8_t mask : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xff}}) {
    for (std::size_t at = 0; at < clean.size(); ++at) {
      SCOPED_TRACE("byte " + std::to_string(at) + " xor " + std::to_string(mask));
      std::vector<std::uint8_t> bytes = clean;
      bytes[at] ^= mask;
      if (at < b[0]) {
        EXPECT_THROW(Parse(bytes, bytes.size()), FormatError);
        continue;
      }
      const BpcReadResult r = Parse(bytes, bytes.size());
      std::size_t chunk = 0;  // 0..slices-1: slice chunks, slices: end chunk
      while (b[chunk + 1] <= at) ++chunk;
      const bool is_slice = chunk < m.slices.size();
      ASSERT_EQ(r.problems.size(), 1u);
      const BpcProblem& p = r.problems[0];
      EXPECT_EQ(p.kind, BpcProblemKind::kCorrupt);
      EXPECT_EQ(p.offset, b[chunk]);
      EXPECT_EQ(p.size, b[chunk + 1] - b[chunk]);
      EXPECT_EQ(p.slice_index, is_slice ? static_cast<int>(chunk) : -1);
      if (is_slice) {
        EXPECT_NE(p.message.find("(slice " + std::to_string(chunk) + ")"), std::string::npos)
            << p.message;
      }
      EXPECT_EQ(r.valid_bytes, b[chunk]);
      EXPECT_EQ(r.finished, is_slice);
      EXPECT_EQ(r.intact_data_after_damage, is_slice);
      // Every other slice is still there, bit-exact.
      std::vector<int> want_indices;
      for (int i = 0; i < static_cast<int>(m.slices.size()); ++i)
        if (!is_slice || i != static_cast<int>(chunk)) want_indices.push_back(i);
      ASSERT_EQ(r.slice_indices, want_indices);
      for (std::size_t i = 0; i < want_indices.size(); ++i)
        ExpectSameSlice(m.slices[want_indices[i]], r.measurement.slices[i]);
      if (HasFailure()) return;
    }
  }
}

// Rewrites the CRC-32s of the chunk at `at` after a test edited it, so only the edit is seen.
void FixChunkCrcs(std::vector<std::uint8_t>& bytes, std::size_t at) {
  std::uint64_t n = 0;
  for (int i = 7; i >= 0; --i) n = (n << 8) | bytes[at + 8 + i];
  const auto put = [&](std::size_t where, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes[where + i] = static_cast<std::uint8_t>(v >> (8 * i));
  };
  if (at + kChunkHeader + n <= bytes.size())
    put(at + 16, Crc32(bytes.data() + at + kChunkHeader, static_cast<std::size_t>(n)));
  put(at + 20, Crc32(bytes.data() + at, 20));
}

void PutU64(std::vector<std::uint8_t>& bytes, std::size_t where, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) bytes[where + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

TEST(Bpc, AbsurdLengthsAndCountsAreRefusedWithoutAllocating) {
  const Measurement m = TestMeasurement(2, 10);
  const std::vector<std::uint8_t> clean = Bytes(EncodeBpc(m));
  const std::vector<std::size_t> b = Boundaries(m, clean.size());
  {
    // A payload length far beyond the file, with a consistent header CRC: read as a cut.
    std::vector<std::uint8_t> bytes = clean;
    PutU64(bytes, b[1] + 8, std::uint64_t{1} << 62);
    FixChunkCrcs(bytes, b[1]);
    const BpcReadResult r = Parse(bytes, bytes.size());
    ASSERT_EQ(r.problems.size(), 1u);
    EXPECT_EQ(r.problems[0].kind, BpcProblemKind::kTruncated);
    EXPECT_EQ(r.problems[0].slice_index, 1);
    EXPECT_EQ(r.measurement.slices.size(), 1u);
  }
  {
    // A sample count of 2^61 in a 10-sample payload with matching CRCs.
    std::vector<std::uint8_t> bytes = clean;
    PutU64(bytes, b[0] + kChunkHeader + 16, std::uint64_t{1} << 61);
    FixChunkCrcs(bytes, b[0]);
    const BpcReadResult r = Parse(bytes, bytes.size());
    ASSERT_EQ(r.problems.size(), 1u);
    EXPECT_EQ(r.problems[0].kind, BpcProblemKind::kCorrupt);
    EXPECT_EQ(r.problems[0].slice_index, 0);
    EXPECT_NE(r.problems[0].message.find("sample count 2305843009213693952"), std::string::npos)
        << r.problems[0].message;
    ASSERT_EQ(r.measurement.slices.size(), 1u);
    ExpectSameSlice(m.slices[1], r.measurement.slices[0]);
  }
  {
    // A header JSON length beyond the file.
    std::vector<std::uint8_t> bytes = clean;
    PutU64(bytes, kPreamble + 8, std::uint64_t{1} << 62);
    FixChunkCrcs(bytes, kPreamble);
    EXPECT_THROW(Parse(bytes, bytes.size()), FormatError);
  }
}

template <class F>
FormatError CatchFormatError(F&& f) {
  try {
    f();
  } catch (const FormatError& e) {
    return e;
  }
  ADD_FAILURE() << "no FormatError";
  return FormatError("", "", "", "");
}

TEST(Bpc, UnreadableHeadersNameFileOffsetExpectedAndFound) {
  TempDir dir("header");
  const std::vector<std::uint8_t> clean = Bytes(EncodeBpc(TestMeasurement(1, 3)));
  const std::string path = dir.File("bad.bpc");
  const auto write = [&](const std::vector<std::uint8_t>& v) {
    WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(v.data()), v.size()));
  };
  {
    std::vector<std::uint8_t> v = clean;
    v[1] = 'X';
    write(v);
    const FormatError e = CatchFormatError([&] { ReadBpc(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.position(), "byte 0");
    EXPECT_NE(e.expected().find("89 42 50 43 0d 0a 1a 0a"), std::string::npos) << e.what();
    EXPECT_EQ(e.got(), "89 58 50 43 0d 0a 1a 0a");
  }
  {
    write({});
    const FormatError e = CatchFormatError([&] { ReadBpc(path); });
    EXPECT_EQ(e.got(), "an empty file");
  }
  {
    std::vector<std::uint8_t> v = clean;
    v[8] = 2;  // major version 2
    write(v);
    const FormatError e = CatchFormatError([&] { ReadBpc(path); });
    EXPECT_EQ(e.position(), "byte 8");
    EXPECT_EQ(e.expected(), "format version 1.x");
    EXPECT_EQ(e.got(), "version 2.0");
  }
  {
    std::vector<std::uint8_t> v = clean;
    v[kPreamble + kChunkHeader + 5] ^= 0x20;  // inside the header JSON
    write(v);
    const FormatError e = CatchFormatError([&] { ReadBpc(path); });
    EXPECT_EQ(e.position(), "byte " + std::to_string(kPreamble + kChunkHeader));
    EXPECT_NE(e.expected().find("header JSON CRC-32"), std::string::npos) << e.what();
  }
  {
    // CRC-consistent but not JSON.
    std::vector<std::uint8_t> v = clean;
    v[kPreamble + kChunkHeader] = '[';
    FixChunkCrcs(v, kPreamble);
    write(v);
    const FormatError e = CatchFormatError([&] { ReadBpc(path); });
    EXPECT_EQ(e.expected(), "a UTF-8 JSON object");
    EXPECT_EQ(e.got(), "malformed JSON");
  }
  {
    std::vector<std::uint8_t> v = clean;
    v[kPreamble] = 'S';  // tag of the first chunk
    write(v);
    const FormatError e = CatchFormatError([&] { ReadBpc(path); });
    EXPECT_EQ(e.position(), "byte 12");
    EXPECT_EQ(e.expected(), "chunk tag 'HEAD'");
    EXPECT_EQ(e.got(), "'SEAD'");
  }
  EXPECT_THROW(ReadBpc(dir.File("missing.bpc")), IoError);
}

TEST(Bpc, ResumeContinuesAnInterruptedCaptureToTheSameFile) {
  TempDir dir("resume");
  const Measurement m = TestMeasurement();
  Metadata start = m.metadata;
  start.capture_end.clear();

  const std::string reference = dir.File("reference.bpc");
  {
    BpcAppender a = BpcAppender::Create(reference, start);
    for (const Slice& s : m.slices) a.AppendSlice(s);
    a.Finish(m.metadata);
  }

  const std::string path = dir.File("interrupted.bpc");
  std::uint64_t after_two = 0;
  {
    BpcAppender a = BpcAppender::Create(path, start);
    a.AppendSlice(m.slices[0]);
    a.AppendSlice(m.slices[1]);
    after_two = fs::file_size(path);
    a.AppendSlice(m.slices[2]);
  }  // the process "dies" while slice 2 is being written: keep only part of its chunk
  fs::resize_file(path, after_two + 100);
  {
    BpcReadResult existing;
    BpcAppender a = BpcAppender::Resume(path, &existing);
    EXPECT_EQ(fs::file_size(path), after_two);
    EXPECT_EQ(existing.valid_bytes, after_two);
    ASSERT_EQ(existing.problems.size(), 1u);
    EXPECT_EQ(existing.problems[0].slice_index, 2);
    EXPECT_EQ(existing.measurement.slices.size(), 2u);
    EXPECT_EQ(a.slice_count(), 2);
    a.AppendSlice(m.slices[2]);
    a.AppendSlice(m.slices[3]);
    a.Finish(m.metadata);
  }
  EXPECT_EQ(ReadFileText(path, 1 << 20), ReadFileText(reference, 1 << 20));
  const BpcReadResult r = ReadBpc(path);
  EXPECT_TRUE(r.problems.empty());
  EXPECT_TRUE(r.finished);
  ASSERT_EQ(r.measurement.slices.size(), m.slices.size());
  for (std::size_t i = 0; i < m.slices.size(); ++i)
    ExpectSameSlice(m.slices[i], r.measurement.slices[i]);
  ExpectSameMetadata(m.metadata, r.measurement.metadata);
  // An unfinished but intact capture loads as is (a capture in progress).
  fs::resize_file(path, after_two);
  EXPECT_EQ(LoadBpc(path).slices.size(), 2u);
}

TEST(Bpc, ResumeSurvivesAZeroFilledTail) {
  // After a crash some file systems keep the new length of a file but not its data.
  TempDir dir("zeros");
  const Measurement m = TestMeasurement(2, 10);
  const std::string path = dir.File("z.bpc");
  {
    BpcAppender a = BpcAppender::Create(path, m.metadata);
    a.AppendSlice(m.slices[0]);
  }
  const std::uint64_t good = fs::file_size(path);
  fs::resize_file(path, good + 700);
  const BpcReadResult r = ReadBpc(path);
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].kind, BpcProblemKind::kCorrupt);
  EXPECT_EQ(r.problems[0].offset, good);
  EXPECT_EQ(r.problems[0].size, 700u);
  EXPECT_EQ(r.problems[0].slice_index, -1);
  {
    BpcAppender a = BpcAppender::Resume(path, nullptr);
    a.AppendSlice(m.slices[1]);
    a.Finish(m.metadata);
  }
  const Measurement back = LoadBpc(path);
  ASSERT_EQ(back.slices.size(), 2u);
  ExpectSameSlice(m.slices[1], back.slices[1]);
}

TEST(Bpc, ResumeRefusesFinishedFilesAndDamageBeforeIntactSlices) {
  TempDir dir("refuse");
  const Measurement m = TestMeasurement(3, 10);
  const std::string path = dir.File("f.bpc");
  WriteBpc(path, m);
  EXPECT_THROW(BpcAppender::Resume(path, nullptr), InvalidArgument);

  std::vector<std::uint8_t> bytes = Bytes(EncodeBpc(m));
  const std::vector<std::size_t> b = Boundaries(m, bytes.size());
  bytes.resize(b[3]);        // unfinished: no end chunk
  bytes[b[0] + 40] ^= 0x10;  // damage slice 0; slices 1 and 2 are intact after it
  WriteFileAtomically(path,
                      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  EXPECT_THROW(BpcAppender::Resume(path, nullptr), FormatError);
  EXPECT_EQ(fs::file_size(path), b[3]);  // untouched
}

TEST(Bpc, AppenderRefusesToWriteAfterFinish) {
  TempDir dir("finish");
  const Measurement m = TestMeasurement(1, 2);
  BpcAppender a = BpcAppender::Create(dir.File("a.bpc"), m.metadata);
  a.Finish(m.metadata);
  EXPECT_FALSE(a.is_open());
  EXPECT_THROW(a.AppendSlice(m.slices[0]), Error);
}

TEST(Bpc, WriteBpcNeverLeavesAPartialFileOrATemporary) {
  TempDir dir("atomic");
  const std::string path = dir.File("capture.bpc");
  const Measurement small = TestMeasurement(1, 5);
  WriteBpc(path, small);
  const std::string before = ReadFileText(path, 1 << 20);
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"capture.bpc"});

  // Make the write fail half way: a file size limit below the encoded size (EFBIG).
  const Measurement big = TestMeasurement(4, 2000);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = old;
  limited.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  EXPECT_THROW(WriteBpc(path, big), IoError);
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &old), 0);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(ReadFileText(path, 1 << 20), before);
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"capture.bpc"});

  WriteBpc(path, big);
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"capture.bpc"});
  EXPECT_EQ(LoadBpc(path).SampleCount(), 8000u);
}

// A chunk as docs/formats/bpc.md lays it out, built here independently of the writer.
std::string SpecChunk(const char tag[4], std::uint32_t index, const std::string& payload) {
  std::string out(tag, 4);
  AppendU32(out, index);
  AppendU64(out, payload.size());
  AppendU32(out, Crc32(payload.data(), payload.size()));
  AppendU32(out, Crc32(out.data(), 20));
  return out + payload;
}

void ExpectSameResult(const BpcReadResult& a, const BpcReadResult& b) {
  EXPECT_EQ(a.finished, b.finished);
  EXPECT_EQ(a.valid_bytes, b.valid_bytes);
  EXPECT_EQ(a.slice_indices, b.slice_indices);
  EXPECT_EQ(a.intact_data_after_damage, b.intact_data_after_damage);
  ASSERT_EQ(a.problems.size(), b.problems.size());
  for (std::size_t i = 0; i < a.problems.size(); ++i) {
    EXPECT_EQ(a.problems[i].offset, b.problems[i].offset);
    EXPECT_EQ(a.problems[i].size, b.problems[i].size);
    EXPECT_EQ(a.problems[i].slice_index, b.problems[i].slice_index);
  }
  ExpectSameMetadata(a.measurement.metadata, b.measurement.metadata);
  ASSERT_EQ(a.measurement.slices.size(), b.measurement.slices.size());
  for (std::size_t i = 0; i < a.measurement.slices.size(); ++i)
    ExpectSameSlice(a.measurement.slices[i], b.measurement.slices[i]);
}

TEST(Bpc, ReadingFromDiskMatchesParsingInMemory) {
  // ReadBpc streams intact files and falls back to the tolerant in-memory parser on damage;
  // both must give the same answer for every kind of file.
  TempDir dir("stream");
  Measurement m = TestMeasurement(3, 3000);
  m.slices[1].samples.clear();  // an empty slice
  const std::string full = EncodeBpc(m);
  const std::vector<std::size_t> b = Boundaries(m, full.size());
  std::vector<std::string> files = {
      full,
      full.substr(0, b[3]),          // unfinished
      full.substr(0, b[0]),          // header only
      full.substr(0, b[2] + 50000),  // cut inside slice 2
      full + "x",                    // trailing data
      // A chunk type from a later minor version between slices 0 and 1: skipped.
      full.substr(0, b[1]) + SpecChunk("XTRA", 0xffffffffu, std::string(70000, 'q')) +
          full.substr(b[1]),
  };
  std::string flipped = full;
  flipped[b[2] + 12345] ^= 0x40;
  files.push_back(flipped);
  files.push_back(EncodeBpc(Measurement{}));  // no slices at all
  for (std::size_t i = 0; i < files.size(); ++i) {
    SCOPED_TRACE("file " + std::to_string(i));
    const std::string path = dir.File("f" + std::to_string(i) + ".bpc");
    WriteFileAtomically(path, files[i]);
    const auto* data = reinterpret_cast<const std::uint8_t*>(files[i].data());
    ExpectSameResult(ReadBpc(path), ParseBpc(data, files[i].size(), path));
  }
  // The unknown chunk really was skipped rather than reported.
  const BpcReadResult r = ReadBpc(dir.File("f5.bpc"));
  EXPECT_TRUE(r.problems.empty());
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.measurement.slices.size(), 3u);
}

TEST(Bpc, AFailedAppendLeavesAValidFileAndCanBeRetried) {
  TempDir dir("diskfull");
  const Measurement m = TestMeasurement(2, 3000);
  const std::string path = dir.File("c.bpc");
  BpcAppender a = BpcAppender::Create(path, m.metadata);
  a.AppendSlice(m.slices[0]);
  const auto good = fs::file_size(path);
  // "Disk full" half way through slice 1: a file size limit (EFBIG).
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = old;
  limited.rlim_cur = good + SliceChunkBytes(m.slices[1]) / 2;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  EXPECT_THROW(a.AppendSlice(m.slices[1]), IoError);
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &old), 0);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(fs::file_size(path), good);
  const BpcReadResult mid = ReadBpc(path);
  EXPECT_TRUE(mid.problems.empty());
  EXPECT_EQ(mid.measurement.slices.size(), 1u);
  EXPECT_EQ(a.slice_count(), 1);
  a.AppendSlice(m.slices[1]);  // space is back: the retry continues the file cleanly
  a.Finish(m.metadata);
  const BpcReadResult r = ReadBpc(path);
  EXPECT_TRUE(r.problems.empty());
  EXPECT_TRUE(r.finished);
  ASSERT_EQ(r.measurement.slices.size(), 2u);
  ExpectSameSlice(m.slices[1], r.measurement.slices[1]);
}

}  // namespace
}  // namespace brdf
