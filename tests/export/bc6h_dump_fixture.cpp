// Test fixture: writes every texel of a texture (.ktx2 / .dds) as the library decodes it (for a
// BC6H file: exactly as a GPU's texelFetch returns it) to a raw file of little-endian float32,
// depth × height × width × 3 (x fastest). tests/python/bc6h_check.py compares them with its
// own decoder.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "brdf/core/file_util.h"
#include "brdf/exporter/texture_file.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bc6h_dump_fixture TEXTURE OUT.raw\n");
    return 2;
  }
  try {
    const brdf::exporter::LoadedTexture t = brdf::exporter::ReadTextureFile(argv[1]);
    std::string out;
    for (int z = 0; z < t.volume.depth; ++z)
      for (int y = 0; y < t.volume.height; ++y)
        for (int x = 0; x < t.volume.width; ++x)
          for (const float v : t.TexelValue(x, y, z))
            out.append(reinterpret_cast<const char*>(&v), sizeof v);
    brdf::WriteFileAtomically(argv[2], out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
