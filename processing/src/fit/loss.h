// The losses of brdf/fit/fit.h per sample and channel, and the costs of a material over a
// fit's samples in doubles (private to brdf_fit).
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include "brdf/core/models.h"
#include "brdf/fit/fit.h"
#include "fit_data.h"

namespace brdf::processing::detail {

constexpr double kCbrtEpsilon = 1e-6;

// The residual of one sample and channel given the model value f (brdf/fit/fit.h lists the
// losses), and its slope dr/df; `target` is the measurement in the loss' own terms (LossTarget,
// once per fit).
inline double LossResidual(FitLoss loss, double f, double target, double cos_in, double sqrt_w,
                           double* slope) {
  switch (loss) {
    case FitLoss::kNgan:
      *slope = sqrt_w * cos_in;
      return sqrt_w * cos_in * (f - target);
    case FitLoss::kLog: {
      const double u = 1.0 + cos_in * f;
      *slope = sqrt_w * cos_in / u;
      return sqrt_w * (std::log(u) - target);
    }
    case FitLoss::kCbrt: {
      const double q = std::cbrt(cos_in * f + kCbrtEpsilon);
      *slope = sqrt_w * cos_in / (3.0 * q * q);
      return sqrt_w * (q - target);
    }
  }
  *slope = 0;
  return 0;
}

inline double LossTarget(FitLoss loss, double m, double cos_in) {
  switch (loss) {
    case FitLoss::kNgan:
      return m;
    case FitLoss::kLog:
      return std::log1p(cos_in * m);
    case FitLoss::kCbrt:
      return std::cbrt(cos_in * m + kCbrtEpsilon);
  }
  return m;
}

// What the residuals need of a sample besides the model's geometry.
struct LossSample {
  double sqrt_w, cos_in;
  std::array<double, 3> target;
};

// ½ Σ r² over `samples`, or with robust_scale b > 0 the Cauchy cost ½ Σ b²·ln(1 + r²/b²).
double Cost(const std::vector<FitSample>& samples, const Material& m, FitLoss loss,
            double robust_scale = 0);

// The Cauchy scale b: options.robust_scale, or 1.4826 × the median |r| at `start` (the
// normal distribution's σ from its median absolute deviation), never below 1e-12.
double RobustScale(const std::vector<FitSample>& samples, const Material& start,
                   const FitOptions& options);

}  // namespace brdf::processing::detail
