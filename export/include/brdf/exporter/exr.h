// EXR and PNG images of a LUT or an atlas, written through OpenEXR and libpng (brdf::image_io,
// never OpenImageIO; docs/design.md §5, §7).
//
// The 3D texture is laid out flat: the K slices in a grid of C = ceil(√K) columns and
// R = ceil(K/C) rows, row-major, ascending θin, top-left first (4 slices: 2 × 2, 722 × 362
// pixels). Cells past the last slice are black. An atlas puts its whole Cm·361 × Rm·181 slice
// grid in each cell instead (atlas.h). Pixel values are the LUT's floats, not the RGB9E5
// quantised ones, so the EXR is the reference the textures can be compared against.
//
// EXR: channels R, G, B, half or float, ZIP (default) or no compression (half holds values up to
// 65504; larger ones become +inf, whereas the RGB9E5 textures clamp at 65408); the metadata travels
// as string header attributes: "brdf:sidecar" (the full sidecar JSON, or "brdf:atlas" for an atlas
// manifest), "brdf:theta_in_deg" ("0, 20, 40, 60"), "brdf:layout" ("2 x 2 slices, row-major,
// ascending theta_in, top-left first"), "brdf:texel_convention", "brdf:payload_crc32", and
// "Software". Nothing else (no date), so equal LUTs give byte-identical EXRs.
//
// PNG tone map (8-bit sRGB, for looking at, never for data): every channel value v is scaled
// by s = 1 / L99, where L99 is the 99th percentile of the Rec.709 luminance
// L = 0.2126 R + 0.7152 G + 0.0722 B over the pixels with L > 0 (s = 1 when there are none),
// mapped with x ↦ 2x / (1 + x) (Reinhard, doubled, so L99 reaches white and the brighter 1 %
// clips), clamped to [0, 1], encoded with the sRGB transfer function and rounded to 8 bits.
// Peaky specular lobes therefore do not push the diffuse body to black.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/image_io/image_io.h"

namespace brdf::exporter {

using image_io::ExrPixelType;
// ZIP (deflate, 16 scanlines) shrinks a half composite about 7× and a float one about 1.5×
// at two to three times the writing time (bench_export); kNone is the fastest.
using image_io::ExrCompression;

struct ExrOptions {
  // Implicit from a pixel type, so `WriteExr(path, image, ExrPixelType::kHalf, ...)` reads well.
  ExrOptions(ExrPixelType pixel_type = ExrPixelType::kFloat,  // NOLINT(google-explicit-constructor)
             ExrCompression compression_kind = ExrCompression::kZip)
      : type(pixel_type), compression(compression_kind) {}
  ExrPixelType type;
  ExrCompression compression;
};

// Interleaved RGB floats, row-major, row 0 at the top.
using FloatImage = image_io::RgbImage;

// The docs/design.md §5 composite of a LUT (722 × 362 for K = 4). Throws InvalidArgument for an
// unexportable LUT.
FloatImage CompositeImage(const Lut& lut);
// The inverse: the K slices back out of a composite image of the right size.
Lut LutFromComposite(const FloatImage& image, std::vector<double> theta_in_deg);

using image_io::StringAttributes;

// Writes an RGB EXR atomically (a temporary sibling renamed into place) with the "Software"
// attribute and `attributes`. Throws IoError when the file cannot be created or written.
void WriteExr(const std::string& path, const FloatImage& image, const ExrOptions& options,
              const StringAttributes& attributes);
// The composite of a LUT with the sidecar's metadata in its header. `packed` is PackLut(lut)
// (for the checksum); the overload without it packs the LUT itself.
void WriteExrComposite(const std::string& path, const Lut& lut, const PackedVolume& packed,
                       const TextureMetadata& metadata, const ExrOptions& options = {});
void WriteExrComposite(const std::string& path, const Lut& lut, const TextureMetadata& metadata,
                       const ExrOptions& options = {});
// The same with the sidecar text and payload checksum already made (a compressed LUT's).
void WriteExrComposite(const std::string& path, const Lut& lut, const std::string& sidecar_json,
                       std::uint32_t payload_crc32, const ExrOptions& options = {});

// The tone-mapped 8-bit sRGB PNG described above, written atomically.
void WritePng(const std::string& path, const FloatImage& image);
void WritePngComposite(const std::string& path, const Lut& lut);
// The tone map alone (exposed for tests): 8-bit sRGB values, width·height·3.
std::vector<unsigned char> ToneMapForPng(const FloatImage& image);

// image, attributes (every string attribute), pixel_type, compression, Attribute(name).
using ExrFile = image_io::ExrImage;
// Reads an RGB EXR (channels R, G, B) through OpenEXR. Throws IoError / FormatError.
ExrFile ReadExr(const std::string& path);

}  // namespace brdf::exporter
