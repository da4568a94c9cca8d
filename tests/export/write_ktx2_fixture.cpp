// Writes the files the node test (tests/node/check_ktx2.mjs) validates with the independent
// ktx-parse package: OUT_DIR/ramp.ktx2 + ramp.json (one LUT) and OUT_DIR/atlas.ktx2 (three
// materials). Texel values are small integers, exact in RGB9E5, so the node script can check
// every decoded texel against the same formula:
//   material m, slice k, row j, column i: (R, G, B) = (i, j, 100·k + m).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "brdf/exporter/atlas.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/sidecar.h"

namespace {

brdf::Lut Ramp(int m) {
  brdf::Lut lut;
  lut.Resize(4);
  lut.theta_in_deg = {0, 20, 40, 60};
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < brdf::Lut::kHeight; ++j)
      for (int i = 0; i < brdf::Lut::kWidth; ++i) {
        float* t = lut.Texel(k, j, i);
        t[0] = static_cast<float>(i);
        t[1] = static_cast<float>(j);
        t[2] = static_cast<float>(100 * k + m);
      }
  return lut;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  try {
    brdf::exporter::TextureMetadata meta;
    meta.name = "ramp";
    meta.source = "write_ktx2_fixture: (R, G, B) = (i, j, 100 k)";
    meta.companion_files = {"ramp.ktx2"};
    const brdf::Lut ramp = Ramp(0);
    const brdf::exporter::PackedVolume packed = brdf::exporter::PackLut(ramp);
    brdf::exporter::WriteKtx2(dir + "/ramp.ktx2", packed, ramp.theta_in_deg, meta);
    brdf::exporter::WriteSidecar(dir + "/ramp.json", packed, ramp.theta_in_deg, meta);
    const std::vector<brdf::Lut> luts = {Ramp(0), Ramp(1), Ramp(2)};
    std::vector<brdf::exporter::AtlasMaterial> materials;
    for (int m = 0; m < 3; ++m)
      materials.push_back({"ramp" + std::to_string(m), &luts[m], "fixture"});
    brdf::exporter::WriteAtlas(dir + "/atlas", materials);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_ktx2_fixture: %s\n", e.what());
    return 1;
  }
  return 0;
}
