// Test driver for tests/python/rgl_oracle.py: evaluates an RGL file with brdf::RglBrdf at
// direction pairs read from a file and writes f_r, so the NumPy oracle can compare.
//   rgl_eval_points FILE.bsdf PAIRS OUT
// PAIRS: n × 6 little-endian float64 (wi.xyz, wo.xyz); OUT: n × 3 float64 (f_r RGB, 1/sr).
#include <bit>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "brdf/core/file_util.h"
#include "brdf/core/rgl.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s FILE.bsdf PAIRS OUT\n", argv[0]);
    return 2;
  }
  try {
    const brdf::RglBrdf brdf = brdf::RglBrdf::Load(argv[1]);
    const std::vector<std::uint8_t> in = brdf::ReadFileBytes(argv[2], 1u << 30);
    brdf::ByteReader r(in.data(), in.size(), argv[2]);
    std::string out;
    while (r.remaining() > 0) {
      brdf::Vec3 wi, wo;
      wi.x = r.F64("wi.x");
      wi.y = r.F64("wi.y");
      wi.z = r.F64("wi.z");
      wo.x = r.F64("wo.x");
      wo.y = r.F64("wo.y");
      wo.z = r.F64("wo.z");
      for (const double v : brdf.Eval(wi, wo))
        brdf::AppendU64(out, std::bit_cast<std::uint64_t>(v));
    }
    brdf::WriteFileAtomically(argv[3], out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
