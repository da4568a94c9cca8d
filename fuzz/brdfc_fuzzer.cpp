// libFuzzer target for the compact LUT reader (`.brdfc`, docs/formats/compact.md): the parser
// `brdf eval` and `brdf info` use (exporter::ParseCompactLut, then the embedded sidecar as
// `info` reads it and a few values as `eval` samples them). Any bytes must parse or throw
// brdf::Error; a crash, hang, sanitizer report or other exception is a bug. What the reader
// accepts must serialize back to the same bytes, and every value it decodes must be finite and
// non-negative.
//
// The payload carries a CRC-32, so almost every mutation of a valid file stops at the checksum
// and never reaches what follows it (the sidecar, the decoder). Each input is therefore parsed
// twice: as it is, and with the checksum recomputed over bytes 36 to the end minus the sidecar
// length the header states.
// Seed corpus: fuzz/corpus/brdfc/ (fuzz/make_brdfc_corpus.py); run by the fuzz_readers test.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/sidecar.h"

namespace {

constexpr std::size_t kHeader = 36, kCrcAt = 28, kSidecarLengthAt = 32;

std::uint32_t LoadLe32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

void Check(const std::vector<std::uint8_t>& bytes) {
  brdf::exporter::LoadedCompact c;
  try {
    c = brdf::exporter::ParseCompactLut(bytes, "fuzz.brdfc");
  } catch (const brdf::Error&) {
    return;
  }
  const brdf::exporter::CompactLut& lut = c.compact;
  // Whatever was read, the writer lays out the same bytes.
  const std::string again = brdf::exporter::SerializeCompactLut(lut, c.sidecar_json);
  if (again.size() != bytes.size() ||
      again.compare(0, again.size(), reinterpret_cast<const char*>(bytes.data()), bytes.size()))
    __builtin_trap();
  if (lut.PayloadBytes() + c.sidecar_json.size() != bytes.size()) __builtin_trap();
  if (!c.sidecar_json.empty()) {
    try {
      brdf::exporter::ParseSidecarJson(c.sidecar_json, "fuzz.brdfc");
    } catch (const brdf::Error&) {
    }
  }
  // A few directions as `brdf eval` takes them, across θin (reciprocity and both clamps).
  for (const double theta_in : {0.0, 17.5, 44.0, 89.0})
    for (const double theta_out : {0.0, 35.0, 80.0})
      for (const double phi_out : {0.0, 90.0, 181.0, 359.5}) {
        const std::array<float, 3> f = lut.SampleAngles(theta_in, theta_out, phi_out);
        for (const float v : f)
          if (!(std::isfinite(v) && v >= 0)) __builtin_trap();
      }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  Check(bytes);
  if (size >= kHeader) {
    const std::uint64_t sidecar = LoadLe32(data + kSidecarLengthAt);
    if (sidecar <= size - kHeader) {
      const std::uint32_t crc = brdf::Crc32(data + kHeader, size - kHeader - sidecar);
      for (int b = 0; b < 4; ++b) bytes[kCrcAt + b] = static_cast<std::uint8_t>(crc >> (8 * b));
      Check(bytes);
    }
  }
  return 0;
}
