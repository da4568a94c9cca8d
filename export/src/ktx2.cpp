#include "brdf/exporter/ktx2.h"

#include <algorithm>
#include <array>
#include <cstring>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/sidecar.h"
#include "container_util.h"

namespace brdf::exporter {
namespace {

constexpr std::size_t kHeaderEnd = 12 + 9 * 4;          // identifier + header
constexpr std::size_t kIndexEnd = kHeaderEnd + 32;      // + dfd/kvd/sgd index
constexpr std::size_t kLevelIndexEnd = kIndexEnd + 24;  // + one level index entry

// Data Format Descriptor field encodings (Khronos Data Format Specification 1.3, basic block).
constexpr std::uint32_t kDfVersion13 = 2;
constexpr std::uint32_t kModelRgbsda = 1, kPrimariesBt709 = 1, kTransferLinear = 1;
constexpr std::uint32_t kQualifierExponent = 0x20;  // KHR_DF_SAMPLE_DATATYPE_EXPONENT
constexpr std::uint32_t kBasicBlockBytes = 24 + 6 * 16;
constexpr std::uint32_t kMantissaUpper = 8448;  // as the spec's shared-exponent example
constexpr std::uint32_t kExponentLower = 15, kExponentUpper = 31;  // bias, maximum

std::uint32_t SampleWord0(std::uint32_t bit_offset, std::uint32_t bit_length,
                          std::uint32_t channel) {
  return bit_offset | ((bit_length - 1) << 16) | (channel << 24);
}

std::size_t Align4(std::size_t n) { return (n + 3) & ~std::size_t{3}; }

void Put32(std::string& out, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
void Put64(std::string& out, std::size_t at, std::uint64_t v) {
  Put32(out, at, static_cast<std::uint32_t>(v));
  Put32(out, at + 4, static_cast<std::uint32_t>(v >> 32));
}

KeyValues WithStandardKeys(const KeyValues& key_values) {
  KeyValues all;
  all.emplace_back("KTXorientation", "rdi");
  all.emplace_back("KTXwriter", BrdfToolWriter());
  for (const auto& kv : key_values) {
    if (kv.first == "KTXorientation" || kv.first == "KTXwriter") continue;
    all.push_back(kv);
  }
  for (const auto& [key, value] : all)
    if (key.empty() || key.find('\0') != std::string::npos)
      throw InvalidArgument("KTX2 key/value data: keys must be non-empty and free of NUL, got \"" +
                            key + "\"");
  // Keys sorted by their UTF-8 bytes (KTX 2.0 §3.11); std::string compares bytes as char,
  // so compare as unsigned to be exact for non-ASCII keys.
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return std::lexicographical_compare(
        a.first.begin(), a.first.end(), b.first.begin(), b.first.end(), [](char x, char y) {
          return static_cast<unsigned char>(x) < static_cast<unsigned char>(y);
        });
  });
  for (std::size_t i = 1; i < all.size(); ++i)
    if (all[i].first == all[i - 1].first)
      throw InvalidArgument("KTX2 key/value data: duplicate key \"" + all[i].first + "\"");
  return all;
}

// Checks one field read at the reader's current position minus 4.
void Expect32(ByteReader& r, std::uint32_t expected, std::string_view what,
              std::string_view meaning = {}) {
  const std::uint64_t at = r.offset();
  const std::uint32_t got = r.U32(what);
  if (got != expected)
    throw FormatError(
        r.file(), BytePosition(at),
        fmt::format("{} {}{}", what, expected,
                    meaning.empty() ? std::string() : " (" + std::string(meaning) + ")"),
        std::to_string(got));
}

void ValidateDfd(const std::uint8_t* data, std::size_t size, std::uint64_t base,
                 const std::string& file) {
  ByteReader r(data, size, file, base);
  const std::vector<std::uint32_t> expected = E5b9g9r9DataFormatDescriptor();
  Expect32(r, expected[0], "DFD dfdTotalSize");
  const std::uint64_t at_block = r.offset();
  const std::uint32_t w0 = r.U32("DFD vendorId/descriptorType");
  if (w0 != 0)
    throw FormatError(file, BytePosition(at_block),
                      "DFD vendorId 0 (Khronos) and descriptorType 0 (basic format)",
                      fmt::format("vendorId {}, descriptorType {}", w0 & 0x1ffff, w0 >> 17));
  const std::uint64_t at_version = r.offset();
  const std::uint32_t w1 = r.U32("DFD versionNumber/descriptorBlockSize");
  if ((w1 & 0xffff) != kDfVersion13)
    throw FormatError(file, BytePosition(at_version), "DFD versionNumber 2 (Data Format 1.3)",
                      std::to_string(w1 & 0xffff));
  if ((w1 >> 16) != kBasicBlockBytes)
    throw FormatError(file, BytePosition(at_version + 2),
                      "DFD descriptorBlockSize 120 (6 samples: mantissa + exponent per channel)",
                      std::to_string(w1 >> 16));
  const std::uint64_t at_model = r.offset();
  const std::uint32_t w2 = r.U32("DFD colour model");
  if ((w2 & 0xff) != kModelRgbsda)
    throw FormatError(file, BytePosition(at_model), "DFD colorModel 1 (RGBSDA)",
                      std::to_string(w2 & 0xff));
  if (((w2 >> 16) & 0xff) != kTransferLinear)
    throw FormatError(file, BytePosition(at_model + 2), "DFD transferFunction 1 (linear)",
                      std::to_string((w2 >> 16) & 0xff));
  Expect32(r, 0, "DFD texelBlockDimension word", "1x1x1x1 texel block");
  Expect32(r, 4, "DFD bytesPlane0-3 word", "bytesPlane0 = 4");
  Expect32(r, 0, "DFD bytesPlane4-7 word");
  static constexpr const char* kSampleNames[6] = {"R mantissa", "R exponent", "G mantissa",
                                                  "G exponent", "B mantissa", "B exponent"};
  for (int s = 0; s < 6; ++s) {
    const std::size_t w = 7 + 4 * s;
    const std::string name =
        std::string("DFD sample ") + std::to_string(s) + " (" + kSampleNames[s] + ")";
    const std::uint64_t at = r.offset();
    const std::uint32_t got = r.U32(name);
    if (got != expected[w])
      throw FormatError(file, BytePosition(at),
                        fmt::format("{}: bitOffset {}, bitLength {} (stored {}), channel 0x{:02x}",
                                    name, expected[w] & 0xffff, ((expected[w] >> 16) & 0xff) + 1,
                                    (expected[w] >> 16) & 0xff, expected[w] >> 24),
                        fmt::format("bitOffset {}, stored bitLength {}, channel 0x{:02x}",
                                    got & 0xffff, (got >> 16) & 0xff, got >> 24));
    r.U32("DFD sample position");  // any sample position is acceptable for 1x1 blocks
    Expect32(r, expected[w + 2], name + " sampleLower");
    Expect32(r, expected[w + 3], name + " sampleUpper");
  }
}

// The BC6H descriptor has one fixed form (Data Format Specification §5.15, as libktx writes it);
// every word but the sample position must match.
void ValidateBc6hDfd(const std::uint8_t* data, std::size_t size, std::uint64_t base,
                     const std::string& file) {
  const std::vector<std::uint32_t> expected = Bc6hUfloatDataFormatDescriptor();
  if (size != expected.size() * 4)
    throw FormatError(
        file, BytePosition(kHeaderEnd + 4),
        fmt::format("dfdByteLength {} (one basic block with one BC6H sample)", expected.size() * 4),
        std::to_string(size));
  static constexpr const char* kWords[11] = {"DFD dfdTotalSize",
                                             "DFD vendorId/descriptorType",
                                             "DFD versionNumber/descriptorBlockSize",
                                             "DFD colour model (131, BC6H), primaries, transfer",
                                             "DFD texelBlockDimension (4 x 4 x 1)",
                                             "DFD bytesPlane0 (16)",
                                             "DFD bytesPlane4-7",
                                             "DFD sample (bits 0-127, channel BC6H colour, FLOAT)",
                                             "DFD sample position",
                                             "DFD sampleLower (0.0)",
                                             "DFD sampleUpper (1.0)"};
  ByteReader r(data, size, file, base);
  for (std::size_t w = 0; w < expected.size(); ++w) {
    const std::uint64_t at = r.offset();
    const std::uint32_t got = r.U32(kWords[w]);
    if (w == 8) continue;  // any sample position is acceptable
    if (got != expected[w])
      throw FormatError(file, BytePosition(at), fmt::format("{} 0x{:08x}", kWords[w], expected[w]),
                        fmt::format("0x{:08x}", got));
  }
}

}  // namespace

