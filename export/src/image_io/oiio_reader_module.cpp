// libbrdf_oiio_reader.so: the only code of the toolchain that links OpenImageIO. Loaded by
// ReadRgbImage on its first call (read_rgb_image.cpp); see brdf/image_io/image_io.h.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <exception>
#include <string>
#include <type_traits>
#include <vector>

#include "brdf/core/lazy_module.h"
#include "oiio_module_abi.h"

BRDF_DEFINE_MODULE_ABI()

namespace {

using brdf::image_io::RgbImage;
using brdf::image_io::detail::OiioReadStatus;

OiioReadStatus Read(const char* path, RgbImage* image, std::string* position, std::string* expected,
                    std::string* got) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    // OIIO does not tell "unknown format" from "damaged" apart; both mean the content is not a
    // readable image (the file itself was checked to exist and be regular).
    *position = "header";
    *expected = "an image OpenImageIO can read (EXR, Radiance HDR, PNG, TIFF, JPEG, ...)";
    *got = OIIO::geterror();
    if (got->empty()) *got = "an unknown or damaged format";
    return OiioReadStatus::kBadContent;
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.depth != 1 || spec.nchannels < 1 ||
      static_cast<unsigned long long>(spec.width) * static_cast<unsigned long long>(spec.height) >
          brdf::image_io::kMaxReadPixels) {
    *position = "header";
    *expected = "a 2D image of 1 to " + std::to_string(brdf::image_io::kMaxReadPixels) +
                " pixels with at least one channel";
    *got = std::to_string(spec.width) + " × " + std::to_string(spec.height) + " × " +
           std::to_string(spec.depth) + " pixels, " + std::to_string(spec.nchannels) + " channels";
    return OiioReadStatus::kBadContent;
  }
  const int used = spec.nchannels >= 3 ? 3 : 1;
  const std::size_t pixels = static_cast<std::size_t>(spec.width) * spec.height;
  std::vector<float> values(pixels * used);
  if (!in->read_image(0, 0, 0, used, OIIO::TypeDesc::FLOAT, values.data())) {
    *position = "pixel data";
    *expected = "complete pixel data";
    *got = in->geterror();
    return OiioReadStatus::kBadContent;
  }
  image->width = spec.width;
  image->height = spec.height;
  if (used == 3) {
    image->rgb = std::move(values);
  } else {
    image->rgb.resize(pixels * 3);
    for (std::size_t p = 0; p < pixels; ++p) std::fill_n(&image->rgb[3 * p], 3, values[p]);
  }
  return OiioReadStatus::kOk;
}

}  // namespace

BRDF_MODULE_ENTRY OiioReadStatus brdf_oiio_read_rgb(const char* path, RgbImage* image,
                                                    std::string* error, std::string* position,
                                                    std::string* expected, std::string* got) {
  try {
    return Read(path, image, position, expected, got);
  } catch (const std::bad_alloc&) {
    *error = "not enough memory to read the image";
    return OiioReadStatus::kCannotOpen;
  } catch (const std::exception& e) {
    *position = "content";
    *expected = "an image OpenImageIO can read";
    *got = e.what();
    return OiioReadStatus::kBadContent;
  }
}

static_assert(
    std::is_same_v<decltype(brdf_oiio_read_rgb), brdf::image_io::detail::OiioReadFunction>,
    "the exported entry point must match its declaration in oiio_module_abi.h");
