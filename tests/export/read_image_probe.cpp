// Positive control of tests/tools/startup_libraries.py: a process that reads an image through
// brdf::image_io::ReadRgbImage, so that the library detector must see OpenImageIO in it.
// usage: read_image_probe OUT.exr   (writes a 2 × 1 EXR there, reads it back, prints it)
#include <cstdio>
#include <exception>

#include "brdf/image_io/image_io.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: read_image_probe OUT.exr\n");
    return 2;
  }
  try {
    brdf::image_io::RgbImage image;
    image.width = 2;
    image.height = 1;
    image.rgb = {0.25f, 0.5f, 1.0f, 2.0f, 4.0f, 8.0f};
    brdf::image_io::WriteExrImage(argv[1], image, brdf::image_io::ExrPixelType::kFloat,
                                  brdf::image_io::ExrCompression::kNone, {});
    const brdf::image_io::RgbImage back = brdf::image_io::ReadRgbImage(argv[1]);
    for (float v : back.rgb) std::printf("%g ", v);
    std::printf("\n");
    return back.rgb == image.rgb ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "read_image_probe: %s\n", e.what());
    return 1;
  }
}
