// ReadRgbImage: the OpenImageIO reader, loaded on first use (brdf/core/lazy_module.h).
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/lazy_module.h"
#include "brdf/image_io/image_io.h"
#include "image_io_pvt.h"
#include "oiio_module_abi.h"

namespace brdf::image_io {
namespace {

LazyModule& OiioModule() {
  static LazyModule module(detail::kOiioModuleFile, "reading images through OpenImageIO");
  return module;
}

}  // namespace

RgbImage ReadRgbImage(const std::string& path) {
  detail::RequireReadableRegularFile(path);
  auto* read = OiioModule().Entry<detail::OiioReadFunction>(detail::kOiioReadEntry);
  RgbImage image;
  std::string error, position, expected, got;
  switch (read(path.c_str(), &image, &error, &position, &expected, &got)) {
    case detail::OiioReadStatus::kOk:
      return image;
    case detail::OiioReadStatus::kCannotOpen:
      throw IoError(path + ": " + error);
    case detail::OiioReadStatus::kBadContent:
      break;
  }
  throw FormatError(path, position, expected, got);
}

bool OpenImageIoLoaded() { return OiioModule().loaded(); }

}  // namespace brdf::image_io
