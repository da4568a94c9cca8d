// Where a damaged Radiance HDR or OpenEXR file goes wrong (image_io_pvt.h), found by walking the
// file's published layout: the decoders (OpenImageIO's, OpenEXR's) say that a file is damaged
// but not in terms a user can check against the file. Run only after a decoder refused a file.
//
// Radiance HDR (RGBE; Ward, "Real Pixels", Graphics Gems II, and the Radiance file format notes):
// a text header of lines, the first "#?RADIANCE" (or another "#?" program name), then
// "NAME=value" lines, a blank line, the resolution line "-Y HEIGHT +X WIDTH" (or its variants),
// then HEIGHT scanlines. A scanline of 8 to 32767 pixels that starts with the bytes 2, 2,
// WIDTH >> 8, WIDTH & 255 is run-length encoded: the four components (R, G, B, E) one after the
// other, each as runs: a count byte above 128 repeats the next byte (count − 128) times, a
// count of 1 to 128 is followed by that many literal bytes. Any other scanline is flat,
// 4 bytes a pixel, and so is the rest of the image after it (the readers' rule).
//
// OpenEXR (the "OpenEXR File Layout" document): magic 76 2f 31 01, a 4-byte version, header
// attributes (name, NUL, type, NUL, 4-byte little-endian size, value) ended by a NUL byte, a
// table of 8-byte offsets, one per block of scanlines, then the blocks: 4-byte first scanline,
// 4-byte data size, data.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "brdf/image_io/image_io.h"
#include "image_io_pvt.h"

namespace brdf::image_io::detail {
namespace {

// Sequential reading with the byte offset and the file size known.
class Bytes {
 public:
  explicit Bytes(const std::string& path) : in_(path, std::ios::binary) {
    in_.seekg(0, std::ios::end);
    size_ = in_ ? static_cast<std::uint64_t>(in_.tellg()) : 0;
    in_.seekg(0);
  }
  bool ok() const { return static_cast<bool>(in_); }
  std::uint64_t size() const { return size_; }
  std::uint64_t offset() const { return offset_; }
  int Get() {
    const int c = in_.get();
    if (c == std::char_traits<char>::eof()) return -1;
    ++offset_;
    return c;
  }
  bool Read(void* out, std::size_t n) {
    if (size_ - offset_ < n) return false;
    in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    offset_ += n;
    return static_cast<bool>(in_);
  }
  void Seek(std::uint64_t offset) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    offset_ = offset;
  }

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0, offset_ = 0;
};

std::string EndOfFile(const Bytes& b) {
  return "the end of the file at byte " + std::to_string(b.size());
}

// Printable text of a header line for a message: at most 40 characters, others as '?'.
std::string Shown(const std::string& text) {
  std::string out;
  for (char c : text.substr(0, 40))
    out += (static_cast<unsigned char>(c) >= 32 && static_cast<unsigned char>(c) < 127) ? c : '?';
  if (text.size() > 40) out += "...";
  return "'" + out + "'";
}

std::string Hex(const unsigned char* bytes, int n) {
  std::string out;
  char buf[4];
  for (int k = 0; k < n; ++k) {
    std::snprintf(buf, sizeof buf, "%s%02x", k ? " " : "", bytes[k]);
    out += buf;
  }
  return out;
}

// "-Y 512 +X 1024" and its variants: the height (first number) and width (second) in file
// order, whatever the axes' signs and order.
bool ParseResolution(const std::string& line, std::uint64_t* rows, std::uint64_t* columns) {
  char s1 = 0, a1 = 0, s2 = 0, a2 = 0;
  long n1 = 0, n2 = 0;
  char tail = 0;
  if (std::sscanf(line.c_str(), "%c%c %ld %c%c %ld %c", &s1, &a1, &n1, &s2, &a2, &n2, &tail) != 6)
    return false;
  const bool signs = (s1 == '+' || s1 == '-') && (s2 == '+' || s2 == '-');
  const bool axes = (a1 == 'Y' && a2 == 'X') || (a1 == 'X' && a2 == 'Y');
  if (!signs || !axes || n1 < 1 || n2 < 1) return false;
  *rows = static_cast<std::uint64_t>(n1);
  *columns = static_cast<std::uint64_t>(n2);
  return true;
}

const char* const kComponent[4] = {"red", "green", "blue", "exponent"};

}  // namespace

