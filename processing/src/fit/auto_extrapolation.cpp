// --extrapolate auto: the docs/design.md §6 Bézier parameters that follow a fitted model's
// fall-off beyond the last measured θout (brdf/fit/fit.h).
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/fit/fit.h"
#include "brdf/processing/extrapolation.h"

namespace brdf::processing {

namespace {

struct BandPoint {
  double x;   // (θ − θb)/(90° − θb) ∈ (0, 1]
  double g0;  // model at θb, same φout, one channel
  double g;   // model at θ
};

// Σ (g0·(1 + α(p − 1)) − g)² for given l, with p − 1 solved in closed form (p clamped ≥ 0).
std::pair<double, double> BestPForL(const std::vector<BandPoint>& band, double l) {
  double num = 0, den = 0;
  std::vector<double> alpha(band.size());
  for (std::size_t i = 0; i < band.size(); ++i) {
    alpha[i] = BezierB(band[i].x, l);
    const double a = band[i].g0 * alpha[i];
    num += a * (band[i].g - band[i].g0);
    den += a * a;
  }
  const double p = std::max(0.0, den > 0 ? 1.0 + num / den : 1.0);
  double cost = 0;
  for (std::size_t i = 0; i < band.size(); ++i) {
    const double r = band[i].g0 * (1.0 + alpha[i] * (p - 1.0)) - band[i].g;
    cost += r * r;
  }
  return {p, cost};
}

}  // namespace

AutoExtrapolationResult FitExtrapolationToModel(const Measurement& measurement,
                                                const Material& model) {
  AutoExtrapolationResult out;
  double theta_b = 0;
  for (const Slice& s : measurement.slices)
    for (const Sample& x : s.samples)
      if ((x.flags & kFlagInvalid) == 0 && std::isfinite(x.theta_out_deg))
        theta_b = std::max(theta_b, static_cast<double>(x.theta_out_deg));
  out.theta_b_deg = theta_b;
  if (!(theta_b < 90.0) || measurement.slices.empty()) return out;  // nothing to extrapolate

  std::vector<BandPoint> band;
  std::vector<double> thetas;
  for (double t = std::floor(theta_b) + 1.0; t < 90.0; t += 1.0) thetas.push_back(t);
  thetas.push_back(90.0);
  const double m = 90.0 - theta_b;
  for (const Slice& s : measurement.slices) {
    std::set<long> phis;  // φout of the slice, 1e-3° resolution
    for (const Sample& x : s.samples) phis.insert(std::lround(WrapDeg360(x.phi_out_deg) * 1000.0));
    const Vec3 l = SphericalDirectionDeg(s.theta_in_deg, s.phi_in_deg);
    for (const long key : phis) {
      const double phi = static_cast<double>(key) / 1000.0;
      const Rgb g0 = model.Evaluate(l, SphericalDirectionDeg(theta_b, phi));
      for (const double t : thetas) {
        // 90° itself is on the horizon, where every model is 0 by convention: the band's
        // end is evaluated a hair above it.
        const Rgb g = model.Evaluate(l, SphericalDirectionDeg(std::min(t, 89.999), phi));
        for (int c = 0; c < 3; ++c) band.push_back({(t - theta_b) / m, g0[c], g[c]});
      }
    }
  }
  double best_l = 0.5, best_cost = std::numeric_limits<double>::infinity(), best_p = 1.0;
  for (int i = 0; i <= 100; ++i) {
    const double l = i / 100.0;
    const auto [p, cost] = BestPForL(band, l);
    if (cost < best_cost) best_cost = cost, best_l = l, best_p = p;
  }
  // Golden section around the best grid point.
  double lo = std::max(0.0, best_l - 0.01), hi = std::min(1.0, best_l + 0.01);
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 30; ++it) {
    const double a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
    if (BestPForL(band, a).second < BestPForL(band, b).second)
      hi = b;
    else
      lo = a;
  }
  const double l_refined = 0.5 * (lo + hi);
  const auto [p_refined, cost_refined] = BestPForL(band, l_refined);
  if (cost_refined < best_cost) best_cost = cost_refined, best_l = l_refined, best_p = p_refined;
  out.params = {best_p, best_l};
  out.params.Validate();
  const double n = static_cast<double>(std::max<std::size_t>(1, band.size()));
  out.band_rmse = std::sqrt(best_cost / n);
  double clamp = 0;
  for (const BandPoint& b : band) clamp += (b.g0 - b.g) * (b.g0 - b.g);
  out.band_rmse_clamp = std::sqrt(clamp / n);
  return out;
}

AutoExtrapolationResult ChooseExtrapolationAuto(const Measurement& measurement, int threads) {
  FitOptions options;
  options.model = Model::kGgx;
  options.threads = threads;
  FitResult fit = FitMaterial(measurement, options);
  AutoExtrapolationResult out = FitExtrapolationToModel(measurement, fit.material);
  if (Underdetermined(fit.report.samples_used, options.model)) {
    // A fit the data does not determine says nothing about the fall-off beyond θb.
    out.not_used = UnderdeterminedWarning(fit.report.samples_used, options.model) +
                   "; the default extrapolation p = 1, l = 0.5 is used instead";
    out.params = ExtrapolationParams{};
    out.band_rmse = out.band_rmse_clamp;
  }
  out.fit = std::move(fit);
  return out;
}

std::string AutoExtrapolationJson(const AutoExtrapolationResult& result) {
  nlohmann::ordered_json j;
  j["kind"] = "extrapolation-auto";
  j["p"] = result.params.p;
  j["l"] = result.params.l;
  j["theta_b_deg"] = result.theta_b_deg;
  j["method"] =
      "p, l by least squares of the docs/design.md §6 band against the GGX fit between "
      "theta_b and 90 deg";
  j["band_rmse"] = result.band_rmse;
  j["band_rmse_clamp"] = result.band_rmse_clamp;
  if (!result.not_used.empty()) j["fit_not_used"] = result.not_used;
  if (result.fit) j["ggx_fit"] = nlohmann::ordered_json::parse(FittedMaterialToJson(*result.fit));
  return j.dump();
}

}  // namespace brdf::processing
