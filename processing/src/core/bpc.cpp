#include "brdf/core/bpc.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"

namespace brdf {

namespace {

using Json = nlohmann::ordered_json;

// docs/formats/bpc.md: preamble, chunk header, slice header and sample record layouts.
constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'B', 'P', 'C', '\r', '\n', 0x1a, '\n'};
constexpr std::size_t kPreambleSize = 12;
constexpr std::size_t kChunkHeaderSize = 24;
constexpr std::size_t kSliceHeaderSize = 32;
constexpr std::uint32_t kRecordSizeNoSigma = 32;
constexpr std::uint32_t kRecordSizeSigma = 44;
constexpr std::uint32_t kNoSlice = 0xffffffffu;
constexpr std::uint32_t kSliceFlagHasSigma = 1u << 0;
constexpr std::uint32_t kSliceFlagIncomplete = 1u << 1;

constexpr char kTagHead[5] = "HEAD";
constexpr char kTagSlice[5] = "SLCE";
constexpr char kTagEnd[5] = "END ";

std::string ErrnoText() { return std::strerror(errno); }

// Printable form of a 4-byte tag for messages ("SLCE", "\x00\x00\x00\x00").
std::string TagText(const std::uint8_t* p) {
  std::string out = "'";
  for (int i = 0; i < 4; ++i) {
    if (p[i] >= 0x20 && p[i] < 0x7f) {
      out.push_back(static_cast<char>(p[i]));
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", p[i]);
      out += buf;
    }
  }
  return out + "'";
}

bool TagIs(const std::uint8_t* p, const char* tag) { return std::memcmp(p, tag, 4) == 0; }

std::uint32_t LoadU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

std::uint64_t LoadU64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(LoadU32(p)) |
         (static_cast<std::uint64_t>(LoadU32(p + 4)) << 32);
}