std::optional<Damage> LocateRadianceDamage(const std::string& path) {
  Bytes b(path);
  if (!b.ok()) return std::nullopt;
  // The header, line by line.
  std::string line;
  std::uint64_t line_number = 0, line_start = 0;
  std::uint64_t rows = 0, columns = 0;
  bool blank_seen = false, format_seen = false;
  for (;;) {
    line.clear();
    line_start = b.offset();
    ++line_number;
    int c;
    while ((c = b.Get()) >= 0 && c != '\n') {
      line += static_cast<char>(c);
      if (line.size() > 4096)
        return Damage{"line " + std::to_string(line_number) + " of the header (byte " +
                          std::to_string(line_start) + ")",
                      "a header line of at most 4096 characters",
                      "a line that goes on past byte " + std::to_string(b.offset())};
    }
    if (line_number == 1 && line.rfind("#?", 0) != 0)
      return Damage{"byte 0", "a Radiance HDR file starting with '#?' (e.g. '#?RADIANCE')",
                    line.empty() && c < 0 ? "an empty file" : Shown(line)};
    if (c < 0)
      return Damage{"line " + std::to_string(line_number) + " of the header (byte " +
                        std::to_string(line_start) + ")",
                    blank_seen ? "the image size line ('-Y HEIGHT +X WIDTH')"
                               : "the end of the header (a blank line, then the image size)",
                    EndOfFile(b)};
    if (blank_seen) {
      if (!ParseResolution(line, &rows, &columns))
        return Damage{"line " + std::to_string(line_number) + " of the header (byte " +
                          std::to_string(line_start) + ")",
                      "the image size as '-Y HEIGHT +X WIDTH' with positive numbers", Shown(line)};
      break;
    }
    if (line.rfind("FORMAT=", 0) == 0) {
      if (line != "FORMAT=32-bit_rle_rgbe")
        return Damage{"line " + std::to_string(line_number) + " of the header (byte " +
                          std::to_string(line_start) + ")",
                      "FORMAT=32-bit_rle_rgbe (RGB radiance)", Shown(line)};
      format_seen = true;
    }
    if (line.empty()) {
      // The readers require the FORMAT line (the format notes make it the one required one).
      if (!format_seen)
        return Damage{"line " + std::to_string(line_number) + " of the header (byte " +
                          std::to_string(line_start) + ", the blank line that ends it)",
                      "a line FORMAT=32-bit_rle_rgbe before it", "no FORMAT line"};
      blank_seen = true;
    }
  }
  if (rows * columns > kMaxReadPixels || rows > kMaxReadPixels || columns > kMaxReadPixels)
    return std::nullopt;  // the reader's size limit says this already
  // The scanlines, in file order.
  const std::uint64_t w = columns;
  auto where = [&](std::uint64_t row, std::uint64_t byte) {
    return "scanline " + std::to_string(row + 1) + " of " + std::to_string(rows) + " (byte " +
           std::to_string(byte) + ")";
  };
  for (std::uint64_t row = 0; row < rows; ++row) {
    const std::uint64_t start = b.offset();
    unsigned char head[4] = {0, 0, 0, 0};
    const bool rle_width = w >= 8 && w <= 0x7fff;
    if (rle_width && !b.Read(head, 4))
      return Damage{where(row, start), "the 4 bytes that start a scanline", EndOfFile(b)};
    if (!rle_width || head[0] != 2 || head[1] != 2 || (head[2] & 0x80) != 0) {
      // Flat: this and every later scanline, 4 bytes a pixel; such bytes can only be too few.
      const std::uint64_t need = 4 * w * (rows - row), left = b.size() - start;
      if (left >= need) return std::nullopt;
      const std::uint64_t whole = left / (4 * w);
      return Damage{where(row + whole, start + whole * 4 * w),
                    std::to_string(need) + " bytes of pixels (4 a pixel) for the last " +
                        std::to_string(rows - row) + " scanlines, up to byte " +
                        std::to_string(start + need),
                    EndOfFile(b)};
    }
    const std::uint64_t encoded = (static_cast<std::uint64_t>(head[2]) << 8) | head[3];
    const unsigned char expected[4] = {2, 2, static_cast<unsigned char>(w >> 8),
                                       static_cast<unsigned char>(w & 255)};
    if (encoded != w)
      return Damage{where(row, start),
                    "a run-length scanline of " + std::to_string(w) + " pixels (bytes " +
                        Hex(expected, 4) + ")",
                    "one of " + std::to_string(encoded) + " pixels (bytes " + Hex(head, 4) + ")"};
    for (int component = 0; component < 4; ++component) {
      std::uint64_t filled = 0;
      while (filled < w) {
        const std::uint64_t at = b.offset();
        const int count = b.Get();
        if (count < 0)
          return Damage{where(row, start),
                        "the " + std::string(kComponent[component]) + " values of pixels " +
                            std::to_string(filled + 1) + " to " + std::to_string(w),
                        EndOfFile(b)};
        const bool run = count > 128;
        const std::uint64_t n = run ? static_cast<std::uint64_t>(count - 128) : count;
        if (n == 0 || n > w - filled)
          return Damage{
              where(row, start) + ", run at byte " + std::to_string(at),
              "a run of 1 to " + std::to_string(w - filled) + " " + kComponent[component] +
                  " values (the rest of the " + std::to_string(w) + " pixels)",
              "a run of " + std::to_string(n) + " (count byte " + std::to_string(count) + ")"};
        for (std::uint64_t k = 0; k < (run ? 1 : n); ++k)
          if (b.Get() < 0)
            return Damage{where(row, start) + ", run at byte " + std::to_string(at),
                          std::to_string(run ? 1 : n) + " " + kComponent[component] +
                              (run || n == 1 ? " value" : " values"),
                          EndOfFile(b)};
        filled += n;
      }
    }
  }
  return std::nullopt;
}

