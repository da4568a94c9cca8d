// Opening a brdf-view source through the toolchain's one way of opening files
// (tools/brdf/sources.h: brdf::cli::ClassifyFile, PrepareMeasurement, OpenExportedTexture,
// OpenEvalSource). Stopgap until those move into the brdf::sources library: this file is the
// only place brdf-view touches them, and it never decides a file's format itself.
#pragma once

#include <string>

#include "brdf/viewer/app.h"

namespace brdf::view_tool {

// Opens `path_or_name` (a file, or the name of a material in the virtual sample library).
// Never throws: a failure comes back as LoadedSource::error (one line, naming the file).
viewer::LoadedSource OpenViewSource(const std::string& path_or_name);

}  // namespace brdf::view_tool
