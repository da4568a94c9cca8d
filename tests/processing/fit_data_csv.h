// The samples a fit used, written for the NumPy/SciPy oracles (tests/python/robust_fit_oracle.py,
// tests/python/engine_fit_oracle.py; the columns bench/fit/scipy_baseline.py's load() reads).
//
// Columns: the shading geometry, the measured RGB and cosθin the fit used, the library's own
// √weight (sqrt_w: the oracles compare it, never use it) and each sample's slice. The oracles
// compute the cell solid angles themselves from θout = acos(n·v) and the slice (brdf/fit/fit.h:
// the solid angle of a sample's cell on the grid, per slice from its θout rows and the number
// of φout samples in each row, normalised to sum 1).
#pragma once

#include <filesystem>
#include <fstream>

#include "fit_data.h"  // private to brdf_fit: the exact samples a fit uses

namespace brdf::processing::testing {

inline void WriteFitData(const std::filesystem::path& path, const FitData& data) {
  std::ofstream out(path);
  out.precision(17);
  out << "n_dot_l,n_dot_v,n_dot_h,v_dot_h,l_dot_v,v_dot_r,m_r,m_g,m_b,cos_in,sqrt_w,slice\n";
  for (const FitSample& s : data.samples)
    out << s.g.n_dot_l << ',' << s.g.n_dot_v << ',' << s.g.n_dot_h << ',' << s.g.v_dot_h << ','
        << s.g.l_dot_v << ',' << s.g.v_dot_r << ',' << s.m[0] << ',' << s.m[1] << ',' << s.m[2]
        << ',' << s.cos_in << ',' << s.sqrt_w << ',' << s.slice << '\n';
}

}  // namespace brdf::processing::testing
