// Test driver for tests/python/rgl_oracle.py: evaluates an RGL file with brdf::RglBrdf at
// direction pairs read from a file and writes f_r, so the NumPy oracle can compare.
//   rgl_eval_points FILE.bsdf PAIRS OUT [--tabulated]
// --tabulated: the file's tabulated form at its default settings (RglTabulatedBrdf, what the
// preview's quadrature evaluates) instead of the exact evaluator.
// PAIRS: n × 6 little-endian float64 (wi.xyz, wo.xyz); OUT: n × 3 float64 (f_r RGB, 1/sr).
#include <bit>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "brdf/core/file_util.h"
#include "brdf/core/rgl.h"

int main(int argc, char** argv) {
  const bool tabulated = argc == 5 && std::string(argv[4]) == "--tabulated";
  if (argc != 4 && !tabulated) {
    std::fprintf(stderr, "usage: %s FILE.bsdf PAIRS OUT [--tabulated]\n", argv[0]);
    return 2;
  }
  try {
    const brdf::RglBrdf exact = brdf::RglBrdf::Load(argv[1]);
    std::unique_ptr<brdf::RglTabulatedBrdf> table;
    if (tabulated) {
      table = exact.Tabulate(brdf::RglTabulationSettings{});
      if (!table) {
        std::fprintf(stderr, "%s: no tabulated form (more than one phi_i)\n", argv[1]);
        return 1;
      }
    }
    const brdf::BrdfSource& brdf = table ? static_cast<const brdf::BrdfSource&>(*table) : exact;
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
