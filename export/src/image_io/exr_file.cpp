// EXR through OpenEXR's C++ API (no OpenImageIO), see brdf/image_io/image_io.h.
#include <sys/stat.h>

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cerrno>
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
    // OpenEXR's own words ("Cannot read image file "F". Early end of file: read 1 out of 4
    // requested bytes.") are the best description of the damage it found; the sentence that
    // repeats the file name is dropped, since the message starts with it already.
    std::string why = e.what();
    const std::string named = "\"" + path + "\". ";
    if (const std::size_t at = why.find(named); at != std::string::npos)
      why = why.substr(at + named.size());
    throw FormatError(path, "EXR content", "a readable OpenEXR image", why);
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
