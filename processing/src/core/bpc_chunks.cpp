// The `.bpc` chunk codec (bpc_chunks.h).
#include "bpc_chunks.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <limits>

#include "brdf/core/error.h"

namespace brdf::detail {

namespace {

void StoreU32(char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
void StoreU64(char* p, std::uint64_t v) {
  StoreU32(p, static_cast<std::uint32_t>(v));
  StoreU32(p + 4, static_cast<std::uint32_t>(v >> 32));
}
void StoreF32(char* p, float v) { StoreU32(p, std::bit_cast<std::uint32_t>(v)); }

}  // namespace

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
  std::string out(reinterpret_cast<const char*>(kBpcMagic.data()), kBpcMagic.size());
  AppendU16(out, kBpcVersionMajor);
  AppendU16(out, kBpcVersionMinor);
  out += EncodeChunk(kTagHead, kNoSlice, HeaderJson(metadata));
  return out;
}

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

Metadata DecodeEndPayload(const std::uint8_t* p, std::size_t n, const std::string& file,
                          std::uint64_t offset, BpcReadResult* result) {
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

}  // namespace brdf::detail
