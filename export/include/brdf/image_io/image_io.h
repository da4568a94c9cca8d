// Reading and writing RGB float images without paying for OpenImageIO at start-up.
//
// brdf::image_io is the one place the toolchain touches image files. Its header names only std
// types, and what it links is light:
//   - EXR through OpenEXR directly (WriteExrImage, ReadExrImage): channels R, G, B, half or
//     float, ZIP or no compression, arbitrary string header attributes;
//   - PNG, 8-bit RGB, through libpng (WritePng8);
//   - any other image OpenImageIO can read (.hdr, .exr, .png, .tif, .jpg, …) through
//     ReadRgbImage, which loads OpenImageIO only on its first call, from the module
//     libbrdf_oiio_reader.so (brdf/core/lazy_module.h). A process that never calls it never
//     maps OpenImageIO's ~260 shared libraries.
//
// Pixels are interleaved R, G, B floats, row-major, row 0 at the top of the image, x growing to
// the right. Values are stored as the file holds them, converted to float: EXR and Radiance HDR
// values are linear; 8- and 16-bit files come back as code / (2^bits − 1) WITHOUT undoing their
// transfer function (an sRGB PNG stays sRGB-encoded).
//
// Every function throws brdf::IoError when the file cannot be opened, created or written and
// brdf::FormatError when its content is not what is described here; messages name the file.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace brdf::image_io {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width·height·3

  const float* Pixel(int x, int y) const {
    return &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
  }
  float* Pixel(int x, int y) { return &rgb[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

// The largest image any reader here accepts: 2^27 pixels (16384 × 8192, 1.5 GiB of floats),
// checked against the header before pixels are allocated.
inline constexpr std::size_t kMaxReadPixels = std::size_t{1} << 27;

// Reads the first image of any file OpenImageIO understands as RGB: 1 or 2 channels (grey, grey
// and alpha) become R = G = B = the first channel; 3 or more keep the first three (alpha and
// further channels are dropped). Loads the OpenImageIO module on first use; when the module is
// missing or cannot be loaded the IoError says so in one line.
RgbImage ReadRgbImage(const std::string& path);

// Whether the OpenImageIO module has been loaded in this process (for tests and diagnostics).
bool OpenImageIoLoaded();

enum class ExrPixelType { kHalf, kFloat };
// ZIP: deflate over blocks of 16 scanlines. kNone: raw scanlines.
enum class ExrCompression { kZip, kNone };

using StringAttributes = std::vector<std::pair<std::string, std::string>>;

// Writes `image` as a scanline EXR with channels R, G, B of `pixel_type` (half rounds to
// nearest; values above 65504 become +inf), data and display window (0, 0)–(width−1,
// height−1), and one string attribute per entry of `attributes` (the name as given, e.g.
// "Software" or "brdf:sidecar"). Nothing else is added (no date), so equal inputs give
// byte-identical files. Atomic: a temporary sibling is renamed into place.
// Throws InvalidArgument for an image whose size does not match its pixels.
void WriteExrImage(const std::string& path, const RgbImage& image, ExrPixelType pixel_type,
                   ExrCompression compression, const StringAttributes& attributes);

struct ExrImage {
  RgbImage image;               // R, G, B as float whatever the stored type
  StringAttributes attributes;  // every string attribute of the header, in header order
  ExrPixelType pixel_type = ExrPixelType::kFloat;  // the type of the R channel
  // kZip for ZIP and ZIPS; kNone for no compression and for the kinds this toolchain never
  // writes (RLE, PIZ, PXR24, B44, DWA), which OpenEXR decodes all the same.
  ExrCompression compression = ExrCompression::kNone;
  std::string Attribute(const std::string& name) const;  // "" when absent
};

// Reads a single-part scanline or tiled EXR that has channels R, G and B (in any order, other
// channels are ignored), through OpenEXR. A data window that does not start at (0, 0) is read
// as an image of its own size. Throws FormatError for a missing channel, a file that is not
// EXR, an image larger than kMaxReadPixels or a damaged pixel block.
ExrImage ReadExrImage(const std::string& path);

// Writes 8-bit RGB (`rgb8`: width·height·3 bytes, row 0 at the top) as a PNG with zlib
// compression `zlib_level` (0–9) and one tEXt chunk per entry of `text` (keywords of 1–79
// Latin-1 characters). Atomic like WriteExrImage. `fast`: every row with the Sub filter and
// zlib's run-length strategy instead of libpng's per-row filter choice and the default
// strategy (the batch's contact images: less encoding time for files a few percent larger,
// docs/benchmarks/batch.md).
void WritePng8(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb8, int zlib_level, const StringAttributes& text,
               bool fast = false);

}  // namespace brdf::image_io
