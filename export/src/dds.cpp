#include "brdf/exporter/dds.h"

#include <cstring>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"
#include "container_util.h"

namespace brdf::exporter {
namespace {

constexpr std::uint32_t kFourCcDx10 = 0x30315844;  // "DX10"
constexpr std::uint32_t kDdsdCaps = 0x1, kDdsdHeight = 0x2, kDdsdWidth = 0x4, kDdsdPitch = 0x8,
                        kDdsdPixelFormat = 0x1000, kDdsdMipMapCount = 0x20000,
                        kDdsdLinearSize = 0x80000, kDdsdDepth = 0x800000;
constexpr std::uint32_t kDdpfFourCc = 0x4;
constexpr std::uint32_t kDdsCapsTexture = 0x1000;
constexpr std::uint32_t kDdsCaps2Volume = 0x200000;
constexpr std::uint32_t kResourceDimensionTexture2d = 3, kResourceDimensionTexture3d = 4;

std::string FourCcText(std::uint32_t v) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((v >> (8 * i)) & 0xff);
    s.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  }
  return "\"" + s + "\"" + fmt::format(" (0x{:08x})", v);
}

}  // namespace

namespace {

// DDS_HEADER + DDS_HEADER_DXT10 of a single-mip volume, or of a 2D texture for depth 0;
// `size_flag` is DDSD_PITCH (the row pitch of an uncompressed texture) or DDSD_LINEARSIZE (the
// bytes of one compressed slice).
std::string VolumeHeader(int width, int height, int depth, std::uint32_t dxgi_format,
                         std::uint32_t size_flag, std::uint32_t pitch_or_linear_size) {
  const bool volume = depth > 0;
  std::string out;
  out.reserve(kDdsDataOffset);
  out.append(kDdsMagic.begin(), kDdsMagic.end());
  AppendU32(out, 124);  // dwSize
  AppendU32(out, kDdsdCaps | kDdsdHeight | kDdsdWidth | size_flag | kDdsdPixelFormat |
                     kDdsdMipMapCount | (volume ? kDdsdDepth : 0u));
  AppendU32(out, static_cast<std::uint32_t>(height));
  AppendU32(out, static_cast<std::uint32_t>(width));
  AppendU32(out, pitch_or_linear_size);
  AppendU32(out, static_cast<std::uint32_t>(depth));
  AppendU32(out, 1);                               // dwMipMapCount
  for (int i = 0; i < 11; ++i) AppendU32(out, 0);  // dwReserved1
  AppendU32(out, 32);                              // DDS_PIXELFORMAT.dwSize
  AppendU32(out, kDdpfFourCc);
  AppendU32(out, kFourCcDx10);
  for (int i = 0; i < 5; ++i) AppendU32(out, 0);  // bit count and masks unused with FOURCC
  AppendU32(out, kDdsCapsTexture);
  AppendU32(out, volume ? kDdsCaps2Volume : 0u);
  AppendU32(out, 0);  // dwCaps3
  AppendU32(out, 0);  // dwCaps4
  AppendU32(out, 0);  // dwReserved2
  AppendU32(out, dxgi_format);
  AppendU32(out, volume ? kResourceDimensionTexture3d : kResourceDimensionTexture2d);
  AppendU32(out, 0);  // miscFlag
  AppendU32(out, 1);  // arraySize: 1 (one 3D or 2D texture)
  AppendU32(out, 0);  // miscFlags2: DDS_ALPHA_MODE_UNKNOWN
  return out;
}

}  // namespace

std::string DdsVolumeHeader(int width, int height, int depth, std::uint32_t dxgi_format,
                            int bytes_per_texel) {
  return VolumeHeader(
      width, height, depth, dxgi_format, kDdsdPitch,
      static_cast<std::uint32_t>(width) * static_cast<std::uint32_t>(bytes_per_texel));
}

std::string DdsTexture2dHeader(int width, int height, std::uint32_t dxgi_format,
                               int bytes_per_texel) {
  return VolumeHeader(
      width, height, 0, dxgi_format, kDdsdPitch,
      static_cast<std::uint32_t>(width) * static_cast<std::uint32_t>(bytes_per_texel));
}

