// Private helpers shared by the KTX2 and DDS containers.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

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

}  // namespace brdf::exporter::detail
