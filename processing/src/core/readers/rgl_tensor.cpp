// Tensor file ("tensor_file\0") parsing and writing: see brdf/core/rgl.h and the format notes
// in ../shared/brdf-data/README.md.
#include <bit>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/rgl.h"
#include "readers/rgl_internal.h"
#include "readers/text_util.h"

namespace brdf {
namespace {

// Smallest field header: name length, empty name, rank, dtype, offset.
constexpr std::uint64_t kMinFieldHeaderBytes = 2 + 2 + 1 + 8;

std::string Quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

}  // namespace

std::string TensorDtypeName(TensorDtype dtype) {
  switch (dtype) {
    case TensorDtype::kUInt8:
      return "uint8";
    case TensorDtype::kInt8:
      return "int8";
    case TensorDtype::kUInt16:
      return "uint16";
    case TensorDtype::kInt16:
      return "int16";
    case TensorDtype::kUInt32:
      return "uint32";
    case TensorDtype::kInt32:
      return "int32";
    case TensorDtype::kUInt64:
      return "uint64";
    case TensorDtype::kInt64:
      return "int64";
    case TensorDtype::kFloat16:
      return "float16";
    case TensorDtype::kFloat32:
      return "float32";
    case TensorDtype::kFloat64:
      return "float64";
  }
  return "dtype " + std::to_string(static_cast<int>(dtype));
}

std::size_t TensorDtypeSize(TensorDtype dtype) {
  switch (dtype) {
    case TensorDtype::kUInt8:
    case TensorDtype::kInt8:
      return 1;
    case TensorDtype::kUInt16:
    case TensorDtype::kInt16:
    case TensorDtype::kFloat16:
      return 2;
    case TensorDtype::kUInt32:
    case TensorDtype::kInt32:
    case TensorDtype::kFloat32:
      return 4;
    case TensorDtype::kUInt64:
    case TensorDtype::kInt64:
    case TensorDtype::kFloat64:
      return 8;
  }
  return 0;
}

std::uint64_t TensorField::element_count() const {
  std::uint64_t n = 1;
  for (const std::uint64_t d : shape) n *= d;  // bounded by the file size at parse time
  return n;
}

std::string TensorField::ShapeString() const {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(shape[i]);
  }
  return s + "]";
}

TensorFile TensorFile::Parse(std::vector<std::uint8_t> bytes, std::string file) {
  TensorFile out;
  out.file_ = std::move(file);
  out.bytes_ = std::move(bytes);
  const std::uint64_t file_size = out.bytes_.size();
  ByteReader r(out.bytes_.data(), out.bytes_.size(), out.file_);

  if (file_size < sizeof kTensorFileMagic ||
      std::memcmp(out.bytes_.data(), kTensorFileMagic, sizeof kTensorFileMagic) != 0) {
    std::string got;
    for (std::size_t i = 0; i < std::min<std::size_t>(file_size, sizeof kTensorFileMagic); ++i) {
      const unsigned char c = out.bytes_[i];
      got += (c >= 0x20 && c < 0x7f) ? std::string(1, static_cast<char>(c))
                                     : "\\x" + std::string(1, "0123456789abcdef"[c >> 4]) +
                                           std::string(1, "0123456789abcdef"[c & 15]);
    }
    throw FormatError(
        out.file_, BytePosition(0), "the tensor file magic \"tensor_file\\0\"",
        "\"" + got + "\"" + (file_size < sizeof kTensorFileMagic ? " (file too short)" : ""),
        "RGL .bsdf files start with this signature");
  }
  r.Skip(sizeof kTensorFileMagic);
  const std::uint64_t version_at = r.offset();
  const std::uint8_t major = r.U8("the version");
  const std::uint8_t minor = r.U8("the version");
  if (major != 1 || minor != 0)
    throw FormatError(out.file_, BytePosition(version_at), "tensor file version 1.0",
                      "version " + std::to_string(major) + "." + std::to_string(minor));
  const std::uint64_t count_at = r.offset();
  const std::uint32_t count = r.U32("the field count");
  if (count > r.remaining() / kMinFieldHeaderBytes)
    throw FormatError(out.file_, BytePosition(count_at),
                      "a field count whose headers fit in the remaining " +
                          std::to_string(r.remaining()) + " bytes (at most " +
                          std::to_string(r.remaining() / kMinFieldHeaderBytes) + ")",
                      std::to_string(count) + " (" +
                          std::to_string(static_cast<std::int32_t>(count)) + " as signed)");

  std::set<std::string, std::less<>> names;
  out.fields_.reserve(count);  // bounded just above by the file size
  for (std::uint32_t k = 0; k < count; ++k) {
    TensorField f;
    f.header_offset = r.offset();
    const std::string which = "field " + std::to_string(k);
    const std::uint16_t name_len = r.U16(which + " name length");
    const std::uint64_t name_at = r.offset();
    f.name = r.String(name_len, which + " name");
    if (!detail::IsValidUtf8(f.name))
      throw FormatError(out.file_, BytePosition(name_at), "a UTF-8 field name",
                        "invalid UTF-8 bytes in field " + std::to_string(k) + "'s name");
    // A name with control characters (a NUL ends the message that quotes it) is what a field
    // count, rank or shape that lies makes of the bytes after it: said as such, by byte.
    for (std::size_t c = 0; c < f.name.size(); ++c)
      if (static_cast<unsigned char>(f.name[c]) < 0x20 || f.name[c] == 0x7f) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02x", static_cast<unsigned char>(f.name[c]));
        throw FormatError(out.file_, BytePosition(name_at + c),
                          "a field name of printable characters (field " + std::to_string(k) +
                              " of " + std::to_string(count) +
                              "; the previous field's rank or shape may be wrong)",
                          std::string("the control character ") + hex);
      }
    if (names.contains(f.name))
      throw FormatError(out.file_, BytePosition(name_at), "unique field names",
                        "a second field " + Quoted(f.name));
    const std::string what = "field " + Quoted(f.name);
    const std::uint16_t rank = r.U16(what + " rank");
    const std::uint64_t dtype_at = r.offset();
    const std::uint8_t dtype = r.U8(what + " dtype");
    if (dtype < 1 || dtype > 11)
      throw FormatError(out.file_, BytePosition(dtype_at), what + " dtype 1..11 (uint8 .. float64)",
                        "dtype " + std::to_string(dtype));
    f.dtype = static_cast<TensorDtype>(dtype);
    const std::uint64_t offset_at = r.offset();
    f.data_offset = r.U64(what + " data offset");
    // Each dimension is read before it is stored, so a huge rank fails at the end of the file
    // without allocating for it.
    std::uint64_t elements = 1;
    bool overflow = false;
    for (std::uint16_t d = 0; d < rank; ++d) {
      const std::uint64_t dim = r.U64(what + " dimension " + std::to_string(d));
      f.shape.push_back(dim);
      if (dim != 0 && elements > std::numeric_limits<std::uint64_t>::max() / dim) overflow = true;
      elements = overflow ? 0 : elements * dim;
    }
    const std::uint64_t item = TensorDtypeSize(f.dtype);
    if (overflow || elements > file_size / item)
      throw FormatError(
          out.file_, BytePosition(offset_at),
          what + " data no larger than the file (" + std::to_string(file_size) + " bytes)",
          "shape " + f.ShapeString() + " of " + TensorDtypeName(f.dtype));
    f.data_bytes = elements * item;
    names.insert(f.name);
    out.fields_.push_back(std::move(f));
  }
  // Data ranges are checked once the whole header has been read, so a file cut inside its
  // header is reported there rather than at the first field whose data went missing.
  for (const TensorField& f : out.fields_) {
    if (f.data_offset > file_size || f.data_bytes > file_size - f.data_offset)
      throw FormatError(
          out.file_, BytePosition(f.header_offset + 2 + f.name.size() + 2 + 1),
          "field " + Quoted(f.name) + " data inside the file (" + std::to_string(file_size) +
              " bytes)",
          std::to_string(f.data_bytes) + " bytes at offset " + std::to_string(f.data_offset));
  }
  return out;
}

