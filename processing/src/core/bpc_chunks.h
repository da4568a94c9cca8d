// The `.bpc` chunk codec (docs/formats/bpc.md), private to brdf_core: the layout constants,
// little-endian fields, the metadata JSON and the encoding and decoding of chunk payloads.
// bpc_read.cpp and bpc_write.cpp hold the file logic around it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/file_util.h"
#include "brdf/core/measurement.h"

namespace brdf::detail {

using Json = nlohmann::ordered_json;

// docs/formats/bpc.md: preamble, chunk header, slice header and sample record layouts (the
// signature is brdf::kBpcMagic in bpc.h, owned by the format's public header).
inline constexpr std::size_t kPreambleSize = 12;
inline constexpr std::size_t kChunkHeaderSize = 24;
inline constexpr std::size_t kSliceHeaderSize = 32;
inline constexpr std::uint32_t kRecordSizeNoSigma = 32;
inline constexpr std::uint32_t kRecordSizeSigma = 44;
inline constexpr std::uint32_t kNoSlice = 0xffffffffu;
inline constexpr std::uint32_t kSliceFlagHasSigma = 1u << 0;
inline constexpr std::uint32_t kSliceFlagIncomplete = 1u << 1;

inline constexpr char kTagHead[5] = "HEAD";
inline constexpr char kTagSlice[5] = "SLCE";
inline constexpr char kTagEnd[5] = "END ";

// Printable form of a 4-byte tag for messages ("SLCE", "\x00\x00\x00\x00").
std::string TagText(const std::uint8_t* p);

inline bool TagIs(const std::uint8_t* p, const char* tag) { return std::memcmp(p, tag, 4) == 0; }

inline std::uint32_t LoadU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

inline std::uint64_t LoadU64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(LoadU32(p)) |
         (static_cast<std::uint64_t>(LoadU32(p + 4)) << 32);
}

inline float LoadF32(const std::uint8_t* p) {
  const std::uint32_t bits = LoadU32(p);
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

Json MetadataToJson(const Metadata& m);

// Invalid UTF-8 in a metadata string (an instrument reporting Latin-1) is replaced by U+FFFD
// rather than failing a capture; valid UTF-8 round-trips exactly.
std::string DumpJson(const Json& j);

Metadata MetadataFromJson(const Json& j, const std::string& file, std::uint64_t offset,
                          const char* chunk);

std::string HeaderJson(const Metadata& metadata);

std::string EndJson(const Metadata& metadata, int slice_count, std::uint64_t sample_count);

Json ParseJsonPayload(const std::uint8_t* p, std::size_t n, const std::string& file,
                      std::uint64_t offset, const char* chunk);

std::string EncodeChunk(const char* tag, std::uint32_t slice_index, const std::string& payload);

// Built in place in one buffer (a reference slice is 1.2 MB): header fields, then records,
// then the two CRCs.
std::string EncodeSliceChunk(const Slice& slice, int index);

std::string EncodePreambleAndHeader(const Metadata& metadata);

struct ChunkHeader {
  const std::uint8_t* tag;
  std::uint32_t slice_index;
  std::uint64_t payload_size;
  std::uint32_t payload_crc;
  std::uint32_t header_crc;
};

inline ChunkHeader DecodeChunkHeader(const std::uint8_t* p) {
  return {p, LoadU32(p + 4), LoadU64(p + 8), LoadU32(p + 16), LoadU32(p + 20)};
}

inline bool HeaderCrcOk(const std::uint8_t* p) { return Crc32(p, 20) == LoadU32(p + 20); }

// Validates the 32-byte slice header at `p` of a slice payload of `n` bytes (n >= 32) and sizes
// `slice` for its samples. Returns an empty string on success, or what is inconsistent (the
// chunk is then reported as corrupt).
std::string DecodeSliceHeader(const std::uint8_t* p, std::uint64_t n, Slice* slice,
                              std::uint32_t* record_size);

void DecodeRecords(const std::uint8_t* r, std::size_t count, std::uint32_t record_size,
                   bool has_sigma, Sample* out);

// Parses one slice payload whose CRC already matched; see DecodeSliceHeader.
std::string DecodeSlicePayload(const std::uint8_t* p, std::uint64_t n, Slice* slice);

// The final metadata of an end chunk payload (CRC already matched). Throws FormatError.
// `result` (may be null) receives the end chunk's slice and sample counts, -1 when absent or
// not integers (the reader reports what it finds; brdf::sources checks them against the file).
Metadata DecodeEndPayload(const std::uint8_t* p, std::size_t n, const std::string& file,
                          std::uint64_t offset, BpcReadResult* result = nullptr);

}  // namespace brdf::detail
