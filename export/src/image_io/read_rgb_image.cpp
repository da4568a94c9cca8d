// ReadRgbImage: the OpenImageIO reader, loaded on first use (brdf/core/lazy_module.h).
#include <cctype>
#include <fstream>
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

bool EndsWithHdr(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".hdr";
}

bool StartsWithRadianceMagic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[2] = {0, 0};
  in.read(magic, 2);
  return in && magic[0] == '#' && magic[1] == '?';
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
  // A Radiance HDR file: where its layout is damaged, in its own terms (damage.cpp).
  if (EndsWithHdr(path) || StartsWithRadianceMagic(path))
    if (const auto damage = detail::LocateRadianceDamage(path))
      throw FormatError(path, damage->position, damage->expected, damage->got);
  throw FormatError(path, position, expected, got);
}

bool OpenImageIoLoaded() { return OiioModule().loaded(); }

}  // namespace brdf::image_io
