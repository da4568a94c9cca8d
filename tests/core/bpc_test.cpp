#include "brdf/core/bpc.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

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
      : path_(fs::temp_directory_path() /
              ("brdf_bpc_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
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

}  // namespace
}  // namespace brdf