TensorFile TensorFile::Read(const std::string& path, std::uint64_t max_bytes) {
  return Parse(ReadFileBytes(path, max_bytes), path);
}

const TensorField* TensorFile::Find(std::string_view name) const {
  for (const TensorField& f : fields_)
    if (f.name == name) return &f;
  return nullptr;
}

const TensorField& TensorFile::Require(std::string_view name) const {
  if (const TensorField* f = Find(name)) return *f;
  std::string present;
  for (const TensorField& f : fields_) present += (present.empty() ? "" : ", ") + f.name;
  throw FormatError(file_, "field " + Quoted(name), "present",
                    "missing (fields: " + (present.empty() ? "none" : present) + ")");
}

std::span<const std::uint8_t> TensorFile::Data(const TensorField& field) const {
  return {bytes_.data() + field.data_offset, static_cast<std::size_t>(field.data_bytes)};
}

std::vector<float> TensorFile::Float32(const TensorField& field) const {
  if (field.dtype != TensorDtype::kFloat32)
    throw FormatError(file_, BytePosition(field.header_offset),
                      "field " + Quoted(field.name) + " of dtype float32",
                      TensorDtypeName(field.dtype));
  std::vector<float> out(static_cast<std::size_t>(field.element_count()));
  const std::uint8_t* p = bytes_.data() + field.data_offset;
  for (float& v : out) {
    v = std::bit_cast<float>(
        static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
        (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24));
    p += 4;
  }
  return out;
}

std::string EncodeTensorFile(std::span<const TensorFieldData> fields) {
  std::uint64_t header = sizeof kTensorFileMagic + 2 + 4;
  for (const TensorFieldData& f : fields)
    header += 2 + f.name.size() + 2 + 1 + 8 + 8 * f.shape.size();
  auto align8 = [](std::uint64_t v) { return (v + 7) & ~std::uint64_t{7}; };
  std::string out(kTensorFileMagic, sizeof kTensorFileMagic);
  out.push_back(1);
  out.push_back(0);
  AppendU32(out, static_cast<std::uint32_t>(fields.size()));
  std::uint64_t offset = align8(header);
  for (const TensorFieldData& f : fields) {
    std::uint64_t elements = 1;
    for (const std::uint64_t d : f.shape) elements *= d;
    if (elements * TensorDtypeSize(f.dtype) != f.data.size())
      throw InvalidArgument("EncodeTensorFile: field '" + f.name + "' has " +
                            std::to_string(f.data.size()) + " data bytes for shape of " +
                            std::to_string(elements) + " " + TensorDtypeName(f.dtype));
    AppendU16(out, static_cast<std::uint16_t>(f.name.size()));
    out += f.name;
    AppendU16(out, static_cast<std::uint16_t>(f.shape.size()));
    out.push_back(static_cast<char>(f.dtype));
    AppendU64(out, offset);
    for (const std::uint64_t d : f.shape) AppendU64(out, d);
    offset = align8(offset + f.data.size());
  }
  for (const TensorFieldData& f : fields) {
    out.resize(align8(out.size()), '\0');
    out += f.data;
  }
  return out;
}

}  // namespace brdf

namespace brdf {}  // namespace brdf