std::string EncodeDds(const Bc6hVolume& volume) {
  if (volume.width < 1 || volume.height < 1 || volume.depth < 1 ||
      volume.bytes.size() != volume.BlockCount() * kBc6hBlockBytes)
    throw InvalidArgument(fmt::format("DDS: inconsistent BC6H volume {} × {} × {} with {} bytes",
                                      volume.width, volume.height, volume.depth,
                                      volume.bytes.size()));
  std::string out = VolumeHeader(
      volume.width, volume.height, volume.depth, kDxgiFormatBc6hUf16, kDdsdLinearSize,
      static_cast<std::uint32_t>(volume.BlocksWide() * volume.BlocksHigh() * kBc6hBlockBytes));
  out.append(volume.bytes.begin(), volume.bytes.end());
  return out;
}

void WriteDds(const std::string& path, const Bc6hVolume& volume) {
  WriteFileAtomically(path, EncodeDds(volume));
}

std::string EncodeDds(const PackedVolume& volume) {
  if (volume.width < 1 || volume.height < 1 || volume.depth < 1 ||
      volume.words.size() != static_cast<std::size_t>(volume.width) * volume.height * volume.depth)
    throw InvalidArgument(fmt::format("DDS: inconsistent volume {} × {} × {} with {} texels",
                                      volume.width, volume.height, volume.depth,
                                      volume.words.size()));
  std::string out =
      DdsVolumeHeader(volume.width, volume.height, volume.depth, kDxgiFormatR9g9b9e5Sharedexp, 4);
  out += volume.Bytes();
  return out;
}

void WriteDds(const std::string& path, const PackedVolume& volume) {
  WriteFileAtomically(path, EncodeDds(volume));
}

void WriteDds(const std::string& path, const Lut& lut) { WriteDds(path, PackLut(lut)); }