std::vector<std::uint32_t> E5b9g9r9DataFormatDescriptor() {
  std::vector<std::uint32_t> d;
  d.push_back(4 + kBasicBlockBytes);  // dfdTotalSize
  d.push_back(0);                     // vendorId 0, descriptorType 0
  d.push_back(kDfVersion13 | (kBasicBlockBytes << 16));
  d.push_back(kModelRgbsda | (kPrimariesBt709 << 8) | (kTransferLinear << 16));  // flags 0
  d.push_back(0);  // texelBlockDimension0..3 = 0: 1×1×1×1
  d.push_back(4);  // bytesPlane0 = 4
  d.push_back(0);  // bytesPlane4..7
  for (std::uint32_t channel = 0; channel < 3; ++channel) {
    d.insert(d.end(), {SampleWord0(9 * channel, 9, channel), 0u, 0u, kMantissaUpper});
    d.insert(d.end(), {SampleWord0(27, 5, channel | kQualifierExponent), 0u, kExponentLower,
                       kExponentUpper});
  }
  return d;
}

namespace {

// The container around any payload: `type_size` and the level alignment (lcm(texel block
// size, 4); no supercompression) follow the format.
std::string EncodeKtx2Payload(std::uint32_t vk_format, std::uint32_t type_size,
                              std::size_t level_alignment, const std::vector<std::uint32_t>& dfd,
                              int width, int height, int depth, const std::string& payload,
                              const KeyValues& key_values) {
  const KeyValues kvs = WithStandardKeys(key_values);
  std::string kvd;
  for (const auto& [key, value] : kvs) {
    const std::size_t length = key.size() + 1 + value.size() + 1;  // key\0value\0
    AppendU32(kvd, static_cast<std::uint32_t>(length));
    kvd += key;
    kvd.push_back('\0');
    kvd += value;
    kvd.push_back('\0');
    kvd.resize(Align4(kvd.size()), '\0');  // valuePadding
  }

  const std::size_t dfd_offset = kLevelIndexEnd;
  const std::size_t dfd_length = dfd.size() * 4;
  const std::size_t kvd_offset = dfd_offset + dfd_length;
  const std::size_t unaligned = kvd_offset + kvd.size();
  const std::size_t level_offset =
      (unaligned + level_alignment - 1) / level_alignment * level_alignment;
  const std::size_t level_length = payload.size();

  std::string out(level_offset, '\0');
  std::memcpy(out.data(), kKtx2Identifier.data(), kKtx2Identifier.size());
  const std::uint32_t header[9] = {vk_format,
                                   type_size,
                                   static_cast<std::uint32_t>(width),
                                   static_cast<std::uint32_t>(height),
                                   static_cast<std::uint32_t>(depth),
                                   0,   // layerCount: not an array
                                   1,   // faceCount
                                   1,   // levelCount
                                   0};  // supercompressionScheme: none
  for (int i = 0; i < 9; ++i) Put32(out, 12 + 4 * i, header[i]);
  Put32(out, kHeaderEnd, static_cast<std::uint32_t>(dfd_offset));
  Put32(out, kHeaderEnd + 4, static_cast<std::uint32_t>(dfd_length));
  Put32(out, kHeaderEnd + 8, kvd.empty() ? 0 : static_cast<std::uint32_t>(kvd_offset));
  Put32(out, kHeaderEnd + 12, static_cast<std::uint32_t>(kvd.size()));
  Put64(out, kHeaderEnd + 16, 0);  // sgdByteOffset
  Put64(out, kHeaderEnd + 24, 0);  // sgdByteLength
  Put64(out, kIndexEnd, level_offset);
  Put64(out, kIndexEnd + 8, level_length);
  Put64(out, kIndexEnd + 16, level_length);  // uncompressedByteLength
  for (std::size_t i = 0; i < dfd.size(); ++i) Put32(out, dfd_offset + 4 * i, dfd[i]);
  std::memcpy(out.data() + kvd_offset, kvd.data(), kvd.size());
  out += payload;
  return out;
}

}  // namespace

