// Opening a brdf-view source: brdf::sources::OpenForView (brdf/sources/open.h), the toolchain's
// one way of opening files, turned into what the window takes. This file never decides a file's
// format or reads it itself.
#pragma once

#include <string>

#include "brdf/core/error.h"
#include "brdf/viewer/app.h"

namespace brdf::view_tool {

// Opens `path_or_name` (a file, or the name of a material in the virtual sample library; a file
// of that name wins). Never throws: a failure comes back as LoadedSource::error (one line,
// naming the file).
viewer::LoadedSource OpenViewSource(const std::string& path_or_name);

// What the user can do about an error, in brdf-view's words ("; use --force to overwrite it"),
// for the remedies its sources and outputs carry; empty for any other.
std::string RemedyText(const Remedy& remedy);

}  // namespace brdf::view_tool