LoadedTexture ParseDds(const std::uint8_t* data, std::size_t size, const std::string& file,
                       const std::vector<double>& theta_in_deg) {
  ByteReader r(data, size, file);
  if (size < 4 || std::memcmp(data, kDdsMagic.data(), kDdsMagic.size()) != 0) {
    std::uint32_t got = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(size, 4); ++i)
      got |= std::uint32_t{data[i]} << (8 * i);
    throw FormatError(file, BytePosition(0), "the DDS magic \"DDS \"",
                      size < 4 ? "a file of " + std::to_string(size) + " bytes" : FourCcText(got));
  }
  r.Skip(4);
  const auto expect = [&](std::uint32_t expected, const char* what, const char* meaning = "") {
    const std::uint64_t at = r.offset();
    const std::uint32_t got = r.U32(what);
    if (got != expected)
      throw FormatError(
          file, BytePosition(at),
          fmt::format("{} {}{}", what, expected, *meaning ? fmt::format(" ({})", meaning) : ""),
          std::to_string(got));
  };
  expect(124, "DDS_HEADER.dwSize");
  const std::uint64_t at_flags = r.offset();
  const std::uint32_t flags = r.U32("DDS_HEADER.dwFlags");
  const std::uint32_t required =
      kDdsdCaps | kDdsdHeight | kDdsdWidth | kDdsdPixelFormat | kDdsdDepth;
  if ((flags & required) != required)
    throw FormatError(file, BytePosition(at_flags),
                      "dwFlags with CAPS, HEIGHT, WIDTH, PIXELFORMAT and DEPTH (a volume texture)",
                      Hex32Text(flags));
  LoadedTexture t;
  t.file = file;
  t.container = TextureContainer::kDds;
  const auto dimension = [&](const char* what) { return detail::ReadDimension(r, file, what); };
  t.volume.height = dimension("dwHeight");
  t.volume.width = dimension("dwWidth");
  const std::uint64_t at_pitch = r.offset();
  const std::uint32_t pitch = r.U32("dwPitchOrLinearSize");  // checked once the format is known
  t.volume.depth = dimension("dwDepth (a 3D texture: one slice per theta_in)");
  {
    const std::uint64_t at = r.offset();
    const std::uint32_t mips = r.U32("dwMipMapCount");
    if ((flags & kDdsdMipMapCount) && mips > 1)
      throw FormatError(file, BytePosition(at), "dwMipMapCount 1 (one level)",
                        std::to_string(mips));
  }
  r.Bytes(44, "DDS_HEADER.dwReserved1");
  expect(32, "DDS_PIXELFORMAT.dwSize");
  {
    const std::uint64_t at = r.offset();
    const std::uint32_t pf_flags = r.U32("DDS_PIXELFORMAT.dwFlags");
    if (!(pf_flags & kDdpfFourCc))
      throw FormatError(file, BytePosition(at), "DDS_PIXELFORMAT.dwFlags with DDPF_FOURCC (0x4)",
                        Hex32Text(pf_flags));
    const std::uint64_t at_cc = r.offset();
    const std::uint32_t four_cc = r.U32("DDS_PIXELFORMAT.dwFourCC");
    if (four_cc != kFourCcDx10)
      throw FormatError(file, BytePosition(at_cc),
                        "FourCC \"DX10\" (a DDS_HEADER_DXT10 extension header)",
                        FourCcText(four_cc));
  }
  r.Bytes(20, "DDS_PIXELFORMAT bit count and masks");
  r.U32("dwCaps");
  {
    const std::uint64_t at = r.offset();
    const std::uint32_t caps2 = r.U32("dwCaps2");
    if (!(caps2 & kDdsCaps2Volume))
      throw FormatError(file, BytePosition(at), "dwCaps2 with DDSCAPS2_VOLUME (0x200000)",
                        Hex32Text(caps2));
  }
  r.Bytes(12, "dwCaps3, dwCaps4 and dwReserved2");
  {
    const std::uint64_t at = r.offset();
    const std::uint32_t dxgi = r.U32("DDS_HEADER_DXT10.dxgiFormat");
    if (dxgi == kDxgiFormatBc6hUf16) {
      t.format = TexelFormat::kBc6hUfloat;
    } else if (dxgi != kDxgiFormatR9g9b9e5Sharedexp) {
      throw FormatError(file, BytePosition(at),
                        "DXGI format 67 (DXGI_FORMAT_R9G9B9E5_SHAREDEXP) or 95 "
                        "(DXGI_FORMAT_BC6H_UF16)",
                        "unsupported DXGI format " + std::to_string(dxgi));
    }
  }
  const bool bc6h = t.format == TexelFormat::kBc6hUfloat;
  if (bc6h) {
    t.bc6h.width = t.volume.width, t.bc6h.height = t.volume.height, t.bc6h.depth = t.volume.depth;
  }
  // An uncompressed row is width × 4 bytes, a row of BC6H blocks ceil(width/4) × 16.
  const std::uint32_t row_pitch = bc6h ? static_cast<std::uint32_t>(t.bc6h.BlocksWide() * 16)
                                       : static_cast<std::uint32_t>(t.volume.width) * 4;
  if ((flags & kDdsdPitch) && !(flags & kDdsdLinearSize) && pitch != row_pitch)
    throw FormatError(file, BytePosition(at_pitch),
                      bc6h ? fmt::format("row pitch {} (ceil(width/4) × 16 bytes)", row_pitch)
                           : fmt::format("row pitch {} (width × 4 bytes)", row_pitch),
                      std::to_string(pitch));
  expect(kResourceDimensionTexture3d, "resourceDimension", "D3D10_RESOURCE_DIMENSION_TEXTURE3D");
  r.U32("miscFlag");
  expect(1, "arraySize", "a 3D texture is never an array");
  r.U32("miscFlags2");

  const std::uint64_t texels = static_cast<std::uint64_t>(t.volume.width) * t.volume.height *
                               static_cast<std::uint64_t>(t.volume.depth);
  const std::uint64_t expected = bc6h ? t.bc6h.BlockCount() * kBc6hBlockBytes : texels * 4;
  if (r.remaining() != expected)
    throw FormatError(
        file, BytePosition(kDdsDataOffset),
        bc6h ? fmt::format("{} bytes of BC6H blocks ({} × {} blocks × {} slices × 16)", expected,
                           t.bc6h.BlocksWide(), t.bc6h.BlocksHigh(), t.bc6h.depth)
             : fmt::format("{} bytes of texel data ({} × {} × {} × 4)", texels * 4, t.volume.width,
                           t.volume.height, t.volume.depth),
        std::to_string(r.remaining()) + " bytes");
  if (bc6h) {
    t.bc6h.bytes.assign(data + kDdsDataOffset, data + kDdsDataOffset + expected);
  } else {
    t.volume.words.resize(texels);
    detail::CopyLittleEndianWords(data + kDdsDataOffset, t.volume.words);
  }
  if (!theta_in_deg.empty()) {
    if (theta_in_deg.size() != static_cast<std::size_t>(t.volume.depth))
      throw InvalidArgument(fmt::format("{}: {} slices but {} θin values given", file,
                                        t.volume.depth, theta_in_deg.size()));
    t.theta_in_deg = theta_in_deg;
    t.theta_in_from_metadata = true;
  }
  FinishLoadedTexture(t);
  return t;
}

LoadedTexture ReadDds(const std::string& path, const std::vector<double>& theta_in_deg) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path, kMaxTextureFileBytes);
  return ParseDds(bytes.data(), bytes.size(), path, theta_in_deg);
}

}  // namespace brdf::exporter
