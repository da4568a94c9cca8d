// SHA-256 (FIPS 180-4), used to recognise genuine third-party data files by their published
// digests (the MERL `.binary` table in ../shared/brdf-data/reference/). Not for security.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace brdf {

// Incremental hashing: Update() any number of times, then Finish() once.
class Sha256 {
 public:
  Sha256();
  void Update(const void* data, std::size_t size);
  void Update(std::string_view bytes) { Update(bytes.data(), bytes.size()); }
  // The 32-byte digest; the object must not be updated afterwards.
  std::array<std::uint8_t, 32> Finish();

 private:
  void Block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t buffered_ = 0;
  std::uint64_t length_ = 0;  // bytes hashed so far
};

// Lower-case hexadecimal digest of `bytes` (64 characters).
std::string Sha256Hex(std::string_view bytes);
std::string Sha256Hex(const void* data, std::size_t size);
// Lower-case hexadecimal digest of a file's content, read in chunks (any size). IoError if
// it cannot be read.
std::string Sha256HexOfFile(const std::string& path);

}  // namespace brdf