std::vector<std::uint32_t> Bc6hUfloatDataFormatDescriptor() {
  constexpr std::uint32_t kBlockBytes = 24 + 16;   // one sample
  constexpr std::uint32_t kModelBc6h = 131;        // KHR_DF_MODEL_BC6H
  constexpr std::uint32_t kQualifierFloat = 0x80;  // KHR_DF_SAMPLE_DATATYPE_FLOAT
  return {4 + kBlockBytes,
          0,  // vendorId 0 (Khronos), descriptorType 0 (basic)
          kDfVersion13 | (kBlockBytes << 16),
          kModelBc6h | (kPrimariesBt709 << 8) | (kTransferLinear << 16),  // flags 0
          3 | (3 << 8),  // texelBlockDimension 4 × 4 × 1 × 1 (stored minus one)
          16,            // bytesPlane0: 16 bytes per block
          0,
          SampleWord0(0, 128, kQualifierFloat),  // channel 0 = KHR_DF_CHANNEL_BC6H_COLOR
          0,                                     // sample position 0, 0, 0, 0
          0,                                     // sampleLower 0.0f
          0x3F800000u};                          // sampleUpper 1.0f
}

std::string EncodeKtx2(const PackedVolume& volume, const KeyValues& key_values) {
  if (volume.width < 1 || volume.height < 1 || volume.depth < 1 ||
      volume.words.size() != static_cast<std::size_t>(volume.width) * volume.height * volume.depth)
    throw InvalidArgument(fmt::format("KTX2: inconsistent volume {} × {} × {} with {} texels",
                                      volume.width, volume.height, volume.depth,
                                      volume.words.size()));
  // typeSize 4 (_PACK32); no supercompression global data, so the level only needs
  // lcm(texel block size, 4) = 4.
  return EncodeKtx2Payload(kVkFormatE5b9g9r9UfloatPack32, 4, 4, E5b9g9r9DataFormatDescriptor(),
                           volume.width, volume.height, volume.depth, volume.Bytes(), key_values);
}

