// Details shared by the image_io sources (not part of the public header).
#pragma once

#include <string>

namespace brdf::image_io::detail {

// Throws IoError unless `path` names an existing regular file, so a FIFO or a device never
// blocks a reader and a folder gets a clear message.
void RequireReadableRegularFile(const std::string& path);

}  // namespace brdf::image_io::detail
