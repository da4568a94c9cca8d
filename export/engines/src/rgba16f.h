// Private: the RGBA16F volume DDS streamed into a staged file (rgba16f.cpp).
#pragma once

#include "brdf/exporter/packed_volume.h"
#include "staged_files.h"

namespace brdf::engines::detail {

// The RGBA16F volume DDS streamed into `w`: header, then the texels converted chunk by chunk
// (no copy of the whole payload in memory). EncodeRgba16fDds's bytes.
void WriteRgba16fDds(StagedFiles::Writer& w, const exporter::PackedVolume& volume);

}  // namespace brdf::engines::detail
