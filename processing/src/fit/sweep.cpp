// The sweep's shape grids and closed-form colour solve (sweep.h).
#include "sweep.h"

#include <algorithm>
#include <cmath>

namespace brdf::processing::detail {

std::vector<double> ShapeGrid(const ParameterInfo& p) {
  if (p.name == "n") return {1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 10000, 30000};
  if (p.name == "alpha")
    return {0.005, 0.01, 0.02, 0.035, 0.05, 0.07, 0.1, 0.14, 0.2, 0.28, 0.4, 0.56, 0.8, 1.0};
  // roughness / smoothness sliders in [0, 1]
  std::vector<double> grid;
  for (int i = 0; i <= 20; ++i) grid.push_back(0.025 + 0.95 * i / 20.0);
  return grid;
}

double SumsCost(const Sums& s, double a, double b) {
  return 0.5 * (s.mm - 2 * (a * s.am + b * s.bm) + a * a * s.aa + 2 * a * b * s.ab + b * b * s.bb);
}
std::pair<double, double> SolveBox(const Sums& s, bool two) {
  auto cost = [&](double a, double b) {
    return s.mm - 2 * (a * s.am + b * s.bm) + a * a * s.aa + 2 * a * b * s.ab + b * b * s.bb;
  };
  auto clamp01 = [](double v) { return std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0); };
  if (!two) return {clamp01(s.aa > 0 ? s.am / s.aa : 0), 0.0};
  std::vector<std::pair<double, double>> candidates;
  const double det = s.aa * s.bb - s.ab * s.ab;
  if (det > 1e-300 * std::max(1.0, s.aa * s.bb)) {
    const double a = (s.am * s.bb - s.bm * s.ab) / det;
    const double b = (s.bm * s.aa - s.am * s.ab) / det;
    if (a >= 0 && a <= 1 && b >= 0 && b <= 1) return {a, b};
  }
  for (double a : {0.0, 1.0})
    candidates.push_back({a, clamp01(s.bb > 0 ? (s.bm - a * s.ab) / s.bb : 0)});
  for (double b : {0.0, 1.0})
    candidates.push_back({clamp01(s.aa > 0 ? (s.am - b * s.ab) / s.aa : 0), b});
  auto best = candidates.front();
  for (const auto& c : candidates)
    if (cost(c.first, c.second) < cost(best.first, best.second)) best = c;
  return best;
}

}  // namespace brdf::processing::detail
