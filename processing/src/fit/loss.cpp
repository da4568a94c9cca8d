// The losses per sample in doubles, and the Cauchy scale chosen from the data (loss.h).
#include "loss.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace brdf::processing::detail {

namespace {

// The residual of one sample and channel (brdf/fit/fit.h lists the losses).
double Residual(FitLoss loss, double f, double m, double cos_in, double sqrt_w) {
  switch (loss) {
    case FitLoss::kNgan:
      return sqrt_w * cos_in * (f - m);
    case FitLoss::kLog:
      return sqrt_w * (std::log(1.0 + cos_in * f) - std::log1p(cos_in * m));
    case FitLoss::kCbrt:
      return sqrt_w * (std::cbrt(cos_in * f + kCbrtEpsilon) - std::cbrt(cos_in * m + kCbrtEpsilon));
  }
  return 0;
}

double MedianAbsResidual(const std::vector<FitSample>& samples, const Material& m, FitLoss loss) {
  std::vector<double> r;
  r.reserve(samples.size() * 3);
  for (const FitSample& s : samples) {
    const std::array<double, 3> f = models::EvaluateRgb(m.model, s.g, m.values.data());
    for (int c = 0; c < 3; ++c)
      r.push_back(std::fabs(Residual(loss, f[c], s.m[c], s.cos_in, s.sqrt_w)));
  }
  if (r.empty()) return 0;
  auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  return *mid;
}

}  // namespace

double Cost(const std::vector<FitSample>& samples, const Material& m, FitLoss loss,
            double robust_scale) {
  const double b2 = robust_scale * robust_scale;
  double sum = 0;
  for (const FitSample& s : samples) {
    const std::array<double, 3> f = models::EvaluateRgb(m.model, s.g, m.values.data());
    for (int c = 0; c < 3; ++c) {
      const double r = Residual(loss, f[c], s.m[c], s.cos_in, s.sqrt_w);
      sum += robust_scale > 0 ? b2 * std::log1p(r * r / b2) : r * r;
    }
  }
  return 0.5 * sum;
}

double RobustScale(const std::vector<FitSample>& samples, const Material& start,
                   const FitOptions& options) {
  const double b = options.robust_scale > 0
                       ? options.robust_scale
                       : 1.4826 * MedianAbsResidual(samples, start, options.loss);
  return std::max(b, 1e-12);
}

}  // namespace brdf::processing::detail
