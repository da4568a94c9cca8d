// EXR through OpenEXR's C++ API (no OpenImageIO), see brdf/image_io/image_io.h.
#include <sys/stat.h>

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/image_io/image_io.h"
#include "image_io_pvt.h"

namespace brdf::image_io {
namespace {

constexpr const char* kChannels[3] = {"R", "G", "B"};

template <typename T>
Imf::FrameBuffer InterleavedRgb(const T* data, const Imath::Box2i& window, int width) {
  constexpr Imf::PixelType kType = std::is_same_v<T, float> ? Imf::FLOAT : Imf::HALF;
  constexpr std::size_t kPixelBytes = 3 * sizeof(T);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(kChannels[c], Imf::Slice::Make(kType, data + c, window, kPixelBytes,
                                                kPixelBytes * static_cast<std::size_t>(width)));
  return frame;
}

const char* CompressionName(Imf::Compression c) {
  static const char* const kNames[] = {"uncompressed", "RLE", "ZIPS", "ZIP",  "PIZ",
                                       "PXR24",        "B44", "B44A", "DWAA", "DWAB"};
  const int k = static_cast<int>(c);
  return k >= 0 && k < 10 ? kNames[k] : "compressed";
}

// OpenEXR refused `path` with `why`: the FormatError that says where, when the file's layout
// shows it (damage.cpp), or which block of scanlines does not decode; else OpenEXR's words.
[[noreturn]] void ThrowDamaged(const std::string& path, std::string why) {
  detail::ExrLayout layout;
  if (const auto damage = detail::LocateExrDamage(path, &layout))
    throw FormatError(path, damage->position, damage->expected, damage->got);
  if (layout.blocks > 0) {
    try {
      Imf::InputFile file(path.c_str(), /*numThreads=*/0);
      const Imath::Box2i window = file.header().dataWindow();
      const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
      // Within the reader's limit, as ReadExrImage checked before reading pixels.
      const bool fits =
          width >= 1 &&
          static_cast<unsigned long long>(width) * layout.lines_per_block <= kMaxReadPixels;
      std::vector<float> rgb(fits ? static_cast<std::size_t>(width) * 3 * layout.lines_per_block
                                  : 0);
      for (std::uint64_t k = 0; fits && k < layout.blocks; ++k) {
        const int y0 = window.min.y + static_cast<int>(k * layout.lines_per_block);
        const int y1 = std::min(window.max.y, y0 + static_cast<int>(layout.lines_per_block) - 1);
        // A frame buffer for this block's rows only: its origin moved so row y0 is its first.
        Imath::Box2i rows = window;
        rows.min.y = y0;
        rows.max.y = y1;
        file.setFrameBuffer(InterleavedRgb(rgb.data(), rows, static_cast<int>(width)));
        try {
          file.readPixels(y0, y1);
        } catch (const std::exception&) {
          throw FormatError(path, detail::ExrBlockPosition(layout, k),
                            std::string(CompressionName(file.header().compression())) +
                                " pixel data that decodes to the block's scanlines",
                            "data that does not decode (damaged bytes)");
        }
      }
    } catch (const Error&) {
      throw;
    } catch (const std::exception&) {
      // The header itself is refused: OpenEXR's words below.
    }
  }
  // OpenEXR's own words ("Cannot read image file "F". Early end of file: read 1 out of 4
  // requested bytes.") when the layout shows nothing; the sentence that repeats the file name
  // is dropped, since the message starts with it already.
  const std::string named = "\"" + path + "\". ";
  if (const std::size_t at = why.find(named); at != std::string::npos)
    why = why.substr(at + named.size());
  throw FormatError(path, "EXR content", "a readable OpenEXR image", why);
}

}  // namespace

void WriteExrImage(const std::string& path, const RgbImage& image, ExrPixelType pixel_type,
                   ExrCompression compression, const StringAttributes& attributes) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw InvalidArgument(fmt::format("{}: EXR: inconsistent image {} × {} with {} floats", path,
                                      image.width, image.height, image.rgb.size()));
  // The default header is what every EXR needs and nothing more: data and display window of
  // the image, pixel aspect 1, screen window (0, 0) / 1, increasing-y scanlines.
  Imf::Header header(image.width, image.height);
  header.compression() =
      compression == ExrCompression::kZip ? Imf::ZIP_COMPRESSION : Imf::NO_COMPRESSION;
  const Imf::PixelType type = pixel_type == ExrPixelType::kHalf ? Imf::HALF : Imf::FLOAT;
  for (const char* name : kChannels) header.channels().insert(name, Imf::Channel(type));
  for (const auto& [name, value] : attributes) {
    if (name.empty() || header.find(name) != header.end())
      throw InvalidArgument(path + ": EXR header attribute '" + name +
                            "' is empty or one of the standard attributes");
    header.insert(name, Imf::StringAttribute(value));
  }
  AtomicOutputPath out_path(path);
  try {
    Imf::OutputFile file(out_path.temp_path().c_str(), header, /*numThreads=*/0);
    // OpenEXR converts pixel types when reading but not when writing: half channels need half
    // slices. Imath's conversion rounds to nearest even; above 65504 it gives +inf.
    std::vector<Imath::half> halves;
    if (type == Imf::HALF) {
      halves.assign(image.rgb.begin(), image.rgb.end());
      file.setFrameBuffer(InterleavedRgb(halves.data(), header.dataWindow(), image.width));
    } else {
      file.setFrameBuffer(InterleavedRgb(image.rgb.data(), header.dataWindow(), image.width));
    }
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw IoError(path + ": writing the EXR failed: " + e.what());
  }
  out_path.Commit();
}

