#include "brdf/processing/measurement_brdf.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "brdf/core/error.h"
#include "slice_interpolator.h"

namespace brdf::processing {

struct MeasurementBrdf::Impl {
  std::vector<double> theta_in;  // ascending
  std::vector<std::unique_ptr<internal::SliceInterpolator>> slices;
  double theta_b = 0;
  ExtrapolationParams params;

  Rgb Slice(std::size_t k, double theta_out, double phi_out) const {
    return internal::SliceValue(*slices[k], theta_b, params, theta_out, phi_out);
  }
};

MeasurementBrdf::MeasurementBrdf(const Measurement& measurement, const ExtrapolationParams& params,
                                 const ResampleOptions& options, std::string name)
    : name_(name.empty() ? measurement.metadata.sample_name : std::move(name)) {
  params.Validate();
  options.Validate();
  if (measurement.slices.empty())
    throw InvalidArgument("measurement '" + name_ + "' has no slices; nothing to evaluate");
  std::vector<std::size_t> order(measurement.slices.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  for (std::size_t i : order) internal::CheckSliceThetaIn(measurement.slices[i], i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return measurement.slices[a].theta_in_deg < measurement.slices[b].theta_in_deg;
  });
  auto impl = std::make_shared<Impl>();
  impl->params = params;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const double t = measurement.slices[order[k]].theta_in_deg;
    if (k > 0 && t - impl->theta_in.back() < 1e-6) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "two slices with θin = %.9g°", t);
      throw InvalidArgument("measurement '" + name_ + "': " + buf);
    }
    impl->theta_in.push_back(t);
    impl->slices.push_back(std::make_unique<internal::SliceInterpolator>(
        measurement.slices[order[k]], order[k], options));
  }
  for (const auto& s : impl->slices)
    impl->theta_b = std::max(impl->theta_b, s->report().max_theta_out_deg);
  for (const auto& s : impl->slices) s->PrepareHorizon(impl->theta_b);
  impl_ = std::move(impl);
}

Rgb MeasurementBrdf::EvalAngles(double theta_in_deg, double theta_out_deg,
                                double phi_out_deg) const {
  const Impl& m = *impl_;
  if (!std::isfinite(theta_in_deg) || !std::isfinite(theta_out_deg) || !std::isfinite(phi_out_deg))
    throw InvalidArgument("MeasurementBrdf: angles must be finite numbers");
  const double theta_out = std::clamp(theta_out_deg, 0.0, 90.0);
  const double phi_out = WrapDeg360(phi_out_deg);
  const std::vector<double>& t = m.theta_in;
  if (theta_in_deg <= t.front()) return m.Slice(0, theta_out, phi_out);
  if (theta_in_deg >= t.back()) return m.Slice(t.size() - 1, theta_out, phi_out);
  const std::size_t hi =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), theta_in_deg) - t.begin());
  const std::size_t lo = hi - 1;
  if (std::fabs(theta_in_deg - t[lo]) <= 1e-6) return m.Slice(lo, theta_out, phi_out);
  if (std::fabs(theta_in_deg - t[hi]) <= 1e-6) return m.Slice(hi, theta_out, phi_out);
  const double w = (theta_in_deg - t[lo]) / (t[hi] - t[lo]);
  const Rgb a = m.Slice(lo, theta_out, phi_out), b = m.Slice(hi, theta_out, phi_out);
  return {a[0] + (b[0] - a[0]) * w, a[1] + (b[1] - a[1]) * w, a[2] + (b[2] - a[2]) * w};
}

Rgb MeasurementBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return {0.0, 0.0, 0.0};
  const Vec3 l = Normalize(wi), v = Normalize(wo);
  const double theta_in = RadToDeg(ThetaOf(l));
  // At normal incidence φin is undefined; any value is right for an isotropic material.
  const double phi_in = (l.x == 0.0 && l.y == 0.0) ? 0.0 : RadToDeg(PhiOf(l));
  return EvalAngles(theta_in, RadToDeg(ThetaOf(v)), RadToDeg(PhiOf(v)) - phi_in);
}

std::string MeasurementBrdf::Name() const { return name_; }

double MeasurementBrdf::theta_b_deg() const { return impl_->theta_b; }

std::vector<double> MeasurementBrdf::theta_in_deg() const { return impl_->theta_in; }

}  // namespace brdf::processing
