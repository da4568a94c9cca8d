// Details shared by the image_io sources (not part of the public header).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace brdf::image_io::detail {

// Throws IoError unless `path` names an existing regular file, so a FIFO or a device never
// blocks a reader and a folder gets a clear message.
void RequireReadableRegularFile(const std::string& path);

// Where a file a decoder refused is damaged, in the file's own terms (damage.cpp): what
// FormatError's position, expected and got say.
struct Damage {
  std::string position, expected, got;
};

// Walks a Radiance HDR file's header and scanlines; nullopt when they are complete and
// well-formed (the damage, if any, is then in pixel values, which RGBE cannot detect).
std::optional<Damage> LocateRadianceDamage(const std::string& path);

// A single-part scanline OpenEXR file's blocks of scanlines, as its header and offset table
// describe them (rows counted in the data window, block k covering rows k·lines_per_block on).
struct ExrLayout {
  std::uint64_t rows = 0, lines_per_block = 0, blocks = 0;
  std::vector<std::uint64_t> block_offsets;  // byte of each block in the file
};
// Walks the header, the offset table and each block's start and size; nullopt when they are
// consistent with the file (then `layout`, if given, describes the blocks, so that a block whose
// data does not decode can be named) and for tiled, deep and multi-part files (not walked).
std::optional<Damage> LocateExrDamage(const std::string& path, ExrLayout* layout);
// "pixel block 3 of 4 (scanlines 33–48 of 64, byte 1234)".
std::string ExrBlockPosition(const ExrLayout& layout, std::uint64_t block);

}  // namespace brdf::image_io::detail