std::string EncodeKtx2(const Bc6hVolume& volume, const KeyValues& key_values) {
  if (volume.width < 1 || volume.height < 1 || volume.depth < 1 ||
      volume.bytes.size() != volume.BlockCount() * kBc6hBlockBytes)
    throw InvalidArgument(fmt::format("KTX2: inconsistent BC6H volume {} × {} × {} with {} bytes",
                                      volume.width, volume.height, volume.depth,
                                      volume.bytes.size()));
  // typeSize 1 for block-compressed formats; levels aligned to lcm(16-byte block, 4) = 16.
  return EncodeKtx2Payload(kVkFormatBc6hUfloatBlock, 1, 16, Bc6hUfloatDataFormatDescriptor(),
                           volume.width, volume.height, volume.depth,
                           std::string(volume.bytes.begin(), volume.bytes.end()), key_values);
}

void WriteKtx2(const std::string& path, const Bc6hVolume& volume, const KeyValues& key_values) {
  WriteFileAtomically(path, EncodeKtx2(volume, key_values));
}

void WriteKtx2(const std::string& path, const PackedVolume& volume, const KeyValues& key_values) {
  WriteFileAtomically(path, EncodeKtx2(volume, key_values));
}

void WriteKtx2(const std::string& path, const PackedVolume& volume,
               const std::vector<double>& theta_in_deg, const TextureMetadata& metadata) {
  WriteKtx2(path, volume, KeyValues{{"brdf.sidecar", SidecarJson(volume, theta_in_deg, metadata)}});
}

