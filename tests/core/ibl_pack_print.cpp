// Test driver for tests/python/ibl_albedo_check.py: the IBL pack (brdf/core/ibl_pack.h) of any
// file `brdf eval` opens, through the same brdf::sources::OpenBrdf, printed as its JSON object.
//   ibl_pack_print FILE
#include <cstdio>
#include <exception>

#include "brdf/core/ibl_pack.h"
#include "brdf/sources/open.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FILE\n", argv[0]);
    return 2;
  }
  try {
    const brdf::sources::OpenedSource source = brdf::sources::OpenBrdf(argv[1]);
    std::printf("%s\n", brdf::IblPackJson(brdf::ComputeIblPack(*source.brdf)).c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