float LoadF32(const std::uint8_t* p) {
  const std::uint32_t bits = LoadU32(p);
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

Json MetadataToJson(const Metadata& m) {
  Json j;
  j["sample_name"] = m.sample_name;
  j["instrument_model"] = m.instrument_model;
  j["instrument_serial"] = m.instrument_serial;
  j["firmware_version"] = m.firmware_version;
  j["protocol_version"] = m.protocol_version;
  j["calibration_reference"] = m.calibration_reference;
  j["calibration_time"] = m.calibration_time;
  j["capture_start"] = m.capture_start;
  j["capture_end"] = m.capture_end;
  j["operator_notes"] = m.operator_notes;
  j["units"] = m.units;
  j["software_version"] = m.software_version;
  j["extra"] = Json::object();
  for (const auto& [k, v] : m.extra) j["extra"][k] = v;
  return j;
}

// Invalid UTF-8 in a metadata string (an instrument reporting Latin-1) is replaced by U+FFFD
// rather than failing a capture; valid UTF-8 round-trips exactly.
std::string DumpJson(const Json& j) {
  return j.dump(2, ' ', false, Json::error_handler_t::replace);
}

Metadata MetadataFromJson(const Json& j, const std::string& file, std::uint64_t offset,
                          const char* chunk) {
  const std::string position = BytePosition(offset) + " (" + chunk + " JSON, member 'metadata')";
  if (!j.is_object()) throw FormatError(file, position, "a JSON object", j.type_name());
  Metadata m;
  const auto get = [&](const char* key, std::string* out) {
    const auto it = j.find(key);
    if (it == j.end()) return;
    if (!it->is_string())
      throw FormatError(file, position, std::string("a string for '") + key + "'", it->type_name());
    *out = it->get<std::string>();
  };
  get("sample_name", &m.sample_name);
  get("instrument_model", &m.instrument_model);
  get("instrument_serial", &m.instrument_serial);
  get("firmware_version", &m.firmware_version);
  get("protocol_version", &m.protocol_version);
  get("calibration_reference", &m.calibration_reference);
  get("calibration_time", &m.calibration_time);
  get("capture_start", &m.capture_start);
  get("capture_end", &m.capture_end);
  get("operator_notes", &m.operator_notes);
  get("units", &m.units);
  get("software_version", &m.software_version);
  if (const auto it = j.find("extra"); it != j.end()) {
    if (!it->is_object())
      throw FormatError(file, position, "an object for 'extra'", it->type_name());
    for (const auto& [k, v] : it->items()) {
      if (!v.is_string())
        throw FormatError(file, position, "string values in 'extra'",
                          std::string(v.type_name()) + " for '" + k + "'");
      m.extra[k] = v.get<std::string>();
    }
  }
  return m;
}

std::string HeaderJson(const Metadata& metadata) {
  Json j;
  j["format"] = "bpc";
  j["version"] = {kBpcVersionMajor, kBpcVersionMinor};
  j["metadata"] = MetadataToJson(metadata);
  j["units"] = {{"angles", "deg"}, {"f_r", "1/sr"}, {"sigma", "1/sr"}};
  // Self-description of the sample record (normative layout: docs/formats/bpc.md).
  Json layout = Json::array();
  const char* names[] = {
      "theta_in_deg", "phi_in_deg", "theta_out_deg", "phi_out_deg", "r", "g", "b"};
  for (int i = 0; i < 7; ++i)
    layout.push_back({{"name", names[i]}, {"offset", 4 * i}, {"type", "float32"}});
  layout.push_back({{"name", "flags"}, {"offset", 28}, {"type", "uint8"}});
  layout.push_back({{"name", "reserved"}, {"offset", 29}, {"type", "uint8[3]"}});
  layout.push_back({{"name", "sigma_r"}, {"offset", 32}, {"type", "float32"}, {"if", "has_sigma"}});
  layout.push_back({{"name", "sigma_g"}, {"offset", 36}, {"type", "float32"}, {"if", "has_sigma"}});
  layout.push_back({{"name", "sigma_b"}, {"offset", 40}, {"type", "float32"}, {"if", "has_sigma"}});
  j["sample_record"] = layout;
  j["flag_bits"] = {
      {"saturated", 0}, {"below_noise_floor", 1}, {"interpolated", 2}, {"invalid", 3}};
  return DumpJson(j);
}

std::string EndJson(const Metadata& metadata, int slice_count, std::uint64_t sample_count) {
  Json j;
  j["metadata"] = MetadataToJson(metadata);
  j["slice_count"] = slice_count;
  j["sample_count"] = sample_count;
  return DumpJson(j);
}

Json ParseJsonPayload(const std::uint8_t* p, std::size_t n, const std::string& file,
                      std::uint64_t offset, const char* chunk) {
  Json j = Json::parse(p, p + n, nullptr, false);
  if (j.is_discarded() || !j.is_object())
    throw FormatError(file, BytePosition(offset) + " (" + chunk + " chunk payload)",
                      "a UTF-8 JSON object", j.is_discarded() ? "malformed JSON" : j.type_name());
  return j;
}

std::string EncodeChunk(const char* tag, std::uint32_t slice_index, const std::string& payload) {
  std::string out;
  out.reserve(kChunkHeaderSize + payload.size());
  out.append(tag, 4);
  AppendU32(out, slice_index);
  AppendU64(out, payload.size());
  AppendU32(out, Crc32(payload.data(), payload.size()));
  AppendU32(out, Crc32(out.data(), 20));
  out += payload;
  return out;
}

void StoreU32(char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
void StoreU64(char* p, std::uint64_t v) {
  StoreU32(p, static_cast<std::uint32_t>(v));
  StoreU32(p + 4, static_cast<std::uint32_t>(v >> 32));
}
void StoreF32(char* p, float v) { StoreU32(p, std::bit_cast<std::uint32_t>(v)); }

// Built in place in one buffer (a reference slice is 1.2 MB): header fields, then records,
// then the two CRCs.
std::string EncodeSliceChunk(const Slice& slice, int index) {
  const std::uint32_t record_size = slice.has_sigma ? kRecordSizeSigma : kRecordSizeNoSigma;
  const std::size_t payload_size = kSliceHeaderSize + slice.samples.size() * record_size;
  std::string out(kChunkHeaderSize + payload_size, '\0');  // reserved bytes stay 0
  char* p = out.data() + kChunkHeaderSize;
  StoreU64(p, std::bit_cast<std::uint64_t>(slice.theta_in_deg));
  StoreU64(p + 8, std::bit_cast<std::uint64_t>(slice.phi_in_deg));
  StoreU64(p + 16, slice.samples.size());
  StoreU32(p + 24, (slice.has_sigma ? kSliceFlagHasSigma : 0u) |
                       (slice.complete ? 0u : kSliceFlagIncomplete));
  StoreU32(p + 28, record_size);
  char* r = p + kSliceHeaderSize;
  for (const Sample& s : slice.samples) {
    StoreF32(r, s.theta_in_deg);
    StoreF32(r + 4, s.phi_in_deg);
    StoreF32(r + 8, s.theta_out_deg);
    StoreF32(r + 12, s.phi_out_deg);
    for (int c = 0; c < 3; ++c) StoreF32(r + 16 + 4 * c, s.rgb[c]);
    r[28] = static_cast<char>(s.flags);
    if (slice.has_sigma)
      for (int c = 0; c < 3; ++c) StoreF32(r + 32 + 4 * c, s.sigma[c]);
    r += record_size;
  }
  std::memcpy(out.data(), kTagSlice, 4);
  StoreU32(out.data() + 4, static_cast<std::uint32_t>(index));
  StoreU64(out.data() + 8, payload_size);
  StoreU32(out.data() + 16, Crc32(p, payload_size));
  StoreU32(out.data() + 20, Crc32(out.data(), 20));
  return out;
}

std::string EncodePreambleAndHeader(const Metadata& metadata) {
  std::string out(reinterpret_cast<const char*>(kMagic.data()), kMagic.size());
  AppendU16(out, kBpcVersionMajor);
  AppendU16(out, kBpcVersionMinor);
  out += EncodeChunk(kTagHead, kNoSlice, HeaderJson(metadata));
  return out;
}

struct ChunkHeader {
  const std::uint8_t* tag;
  std::uint32_t slice_index;
  std::uint64_t payload_size;
  std::uint32_t payload_crc;
  std::uint32_t header_crc;
};

ChunkHeader DecodeChunkHeader(const std::uint8_t* p) {
  return {p, LoadU32(p + 4), LoadU64(p + 8), LoadU32(p + 16), LoadU32(p + 20)};
}

bool HeaderCrcOk(const std::uint8_t* p) { return Crc32(p, 20) == LoadU32(p + 20); }

// Validates the 32-byte slice header at `p` of a slice payload of `n` bytes (n >= 32) and sizes
// `slice` for its samples. Returns an empty string on success, or what is inconsistent (the
// chunk is then reported as corrupt).
std::string DecodeSliceHeader(const std::uint8_t* p, std::uint64_t n, Slice* slice,
                              std::uint32_t* record_size) {
  std::memcpy(&slice->theta_in_deg, p, 8);
  std::memcpy(&slice->phi_in_deg, p + 8, 8);
  const std::uint64_t count = LoadU64(p + 16);
  const std::uint32_t flags = LoadU32(p + 24);
  *record_size = LoadU32(p + 28);
  slice->has_sigma = (flags & kSliceFlagHasSigma) != 0;
  slice->complete = (flags & kSliceFlagIncomplete) == 0;
  const std::uint32_t min_record = slice->has_sigma ? kRecordSizeSigma : kRecordSizeNoSigma;
  if (*record_size < min_record)
    return "record size " + std::to_string(*record_size) + " (at least " +
           std::to_string(min_record) + " expected)";
  // Bounded by the payload size (itself bounded by the file size) before any allocation.
  const std::uint64_t body = n - kSliceHeaderSize;
  if (count > body / *record_size || count * *record_size != body)
    return "sample count " + std::to_string(count) + " x record size " +
           std::to_string(*record_size) + " != " + std::to_string(body) + " payload bytes";
  slice->samples.resize(static_cast<std::size_t>(count));
  return {};
}

void DecodeRecords(const std::uint8_t* r, std::size_t count, std::uint32_t record_size,
                   bool has_sigma, Sample* out) {
  for (std::size_t i = 0; i < count; ++i, r += record_size) {
    Sample& s = out[i];
    s.theta_in_deg = LoadF32(r);
    s.phi_in_deg = LoadF32(r + 4);
    s.theta_out_deg = LoadF32(r + 8);
    s.phi_out_deg = LoadF32(r + 12);
    for (int c = 0; c < 3; ++c) s.rgb[c] = LoadF32(r + 16 + 4 * c);
    s.flags = r[28];
    if (has_sigma) {
      for (int c = 0; c < 3; ++c) s.sigma[c] = LoadF32(r + 32 + 4 * c);
    } else {
      s.sigma = {0.0f, 0.0f, 0.0f};
    }
  }
}

// Parses one slice payload whose CRC already matched; see DecodeSliceHeader.
std::string DecodeSlicePayload(const std::uint8_t* p, std::uint64_t n, Slice* slice) {
  if (n < kSliceHeaderSize)
    return "payload of " + std::to_string(n) + " bytes, shorter than the 32-byte slice header";
  std::uint32_t record_size = 0;
  std::string why = DecodeSliceHeader(p, n, slice, &record_size);
  if (why.empty())
    DecodeRecords(p + kSliceHeaderSize, slice->samples.size(), record_size, slice->has_sigma,
                  slice->samples.data());
  return why;
}

// The final metadata of an end chunk payload (CRC already matched). Throws FormatError.
// `result` (may be null) receives the end chunk's slice and sample counts, -1 when absent or
// not integers (the reader reports what it finds; brdf::sources checks them against the file).
Metadata DecodeEndPayload(const std::uint8_t* p, std::size_t n, const std::string& file,
                          std::uint64_t offset, BpcReadResult* result = nullptr) {
  const Json j = ParseJsonPayload(p, n, file, offset, "end");
  const auto it = j.find("metadata");
  if (it == j.end()) throw FormatError(file, BytePosition(offset), "a 'metadata' member", "none");
  Metadata m = MetadataFromJson(*it, file, offset, "end chunk");
  if (result) {
    const auto count = [&](const char* key) -> std::int64_t {
      const auto c = j.find(key);
      if (c == j.end() || !c->is_number_unsigned()) return -1;
      return static_cast<std::int64_t>(std::min<std::uint64_t>(
          c->get<std::uint64_t>(),
          static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())));
    };
    result->end_slice_count = count("slice_count");
    result->end_sample_count = count("sample_count");
    result->end_offset = offset - kChunkHeaderSize;
  }
  return m;
}

class BpcParser {
 public:
  BpcParser(std::string file, const std::uint8_t* data, std::size_t size)
      : file_(std::move(file)), data_(data), size_(size) {}

  BpcReadResult Parse() {
    std::size_t pos = ParseHeader();
    result_.valid_bytes = pos;
    bool prefix_intact = true;
    int expected_slice = 0;  // ordinal of the next slice chunk, damaged ones included
    while (pos < size_) {
      const std::size_t remaining = size_ - pos;
      if (remaining < kChunkHeaderSize) {
        AddProblem(BpcProblemKind::kTruncated, pos, remaining, -1, "a 24-byte chunk header",
                   "end of file after " + std::to_string(remaining) + " bytes (file cut at byte " +
                       std::to_string(size_) + ")");
        break;
      }
      const std::uint8_t* p = data_ + pos;
      const ChunkHeader h = DecodeChunkHeader(p);
      if (!HeaderCrcOk(p)) {
        // The header cannot be trusted, so neither can its length: look for the next intact
        // chunk header. A single flipped byte leaves either the tag or the index intact, which
        // is enough to attribute the damage to a slice.
        const int slice =
            (TagIs(p, kTagSlice) || h.slice_index == static_cast<std::uint32_t>(expected_slice))
                ? expected_slice
                : -1;
        const std::size_t next = FindNextChunk(pos + 1);
        const std::uint64_t region = next - pos;
        AddProblem(BpcProblemKind::kCorrupt, pos, region, slice,
                   "chunk header CRC-32 " + Hex32Text(h.header_crc),
                   Hex32Text(Crc32(p, 20)) + " (tag " + TagText(p) + "); " +
                       std::to_string(region) + " bytes skipped" +
                       (next == size_ ? " to the end of the file" : ""));
        if (slice >= 0) ++expected_slice;
        prefix_intact = false;
        pos = next;
        continue;
      }
      const bool is_slice = TagIs(p, kTagSlice);
      const int stored_slice =
          is_slice && h.slice_index <= static_cast<std::uint32_t>(std::numeric_limits<int>::max())
              ? static_cast<int>(h.slice_index)
              : -1;
      if (h.payload_size > remaining - kChunkHeaderSize) {
        AddProblem(BpcProblemKind::kTruncated, pos, remaining, stored_slice,
                   std::to_string(h.payload_size) + " payload bytes for chunk " + TagText(p),
                   std::to_string(remaining - kChunkHeaderSize) + " (file cut at byte " +
                       std::to_string(size_) + ")");
        break;
      }
      const std::uint8_t* payload = p + kChunkHeaderSize;
      const std::size_t n = static_cast<std::size_t>(h.payload_size);
      const std::size_t end = pos + kChunkHeaderSize + n;
      const std::uint32_t crc = Crc32(payload, n);
      if (crc != h.payload_crc) {
        AddProblem(BpcProblemKind::kCorrupt, pos, end - pos, stored_slice,
                   "payload CRC-32 " + Hex32Text(h.payload_crc) + " of chunk " + TagText(p),
                   Hex32Text(crc));
        if (stored_slice >= 0) expected_slice = stored_slice + 1;
        prefix_intact = false;
        pos = end;
        continue;
      }
      bool intact = true;
      if (is_slice) {
        Slice slice;
        const std::string why = stored_slice < 0
                                    ? std::string("slice index ") + std::to_string(h.slice_index)
                                    : DecodeSlicePayload(payload, n, &slice);
        if (why.empty()) {
          result_.measurement.slices.push_back(std::move(slice));
          result_.slice_indices.push_back(stored_slice);
          result_.slice_offsets.push_back(pos);
          expected_slice = stored_slice + 1;
        } else {
          AddProblem(BpcProblemKind::kCorrupt, pos, end - pos, stored_slice,
                     "a consistent slice chunk", why);
          intact = false;
          if (stored_slice >= 0) expected_slice = stored_slice + 1;
        }
      } else if (TagIs(p, kTagEnd)) {
        // A CRC-valid end chunk with unusable JSON was written wrong, not damaged in transit;
        // it is reported like damage so the slices before it stay readable.
        try {
          end_metadata_ = DecodeEndPayload(payload, n, file_, pos + kChunkHeaderSize, &result_);
          result_.finished = true;
        } catch (const FormatError& e) {
          AddProblem(BpcProblemKind::kCorrupt, pos, end - pos, -1, e.expected(), e.got());
          intact = false;
        }
      }
      // Any other tag is a chunk type from a newer minor version: skipped (bpc.md, versioning).
      if (intact && !prefix_intact) result_.intact_data_after_damage = true;
      if (!intact) prefix_intact = false;
      pos = end;
      if (prefix_intact) result_.valid_bytes = pos;
      if (result_.finished) {
        if (pos < size_)
          AddProblem(BpcProblemKind::kTrailingData, pos, size_ - pos, -1,
                     "end of file after the end chunk",
                     std::to_string(size_ - pos) + " more bytes");
        break;
      }
    }
    result_.header_metadata = result_.measurement.metadata;
    if (result_.finished) result_.measurement.metadata = end_metadata_;
    return std::move(result_);
  }

 private:
  [[noreturn]] void FailHeader(std::uint64_t offset, const std::string& expected,
                               const std::string& got) const {
    throw FormatError(file_, BytePosition(offset), expected, got,
                      "the file header is unreadable, so nothing in the file can be trusted");
  }

  std::size_t ParseHeader() {
    if (size_ < kMagic.size() || std::memcmp(data_, kMagic.data(), kMagic.size()) != 0) {
      std::string got;
      for (std::size_t i = 0; i < std::min<std::size_t>(size_, kMagic.size()); ++i) {
        char buf[4];
        std::snprintf(buf, sizeof buf, "%02x", data_[i]);
        got += (i ? " " : "") + std::string(buf);
      }
      FailHeader(0, "the .bpc magic 89 42 50 43 0d 0a 1a 0a",
                 size_ == 0 ? std::string("an empty file") : got);
    }
    if (size_ < kPreambleSize)
      FailHeader(8, "a 2+2-byte format version", "end of file at byte " + std::to_string(size_));
    const unsigned major = data_[8] | (data_[9] << 8);
    const unsigned minor = data_[10] | (data_[11] << 8);
    if (major != kBpcVersionMajor)
      FailHeader(8, "format version " + std::to_string(kBpcVersionMajor) + ".x",
                 "version " + std::to_string(major) + "." + std::to_string(minor));
    std::size_t pos = kPreambleSize;
    if (size_ - pos < kChunkHeaderSize)
      FailHeader(pos, "the 24-byte header chunk header",
                 "end of file at byte " + std::to_string(size_));
    const std::uint8_t* p = data_ + pos;
    if (!TagIs(p, kTagHead)) FailHeader(pos, "chunk tag 'HEAD'", TagText(p));
    if (!HeaderCrcOk(p))
      FailHeader(pos + 20, "header chunk header CRC-32 " + Hex32Text(LoadU32(p + 20)),
                 Hex32Text(Crc32(p, 20)));
    const ChunkHeader h = DecodeChunkHeader(p);
    if (h.payload_size > size_ - pos - kChunkHeaderSize)
      FailHeader(pos + 8, std::to_string(h.payload_size) + " bytes of header JSON",
                 std::to_string(size_ - pos - kChunkHeaderSize) + " bytes before the end of file");
    const std::size_t n = static_cast<std::size_t>(h.payload_size);
    const std::uint8_t* payload = p + kChunkHeaderSize;
    if (const std::uint32_t crc = Crc32(payload, n); crc != h.payload_crc)
      FailHeader(pos + kChunkHeaderSize, "header JSON CRC-32 " + Hex32Text(h.payload_crc),
                 Hex32Text(crc));
    const Json j = ParseJsonPayload(payload, n, file_, pos + kChunkHeaderSize, "header");
    // The preamble's version is outside any CRC; the JSON repeats it, so a damaged version
    // field is caught rather than silently accepted.
    const Json want_version = {major, minor};
    if (const auto v = j.find("version"); v == j.end() || *v != want_version)
      FailHeader(8, "the format version of the header JSON",
                 "preamble version " + std::to_string(major) + "." + std::to_string(minor) +
                     " but header JSON 'version' " + (v == j.end() ? "missing" : v->dump()));
    const auto md = j.find("metadata");
    if (md == j.end())
      throw FormatError(file_, BytePosition(pos + kChunkHeaderSize) + " (header JSON)",
                        "a 'metadata' member", "none");
    result_.measurement.metadata = MetadataFromJson(*md, file_, pos + kChunkHeaderSize, "header");
    return pos + kChunkHeaderSize + n;
  }

  // First offset >= from holding a slice or end chunk header whose header CRC matches; the
  // file size if there is none.
  std::size_t FindNextChunk(std::size_t from) const {
    for (std::size_t q = from; q + kChunkHeaderSize <= size_; ++q) {
      const std::uint8_t* p = data_ + q;
      if ((TagIs(p, kTagSlice) || TagIs(p, kTagEnd)) && HeaderCrcOk(p)) return q;
    }
    return size_;
  }

  void AddProblem(BpcProblemKind kind, std::uint64_t offset, std::uint64_t size, int slice,
                  std::string expected, std::string got) {
    BpcProblem problem;
    problem.kind = kind;
    problem.offset = offset;
    problem.size = size;
    problem.slice_index = slice;
    std::string position = BytePosition(offset);
    if (slice >= 0) position += " (slice " + std::to_string(slice) + ")";
    std::string hint;
    if (kind == BpcProblemKind::kTruncated) hint = "damaged tail of an interrupted capture";
    problem.message = FormatError(file_, position, expected, got, hint).what();
    problem.expected = std::move(expected);
    problem.got = std::move(got);
    result_.problems.push_back(std::move(problem));
  }

  std::string file_;
  const std::uint8_t* data_;
  std::size_t size_;
  BpcReadResult result_;
  Metadata end_metadata_;
};

int SyncFile(std::FILE* f) {
  if (std::fflush(f) != 0) return -1;
  return ::fsync(::fileno(f));
}

void SyncParentDir(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string dir = p.has_parent_path() ? p.parent_path().string() : std::string(".");
  const int fd = ::open(dir.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

// Reads exactly n bytes; false on a short read or an error.
bool ReadExact(int fd, void* dst, std::size_t n) {
  auto* p = static_cast<std::uint8_t*>(dst);
  while (n > 0) {
    const ssize_t got = ::read(fd, p, n);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    p += got;
    n -= static_cast<std::size_t>(got);
  }
  return true;
}

// The common case, an intact file, streamed through a small buffer: the whole file is never
// held in memory, which halves the memory a read touches (page faults dominate a 5 MB read).
// Returns nothing at the first sign of damage (or a file changing under us); the caller then
// reads the whole file with the tolerant parser, which alone decides what is reported.
std::optional<BpcReadResult> ReadIntactStreaming(int fd, std::uint64_t size,
                                                 const std::string& path) {
  if (size < kPreambleSize + kChunkHeaderSize) return std::nullopt;
  std::vector<std::uint8_t> head(kPreambleSize + kChunkHeaderSize);
  if (!ReadExact(fd, head.data(), head.size())) return std::nullopt;
  const std::uint64_t head_json = LoadU64(head.data() + kPreambleSize + 8);
  if (head_json > size - head.size()) return std::nullopt;
  head.resize(head.size() + static_cast<std::size_t>(head_json));
  if (!ReadExact(fd, head.data() + kPreambleSize + kChunkHeaderSize,
                 static_cast<std::size_t>(head_json)))
    return std::nullopt;
  BpcReadResult result;
  try {
    result = ParseBpc(head.data(), head.size(), path);
  } catch (const FormatError&) {
    return std::nullopt;
  }
  if (!result.problems.empty()) return std::nullopt;

  constexpr std::size_t kBlockBytes = 64 * 1024;
  std::vector<std::uint8_t> block(kBlockBytes);
  std::uint64_t pos = head.size();
  while (pos < size) {
    std::uint8_t h[kChunkHeaderSize];
    if (size - pos < kChunkHeaderSize || !ReadExact(fd, h, sizeof h) || !HeaderCrcOk(h))
      return std::nullopt;
    const ChunkHeader ch = DecodeChunkHeader(h);
    const std::uint64_t n = ch.payload_size;
    if (n > size - pos - kChunkHeaderSize) return std::nullopt;
    std::uint32_t crc = 0;
    if (TagIs(h, kTagSlice)) {
      std::uint8_t sh[kSliceHeaderSize];
      Slice slice;
      std::uint32_t record_size = 0;
      if (ch.slice_index > static_cast<std::uint32_t>(std::numeric_limits<int>::max()) ||
          n < kSliceHeaderSize || !ReadExact(fd, sh, sizeof sh) ||
          !DecodeSliceHeader(sh, n, &slice, &record_size).empty())
        return std::nullopt;
      crc = Crc32(sh, sizeof sh);
      const std::size_t per_block = std::max<std::size_t>(1, kBlockBytes / record_size);
      if (block.size() < per_block * record_size) block.resize(per_block * record_size);
      for (std::size_t done = 0; done < slice.samples.size();) {
        const std::size_t count = std::min(per_block, slice.samples.size() - done);
        const std::size_t bytes = count * record_size;
        if (!ReadExact(fd, block.data(), bytes)) return std::nullopt;
        crc = Crc32(block.data(), bytes, crc);
        DecodeRecords(block.data(), count, record_size, slice.has_sigma,
                      slice.samples.data() + done);
        done += count;
      }
      if (crc != ch.payload_crc) return std::nullopt;
      result.measurement.slices.push_back(std::move(slice));
      result.slice_indices.push_back(static_cast<int>(ch.slice_index));
      result.slice_offsets.push_back(pos);
    } else if (TagIs(h, kTagEnd)) {
      std::vector<std::uint8_t> payload(static_cast<std::size_t>(n));
      if (!ReadExact(fd, payload.data(), payload.size()) ||
          Crc32(payload.data(), payload.size()) != ch.payload_crc ||
          pos + kChunkHeaderSize + n != size)
        return std::nullopt;
      try {
        result.header_metadata = result.measurement.metadata;
        result.measurement.metadata =
            DecodeEndPayload(payload.data(), payload.size(), path, pos + kChunkHeaderSize, &result);
      } catch (const FormatError&) {
        return std::nullopt;
      }
      result.finished = true;
    } else {
      for (std::uint64_t left = n; left > 0;) {
        const std::size_t bytes =
            static_cast<std::size_t>(std::min<std::uint64_t>(left, block.size()));
        if (!ReadExact(fd, block.data(), bytes)) return std::nullopt;
        crc = Crc32(block.data(), bytes, crc);
        left -= bytes;
      }
      if (crc != ch.payload_crc) return std::nullopt;
    }
    pos += kChunkHeaderSize + n;
    result.valid_bytes = pos;
  }
  if (!result.finished) result.header_metadata = result.measurement.metadata;
  return result;
}

}  // namespace

BpcReadResult ReadBpc(const std::string& path) {
  // Never blocks on a FIFO or device; refuses anything but a regular file.
  std::uint64_t size = 0;
  const int fd = OpenRegularFile(path, &size);
  std::optional<BpcReadResult> fast;
  if (size <= kBpcMaxFileBytes) fast = ReadIntactStreaming(fd, size, path);
  ::close(fd);
  if (fast) return std::move(*fast);
  // Damaged or unusual: the parser needs random access. Mapped, not read, so a huge file
  // (e.g. a small capture followed by gigabytes of holes) costs only the pages looked at.
  const MappedFile mapped(path, kBpcMaxFileBytes);
  return ParseBpc(mapped.data(), mapped.size(), path);
}

BpcReadResult ParseBpc(const std::uint8_t* data, std::size_t size, const std::string& file) {
  return BpcParser(file, data, size).Parse();
}

Measurement LoadBpc(const std::string& path) {
  BpcReadResult r = ReadBpc(path);
  if (!r.problems.empty()) {
    const BpcProblem& p = r.problems.front();
    std::string position = BytePosition(p.offset);
    if (p.slice_index >= 0) position += " (slice " + std::to_string(p.slice_index) + ")";
    throw FormatError(path, position, p.expected, p.got);
  }
  return std::move(r.measurement);
}

std::string EncodeBpc(const Measurement& measurement) {
  std::string out = EncodePreambleAndHeader(measurement.metadata);
  std::uint64_t samples = 0;
  for (std::size_t i = 0; i < measurement.slices.size(); ++i) {
    out += EncodeSliceChunk(measurement.slices[i], static_cast<int>(i));
    samples += measurement.slices[i].samples.size();
  }
  out += EncodeChunk(
      kTagEnd, kNoSlice,
      EndJson(measurement.metadata, static_cast<int>(measurement.slices.size()), samples));
  return out;
}

void WriteBpc(const std::string& path, const Measurement& measurement) {
  WriteFileAtomically(path, EncodeBpc(measurement));
}

BpcAppender::BpcAppender(std::string path, std::FILE* file, int slice_count)
    : path_(std::move(path)), file_(file), slice_count_(slice_count) {}

BpcAppender::BpcAppender(BpcAppender&& other) noexcept
    : path_(std::move(other.path_)),
      file_(std::exchange(other.file_, nullptr)),
      slice_count_(other.slice_count_),
      sample_count_(other.sample_count_),
      size_(other.size_) {}

BpcAppender& BpcAppender::operator=(BpcAppender&& other) noexcept {
  if (this != &other) {
    Close();
    path_ = std::move(other.path_);
    file_ = std::exchange(other.file_, nullptr);
    slice_count_ = other.slice_count_;
    sample_count_ = other.sample_count_;
    size_ = other.size_;
  }
  return *this;
}

BpcAppender::~BpcAppender() { Close(); }

void BpcAppender::Close() {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
}

BpcAppender BpcAppender::Create(const std::string& path, const Metadata& metadata) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw IoError(path + ": cannot create capture file: " + ErrnoText());
  BpcAppender appender(path, f, 0);
  appender.WriteDurably(EncodePreambleAndHeader(metadata));
  SyncParentDir(path);  // the new directory entry must survive a crash too
  return appender;
}

BpcAppender BpcAppender::Resume(const std::string& path, BpcReadResult* existing) {
  BpcReadResult r = ReadBpc(path);
  if (r.finished)
    throw InvalidArgument(path +
                          ": the capture is already finished (it has its end chunk); "
                          "nothing to resume");
  if (r.intact_data_after_damage)
    throw FormatError(path, BytePosition(r.valid_bytes),
                      "damage only at the tail of an interrupted capture",
                      "intact chunks after a damaged one", "resuming would truncate them",
                      Remedy{RemedyKind::kRepairCapture, path});
  if (::truncate(path.c_str(), static_cast<off_t>(r.valid_bytes)) != 0)
    throw IoError(path + ": cannot truncate to " + std::to_string(r.valid_bytes) +
                  " bytes: " + ErrnoText());
  std::FILE* f = std::fopen(path.c_str(), "r+b");
  if (f == nullptr) throw IoError(path + ": cannot open for appending: " + ErrnoText());
  if (std::fseek(f, 0, SEEK_END) != 0) {
    std::fclose(f);
    throw IoError(path + ": cannot seek to the end: " + ErrnoText());
  }
  int next_index = 0;
  for (int index : r.slice_indices) next_index = std::max(next_index, index + 1);
  BpcAppender appender(path, f, next_index);
  appender.sample_count_ = r.measurement.SampleCount();
  appender.size_ = r.valid_bytes;
  if (SyncFile(f) != 0) throw IoError(path + ": cannot sync after truncation: " + ErrnoText());
  if (existing != nullptr) *existing = std::move(r);
  return appender;
}

void BpcAppender::WriteDurably(const std::string& bytes) {
  if (file_ == nullptr) throw Error(path_ + ": capture file already finished or closed");
  // Raw writes on the descriptor (no stdio buffer that could hold half a chunk after a failure).
  const int fd = ::fileno(file_);
  std::size_t done = 0;
  bool ok = true;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ok = false;
      break;
    }
    done += static_cast<std::size_t>(n);
  }
  ok = ok && ::fsync(fd) == 0;
  if (!ok) {
    const std::string why = ErrnoText();
    // Cut the partial chunk off again (disk full, quota, file size limit), so the file stays a
    // valid prefix and a retry appends cleanly after the last complete chunk.
    const bool restored = ::ftruncate(fd, static_cast<off_t>(size_)) == 0 &&
                          ::lseek(fd, static_cast<off_t>(size_), SEEK_SET) >= 0;
    throw IoError(path_ + ": write failed: " + why +
                  (restored ? " (the file is left at its last complete chunk)" : ""));
  }
  size_ += bytes.size();
}

void BpcAppender::AppendSlice(const Slice& slice) {
  WriteDurably(EncodeSliceChunk(slice, slice_count_));
  ++slice_count_;
  sample_count_ += slice.samples.size();
}

void BpcAppender::Finish(const Metadata& final_metadata) {
  WriteDurably(
      EncodeChunk(kTagEnd, kNoSlice, EndJson(final_metadata, slice_count_, sample_count_)));
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw IoError(path_ + ": close failed: " + ErrnoText());
}

std::string MetadataToJsonText(const Metadata& metadata) { return MetadataToJson(metadata).dump(); }

}  // namespace brdf
