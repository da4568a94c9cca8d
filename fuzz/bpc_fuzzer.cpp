// libFuzzer target for the .bpc reader (docs/formats/bpc.md): any bytes must give a result or
// a FormatError, never a crash, hang or unbounded allocation; what is read must be internally
// consistent and must survive a rewrite bit for bit.
//
// Every chunk carries two CRC-32s, so almost every mutation of a valid file is caught by a CRC
// check and never reaches the code behind it (chunk framing, slice decoding, the JSON of HEAD
// and END). Each input is therefore parsed twice: as it is (the CRC checks and damage
// reporting), and with every chunk's CRCs recomputed (everything behind them).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"

namespace {

constexpr std::size_t kPreamble = 12, kChunkHeader = 24;

std::uint64_t LoadLe64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
void StoreLe32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// The input with each chunk's payload CRC (over the payload bytes present) and header CRC
// rewritten, walking the chunks as the format lays them out.
std::vector<std::uint8_t> WithRepairedCrcs(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> v(data, data + size);
  std::size_t pos = kPreamble;
  while (pos + kChunkHeader <= v.size()) {
    const std::uint64_t available = v.size() - pos - kChunkHeader;
    const std::size_t payload =
        static_cast<std::size_t>(std::min<std::uint64_t>(LoadLe64(&v[pos + 8]), available));
    StoreLe32(&v[pos + 16], brdf::Crc32(v.data() + pos + kChunkHeader, payload));
    StoreLe32(&v[pos + 20], brdf::Crc32(v.data() + pos, 20));
    pos += kChunkHeader + payload;
  }
  return v;
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool SameSlices(const brdf::Measurement& a, const brdf::Measurement& b) {
  if (a.slices.size() != b.slices.size()) return false;
  for (std::size_t i = 0; i < a.slices.size(); ++i) {
    const brdf::Slice &s = a.slices[i], &t = b.slices[i];
    if (!SameBits(s.theta_in_deg, t.theta_in_deg) || !SameBits(s.phi_in_deg, t.phi_in_deg) ||
        s.has_sigma != t.has_sigma || s.complete != t.complete ||
        s.samples.size() != t.samples.size())
      return false;
    for (std::size_t k = 0; k < s.samples.size(); ++k) {
      const brdf::Sample &x = s.samples[k], &y = t.samples[k];
      bool same = SameBits(x.theta_in_deg, y.theta_in_deg) &&
                  SameBits(x.phi_in_deg, y.phi_in_deg) &&
                  SameBits(x.theta_out_deg, y.theta_out_deg) &&
                  SameBits(x.phi_out_deg, y.phi_out_deg) && x.flags == y.flags;
      for (int c = 0; c < 3; ++c)
        same = same && SameBits(x.rgb[c], y.rgb[c]) && SameBits(x.sigma[c], y.sigma[c]);
      if (!same) return false;
    }
  }
  return true;
}

bool SameMetadata(const brdf::Metadata& a, const brdf::Metadata& b) {
  return a.sample_name == b.sample_name && a.instrument_model == b.instrument_model &&
         a.instrument_serial == b.instrument_serial && a.firmware_version == b.firmware_version &&
         a.protocol_version == b.protocol_version &&
         a.calibration_reference == b.calibration_reference &&
         a.calibration_time == b.calibration_time && a.capture_start == b.capture_start &&
         a.capture_end == b.capture_end && a.operator_notes == b.operator_notes &&
         a.units == b.units && a.software_version == b.software_version && a.extra == b.extra;
}

void Check(const std::uint8_t* data, std::size_t size) {
  brdf::BpcReadResult r;
  try {
    r = brdf::ParseBpc(data, size, "fuzz.bpc");
  } catch (const brdf::FormatError&) {
    return;  // the header itself is unreadable: the expected outcome for most inputs
  }
  if (r.valid_bytes > size) __builtin_trap();
  if (r.slice_indices.size() != r.measurement.slices.size()) __builtin_trap();
  for (const brdf::BpcProblem& p : r.problems)
    if (p.offset + p.size > size || p.message.empty()) __builtin_trap();
  // Whatever was read is a measurement the writer stores losslessly.
  const std::string bytes = brdf::EncodeBpc(r.measurement);
  const brdf::BpcReadResult again = brdf::ParseBpc(
      reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "rewritten.bpc");
  if (!again.finished || !again.problems.empty()) __builtin_trap();
  if (!SameSlices(r.measurement, again.measurement)) __builtin_trap();
  if (!SameMetadata(r.measurement.metadata, again.measurement.metadata)) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Check(data, size);
  const std::vector<std::uint8_t> repaired = WithRepairedCrcs(data, size);
  Check(repaired.data(), repaired.size());
  return 0;
}