void WriteKtx2(const std::string& path, const Lut& lut, const TextureMetadata& metadata) {
  WriteKtx2(path, PackLut(lut), lut.theta_in_deg, metadata);
}

LoadedTexture ParseKtx2(const std::uint8_t* data, std::size_t size, const std::string& file) {
  ByteReader r(data, size, file);
  if (size < 12 || std::memcmp(data, kKtx2Identifier.data(), 12) != 0) {
    std::string got = size < 12 ? fmt::format("a file of {} bytes", size) : std::string("bytes");
    for (std::size_t i = 0; i < std::min<std::size_t>(size, 12); ++i)
      got += fmt::format(" {:02x}", data[i]);
    throw FormatError(
        file, BytePosition(0),
        "the KTX 2.0 identifier ab 4b 54 58 20 32 30 bb 0d 0a 1a 0a («KTX 20»\\r\\n\\x1A\\n)", got);
  }
  r.Skip(12);
  LoadedTexture t;
  t.file = file;
  t.container = TextureContainer::kKtx2;
  {
    const std::uint64_t at = r.offset();
    const std::uint32_t vk_format = r.U32("vkFormat");
    if (vk_format == kVkFormatBc6hUfloatBlock) {
      t.format = TexelFormat::kBc6hUfloat;
    } else if (vk_format != kVkFormatE5b9g9r9UfloatPack32) {
      throw FormatError(file, BytePosition(at),
                        "vkFormat 123 (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) or 131 "
                        "(VK_FORMAT_BC6H_UFLOAT_BLOCK)",
                        std::to_string(vk_format));
    }
  }
  const bool bc6h = t.format == TexelFormat::kBc6hUfloat;
  Expect32(r, bc6h ? 1 : 4, "typeSize", bc6h ? "1 for a block-compressed format" : "");
  const auto dimension = [&](const char* what) { return detail::ReadDimension(r, file, what); };
  t.volume.width = dimension("pixelWidth");
  t.volume.height = dimension("pixelHeight");
  t.volume.depth = dimension("pixelDepth (a 3D texture: one slice per theta_in)");
  Expect32(r, 0, "layerCount", "not an array texture");
  Expect32(r, 1, "faceCount");
  {
    const std::uint64_t at = r.offset();
    const std::uint32_t levels = r.U32("levelCount");
    if (levels > 1)
      throw FormatError(file, BytePosition(at), "levelCount 1 (one mip level)",
                        std::to_string(levels));
  }
  Expect32(r, 0, "supercompressionScheme", "none");
  const std::uint32_t dfd_offset = r.U32("dfdByteOffset");
  const std::uint32_t dfd_length = r.U32("dfdByteLength");
  const std::uint32_t kvd_offset = r.U32("kvdByteOffset");
  const std::uint32_t kvd_length = r.U32("kvdByteLength");
  const std::uint64_t sgd_offset = r.U64("sgdByteOffset");
  const std::uint64_t sgd_length = r.U64("sgdByteLength");
  if (sgd_length != 0 || sgd_offset != 0)
    throw FormatError(file, BytePosition(kHeaderEnd + 16),
                      "no supercompression global data (offset and length 0)",
                      fmt::format("offset {}, length {}", sgd_offset, sgd_length));
  const std::uint64_t level_offset = r.U64("level 0 byteOffset");
  const std::uint64_t level_length = r.U64("level 0 byteLength");
  const std::uint64_t level_uncompressed = r.U64("level 0 uncompressedByteLength");

  const auto check_range = [&](std::uint64_t offset, std::uint64_t length, std::uint64_t at,
                               const char* what) {
    if (offset > size || length > size - offset)
      throw FormatError(file, BytePosition(at),
                        fmt::format("{} inside the file ({} bytes)", what, size),
                        // Length and offset as stored: their sum may wrap past 2^64.
                        fmt::format("{} bytes from offset {}", length, offset));
  };
  check_range(dfd_offset, dfd_length, kHeaderEnd, "the Data Format Descriptor");
  if (bc6h) {
    ValidateBc6hDfd(data + dfd_offset, dfd_length, dfd_offset, file);
  } else if (dfd_length != 4 + kBasicBlockBytes)
    throw FormatError(
        file, BytePosition(kHeaderEnd + 4),
        fmt::format("dfdByteLength {} (one basic block of 6 samples)", 4 + kBasicBlockBytes),
        std::to_string(dfd_length));
  else
    ValidateDfd(data + dfd_offset, dfd_length, dfd_offset, file);

  check_range(kvd_offset, kvd_length, kHeaderEnd + 8, "the key/value data");
  {
    ByteReader kv(data + kvd_offset, kvd_length, file, kvd_offset);
    while (kv.remaining() > 0) {
      const std::uint64_t at = kv.offset();
      const std::uint32_t length = kv.U32("keyAndValueByteLength");
      const std::uint8_t* p = kv.Bytes(length, "key and value");
      const auto* nul = static_cast<const std::uint8_t*>(std::memchr(p, 0, length));
      if (nul == nullptr || nul == p)
        throw FormatError(file, BytePosition(at + 4), "a non-empty NUL-terminated key",
                          "no key terminator in " + std::to_string(length) + " bytes");
      std::string key(reinterpret_cast<const char*>(p), static_cast<std::size_t>(nul - p));
      std::string value(reinterpret_cast<const char*>(nul + 1), length - key.size() - 1);
      if (!value.empty() && value.back() == '\0') value.pop_back();
      t.key_values.emplace_back(std::move(key), std::move(value));
      const std::size_t padding = Align4(length) - length;
      if (padding > 0 && kv.remaining() > 0) kv.Skip(std::min(padding, kv.remaining()));
    }
  }

  const std::uint64_t texels = static_cast<std::uint64_t>(t.volume.width) * t.volume.height *
                               static_cast<std::uint64_t>(t.volume.depth);
  if (bc6h) {
    t.bc6h.width = t.volume.width, t.bc6h.height = t.volume.height, t.bc6h.depth = t.volume.depth;
  }
  const std::uint64_t expected_length = bc6h ? t.bc6h.BlockCount() * kBc6hBlockBytes : texels * 4;
  if (level_length != expected_length)
    throw FormatError(
        file, BytePosition(kIndexEnd + 8),
        bc6h ? fmt::format("level 0 byteLength {} ({} × {} blocks of 4 × 4 texels × {} slices × 16 "
                           "bytes)",
                           expected_length, t.bc6h.BlocksWide(), t.bc6h.BlocksHigh(), t.bc6h.depth)
             : fmt::format("level 0 byteLength {} ({} × {} × {} texels × 4 bytes)", texels * 4,
                           t.volume.width, t.volume.height, t.volume.depth),
        std::to_string(level_length));
  if (level_uncompressed != level_length)
    throw FormatError(file, BytePosition(kIndexEnd + 16),
                      fmt::format("uncompressedByteLength {} (no supercompression)", level_length),
                      std::to_string(level_uncompressed));
  const std::uint64_t alignment = bc6h ? 16 : 4;
  if (level_offset % alignment != 0)
    throw FormatError(file, BytePosition(kIndexEnd),
                      fmt::format("a level byteOffset aligned to {} bytes", alignment),
                      std::to_string(level_offset));
  check_range(level_offset, level_length, kIndexEnd, "the level 0 image");

  if (bc6h) {
    t.bc6h.bytes.assign(data + level_offset, data + level_offset + level_length);
  } else {
    t.volume.words.resize(texels);
    detail::CopyLittleEndianWords(data + level_offset, t.volume.words);
  }

  for (const auto& [key, value] : t.key_values) {
    if (key == "brdf.sidecar") t.sidecar_json = value;
    if (key == "brdf.atlas") t.atlas_manifest_json = value;
  }
  FinishLoadedTexture(t);
  return t;
}

LoadedTexture ReadKtx2(const std::string& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path, kMaxTextureFileBytes);
  return ParseKtx2(bytes.data(), bytes.size(), path);
}

}  // namespace brdf::exporter