namespace {

std::uint32_t Le32(const unsigned char* p) {
  return p[0] | (p[1] << 8) | (p[2] << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::uint64_t Le64(const unsigned char* p) {
  return Le32(p) | (static_cast<std::uint64_t>(Le32(p + 4)) << 32);
}

// Scanlines per block of each OpenEXR compression (the file layout document's table).
int LinesPerBlock(int compression) {
  switch (compression) {
    case 0:  // none
    case 1:  // RLE
    case 2:  // ZIPS
      return 1;
    case 3:  // ZIP
    case 5:  // PXR24
      return 16;
    case 4:  // PIZ
    case 6:  // B44
    case 7:  // B44A
    case 8:  // DWAA
      return 32;
    case 9:  // DWAB
      return 256;
    default:
      return 0;
  }
}

// The attributes every OpenEXR header has, with their types and value sizes (0: variable).
struct RequiredAttribute {
  const char* name;
  const char* type;
  std::uint32_t size;
};
constexpr RequiredAttribute kRequired[] = {
    {"channels", "chlist", 0},        {"compression", "compression", 1},
    {"dataWindow", "box2i", 16},      {"displayWindow", "box2i", 16},
    {"lineOrder", "lineOrder", 1},    {"pixelAspectRatio", "float", 4},
    {"screenWindowCenter", "v2f", 8}, {"screenWindowWidth", "float", 4},
};

// Reads a NUL-terminated name; false at the end of the file or past 255 characters.
bool ReadName(Bytes& b, std::string* name) {
  name->clear();
  for (int c; (c = b.Get()) != 0;) {
    if (c < 0 || name->size() >= 255) return false;
    *name += static_cast<char>(c);
  }
  return true;
}

}  // namespace

std::string ExrBlockPosition(const ExrLayout& layout, std::uint64_t block) {
  const std::uint64_t first = block * layout.lines_per_block;
  const std::uint64_t last = std::min<std::uint64_t>(first + layout.lines_per_block, layout.rows);
  std::string where =
      "pixel block " + std::to_string(block + 1) + " of " + std::to_string(layout.blocks) + " (";
  where += last - first == 1
               ? "scanline " + std::to_string(first + 1)
               : "scanlines " + std::to_string(first + 1) + "–" + std::to_string(last);
  where += " of " + std::to_string(layout.rows);
  if (block < layout.block_offsets.size())
    where += ", byte " + std::to_string(layout.block_offsets[block]);
  return where + ")";
}

std::optional<Damage> LocateExrDamage(const std::string& path, ExrLayout* layout) {
  Bytes b(path);
  if (!b.ok()) return std::nullopt;
  unsigned char head[8];
  if (!b.Read(head, 8))
    return Damage{"byte 0", "the 8-byte OpenEXR signature (76 2f 31 01 and the version)",
                  "a file of " + std::to_string(b.size()) + (b.size() == 1 ? " byte" : " bytes")};
  static const unsigned char kMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  if (!std::equal(head, head + 4, kMagic))
    return Damage{"byte 0", "the OpenEXR magic number 76 2f 31 01", "bytes " + Hex(head, 4)};
  const std::uint32_t flags = Le32(head + 4) >> 8;
  if ((flags & (0x02 | 0x08 | 0x10)) != 0) return std::nullopt;  // tiled, deep or multi-part
  bool have_window = false;
  std::set<std::string> seen;
  int compression = -1;
  std::int32_t y_min = 0, y_max = -1;
  for (;;) {
    const std::uint64_t at = b.offset();
    std::string name, type;
    if (!ReadName(b, &name))
      return Damage{"header attribute at byte " + std::to_string(at),
                    "an attribute name ended by a zero byte (at most 255 characters)",
                    b.offset() >= b.size() ? EndOfFile(b) : "a longer name"};
    if (name.empty()) break;  // the end of the header
    unsigned char size_bytes[4];
    if (!ReadName(b, &type) || !b.Read(size_bytes, 4))
      return Damage{"header attribute '" + name + "' at byte " + std::to_string(at),
                    "its type name and 4-byte size", EndOfFile(b)};
    const std::uint32_t size = Le32(size_bytes);
    if (size > b.size() - b.offset())
      return Damage{"header attribute '" + name + "' at byte " + std::to_string(at),
                    "a value size of at most the " + std::to_string(b.size() - b.offset()) +
                        " bytes left in the file",
                    std::to_string(size) + " bytes"};
    // Only the small values this walk reads are loaded; the others are skipped.
    std::vector<unsigned char> value(std::min<std::uint32_t>(size, 16));
    b.Read(value.data(), value.size());
    b.Seek(b.offset() + (size - value.size()));
    for (const RequiredAttribute& r : kRequired)
      if (name == r.name) {
        if (type != r.type)
          return Damage{"header attribute '" + name + "' at byte " + std::to_string(at),
                        "the type '" + std::string(r.type) + "'", "'" + type + "'"};
        if (r.size > 0 && size != r.size)
          return Damage{"header attribute '" + name + "' at byte " + std::to_string(at),
                        "a value of " + std::to_string(r.size) + " bytes",
                        std::to_string(size) + " bytes"};
        seen.insert(name);
      }
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      have_window = true;
      y_min = static_cast<std::int32_t>(Le32(&value[4]));
      y_max = static_cast<std::int32_t>(Le32(&value[12]));
    } else if (name == "compression" && type == "compression" && size == 1) {
      compression = value[0];
    }
  }
  const std::uint64_t header_end = b.offset();
  for (const RequiredAttribute& r : kRequired)
    if (seen.count(r.name) == 0)
      return Damage{"the header (ending at byte " + std::to_string(header_end - 1) + ")",
                    "the required attribute '" + std::string(r.name) + "' of type '" + r.type + "'",
                    "no such attribute"};
  if (!have_window || compression < 0 || y_max < y_min) return std::nullopt;  // OpenEXR says it
  const int lines = LinesPerBlock(compression);
  if (lines == 0) return std::nullopt;
  ExrLayout found;
  found.rows = static_cast<std::uint64_t>(static_cast<std::int64_t>(y_max) - y_min + 1);
  found.lines_per_block = static_cast<std::uint64_t>(lines);
  found.blocks = (found.rows + found.lines_per_block - 1) / found.lines_per_block;
  const std::uint64_t table_end = header_end + 8 * found.blocks;
  for (std::uint64_t k = 0; k < found.blocks; ++k) {
    unsigned char entry[8];
    const std::uint64_t at = b.offset();
    if (!b.Read(entry, 8))
      return Damage{"entry " + std::to_string(k + 1) + " of the table of " +
                        std::to_string(found.blocks) + " pixel-block offsets (byte " +
                        std::to_string(at) + ")",
                    "an 8-byte offset", EndOfFile(b)};
    found.block_offsets.push_back(Le64(entry));
  }
  for (std::uint64_t k = 0; k < found.blocks; ++k) {
    const std::uint64_t o = found.block_offsets[k];
    if (o < table_end || o >= b.size())
      return Damage{"entry " + std::to_string(k + 1) + " of the table of " +
                        std::to_string(found.blocks) + " pixel-block offsets (byte " +
                        std::to_string(header_end + 8 * k) + ")",
                    "an offset from " + std::to_string(table_end) + " to " +
                        std::to_string(b.size() - 1) + " (inside the file's pixel data)",
                    std::to_string(o)};
    b.Seek(o);
    unsigned char block_head[8];
    if (!b.Read(block_head, 8))
      return Damage{ExrBlockPosition(found, k), "the block's 8-byte start (scanline and size)",
                    EndOfFile(b)};
    const std::int64_t y = static_cast<std::int32_t>(Le32(block_head));
    const std::uint64_t size = Le32(block_head + 4);
    const std::int64_t expected_y = y_min + static_cast<std::int64_t>(k) * lines;
    if (y != expected_y)
      return Damage{ExrBlockPosition(found, k),
                    "the block to start at scanline coordinate " + std::to_string(expected_y),
                    std::to_string(y)};
    if (size == 0 || size > b.size() - b.offset())
      return Damage{ExrBlockPosition(found, k),
                    size == 0 ? std::string("a pixel data size above 0")
                              : std::to_string(size) + " bytes of pixel data, up to byte " +
                                    std::to_string(b.offset() + size),
                    size == 0 ? std::string("0") : EndOfFile(b)};
  }
  if (layout != nullptr) *layout = std::move(found);
  return std::nullopt;
}

}  // namespace brdf::image_io::detail
