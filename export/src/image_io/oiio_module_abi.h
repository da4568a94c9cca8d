// The entry point of libbrdf_oiio_reader.so, shared by the module and its loader
// (read_rgb_image.cpp). Changing it needs no version bump: both sides are built together and
// LazyModule refuses a module from another build.
#pragma once

#include <string>

#include "brdf/image_io/image_io.h"

namespace brdf::image_io::detail {

inline constexpr const char* kOiioModuleFile = "libbrdf_oiio_reader.so";
inline constexpr const char* kOiioReadEntry = "brdf_oiio_read_rgb";

enum class OiioReadStatus : int { kOk = 0, kCannotOpen = 1, kBadContent = 2 };

// Reads `path` into `*image` as described for ReadRgbImage. On failure returns the status and
// puts one line (without the path) into `*error`, for which `*position`, `*expected` and `*got`
// are filled when the status is kBadContent. Never throws.
using OiioReadFunction = OiioReadStatus(const char* path, RgbImage* image, std::string* error,
                                        std::string* position, std::string* expected,
                                        std::string* got);

}  // namespace brdf::image_io::detail
