// The deterministic sweep's pieces shared by every model (private to brdf_fit): the grids
// of the shape parameter and the closed-form colour solve of each candidate.
#pragma once

#include <utility>
#include <vector>

#include "brdf/core/models.h"

namespace brdf::processing::detail {

// The sweep's values of a shape parameter (n, α, or a roughness / smoothness slider).
std::vector<double> ShapeGrid(const ParameterInfo& p);

// Bounded least squares of m ≈ a·A + b·B for (a, b) ∈ [0, 1]² from the normal-equation sums.
struct Sums {
  double aa = 0, ab = 0, bb = 0, am = 0, bm = 0, mm = 0;
};
// ½ Σ (w·(m − a·A − b·B))² from the sums.
double SumsCost(const Sums& s, double a, double b);
// (a, b) minimising SumsCost; b stays 0 unless `two`.
std::pair<double, double> SolveBox(const Sums& s, bool two);

struct Candidate {
  Material material;
  double cost = 0;
};

}  // namespace brdf::processing::detail