std::string ExrImage::Attribute(const std::string& name) const {
  for (const auto& [key, value] : attributes)
    if (key == name) return value;
  return {};
}

ExrImage ReadExrImage(const std::string& path) {
  detail::RequireReadableRegularFile(path);
  ExrImage out;
  try {
    Imf::InputFile file(path.c_str(), /*numThreads=*/0);
    const Imf::Header& header = file.header();
    const Imf::ChannelList& channels = header.channels();
    std::string names;
    for (auto it = channels.begin(); it != channels.end(); ++it)
      names += (names.empty() ? "" : ", ") + std::string(it.name());
    for (const char* name : kChannels) {
      const Imf::Channel* channel = channels.findChannel(name);
      if (channel == nullptr)
        throw FormatError(path, "channel list", "channels R, G, B",
                          names.empty() ? "no channels" : "channels " + names);
      if (channel->xSampling != 1 || channel->ySampling != 1)
        throw FormatError(path, std::string("channel ") + name, "one sample per pixel",
                          fmt::format("sampling {} × {}", channel->xSampling, channel->ySampling));
    }
    const Imath::Box2i window = header.dataWindow();
    const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
    if (width < 1 || height < 1 ||
        static_cast<unsigned long long>(width) * static_cast<unsigned long long>(height) >
            kMaxReadPixels)
      throw FormatError(path, "data window",
                        fmt::format("an image of 1 to {} pixels", kMaxReadPixels),
                        fmt::format("{} × {}", width, height));
    out.pixel_type =
        channels.findChannel("R")->type == Imf::HALF ? ExrPixelType::kHalf : ExrPixelType::kFloat;
    out.compression = header.compression() == Imf::ZIP_COMPRESSION ||
                              header.compression() == Imf::ZIPS_COMPRESSION
                          ? ExrCompression::kZip
                          : ExrCompression::kNone;
    out.image.width = static_cast<int>(width);
    out.image.height = static_cast<int>(height);
    out.image.rgb.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
    file.setFrameBuffer(InterleavedRgb(out.image.rgb.data(), window, out.image.width));
    file.readPixels(window.min.y, window.max.y);
    for (auto it = header.begin(); it != header.end(); ++it)
      if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
        out.attributes.emplace_back(it.name(), text->value());
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    ThrowDamaged(path, e.what());
  }
  return out;
}

namespace detail {

void RequireReadableRegularFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw IoError(path + ": cannot open: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw IoError(path + ": not a regular file (a folder, FIFO or device cannot be an image)");
}

}  // namespace detail
}  // namespace brdf::image_io
