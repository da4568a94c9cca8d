// The samples a fit used, written for the NumPy/SciPy oracles (tests/python/robust_fit_oracle.py,
// tests/python/engine_fit_oracle.py; the columns bench/fit/scipy_baseline.py's load() reads).
//
// Columns: the shading geometry, the measured RGB and cosθin the fit used, the library's own
// √weight (sqrt_w: the oracles compare it, never use it) and each sample's slice. The oracles
// compute the cell solid angles themselves from θout = acos(n·v) and the slice (brdf/fit/fit.h:
// the solid angle of a sample's cell on the grid, per slice from its θout rows and the number
// of φout samples in each row, normalised to sum 1).
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "fit_data.h"  // private to brdf_fit: the exact samples a fit uses
#include "test_support.h"

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

// Runs tests/python/SCRIPT on `dir` with Debian's python3 (BRDF_PYTHON3) and returns the JSON it
// printed; a failed run is a test failure (the oracle is required, never skipped) and nullopt.
// Checks the one figure every fit oracle reports: the fit's own √weights are the cells' solid
// angles the oracle computed from the grid.
inline std::optional<nlohmann::json> RunFitOracle(const std::string& script,
                                                  const std::filesystem::path& dir) {
  const std::string cmd = std::string(BRDF_PYTHON3) + " " + BRDF_SOURCE_DIR + "/tests/python/" +
                          script + " '" + dir.string() + "'";
  const brdf::test::CommandOutput oracle = brdf::test::RunCommand(cmd);
  if (oracle.status != 0) {
    ADD_FAILURE() << cmd << " failed (needs /usr/bin/python3 with numpy and SciPy: "
                  << "tools/install-deps.sh)\n"
                  << oracle.out;
    return std::nullopt;
  }
  nlohmann::json want = nlohmann::json::parse(oracle.out);
  EXPECT_LT(want["weight_difference"].get<double>(), 1e-9)
      << "the fit's sample weights are not the cells' solid angles";
  return want;
}

}  // namespace brdf::processing::testing
