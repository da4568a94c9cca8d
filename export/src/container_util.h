// Private helpers shared by the KTX2 and DDS containers.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"

namespace brdf::exporter::detail {

// Copies words.size() little-endian 32-bit words from `src` (bounds checked by the caller).
inline void CopyLittleEndianWords(const std::uint8_t* src, std::vector<std::uint32_t>& words) {
  if constexpr (std::endian::native == std::endian::little) {
    if (!words.empty()) std::memcpy(words.data(), src, words.size() * 4);
  } else {
    for (std::size_t i = 0; i < words.size(); ++i, src += 4)
      words[i] = static_cast<std::uint32_t>(src[0]) | (static_cast<std::uint32_t>(src[1]) << 8) |
                 (static_cast<std::uint32_t>(src[2]) << 16) |
                 (static_cast<std::uint32_t>(src[3]) << 24);
  }
}

// Reads one u32 texture dimension and checks it is in 1..65536 (both containers' limit here),
// naming the header field and its byte offset when it is not.
inline int ReadDimension(ByteReader& r, const std::string& file, const char* what) {
  const std::uint64_t at = r.offset();
  const std::uint32_t v = r.U32(what);
  if (v == 0 || v > (1u << 16))
    throw FormatError(file, BytePosition(at), std::string(what) + " in 1..65536",
                      std::to_string(v));
  return static_cast<int>(v);
}

}  // namespace brdf::exporter::detail
