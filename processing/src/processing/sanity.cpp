#include "brdf/processing/sanity.h"

#include <algorithm>
#include <cmath>

#include "brdf/core/geometry.h"

#include <nlohmann/json.hpp>

namespace brdf::processing {
namespace {

constexpr double kThetaStepDeg = 1.0;  // albedo quadrature: midpoint rule, 90 × 180 cells
constexpr double kPhiStepDeg = 2.0;
constexpr double kReciprocityPhiStepDeg = 5.0;
constexpr double kMinEnergyMargin = 0.02;
constexpr double kMatchDeg = 1e-6;  // θin of a LUT slice and of a measured slice agree

double Sum(const std::array<float, 3>& v) { return double(v[0]) + v[1] + v[2]; }

const Slice* MeasuredSlice(const Measurement& m, double theta_in_deg) {
  for (const Slice& s : m.slices)
    if (std::fabs(s.theta_in_deg - theta_in_deg) < kMatchDeg) return &s;
  return nullptr;
}

}  // namespace

SanityReport PhysicalSanity(const Lut& lut, const Measurement& measurement, double theta_b_deg) {
  SanityReport report;
  report.theta_b_deg = theta_b_deg;
  std::vector<double> measured_theta;
  for (const Slice& s : measurement.slices) measured_theta.push_back(s.theta_in_deg);
  const double d_omega = DegToRad(kThetaStepDeg) * DegToRad(kPhiStepDeg);
  for (int k = 0; k < lut.slices(); ++k) {
    SliceSanity s;
    s.theta_in_deg = lut.theta_in_deg[static_cast<std::size_t>(k)];
    const Slice* slice = MeasuredSlice(measurement, s.theta_in_deg);
    s.measured = slice != nullptr;
    for (double t = 0.5 * kThetaStepDeg; t < 90.0; t += kThetaStepDeg) {
      const double w = std::cos(DegToRad(t)) * std::sin(DegToRad(t)) * d_omega;
      std::array<double, 3>& part =
          s.measured && t <= theta_b_deg ? s.albedo_measured : s.albedo_filled;
      for (double p = 0.5 * kPhiStepDeg; p < 360.0; p += kPhiStepDeg) {
        const std::array<float, 3> f = lut.SampleAngles(s.theta_in_deg, t, p);
        for (int c = 0; c < 3; ++c) part[c] += f[c] * w;
      }
    }
    if (s.measured && s.theta_in_deg <= theta_b_deg) {
      std::vector<double> residuals;
      for (double b : measured_theta) {
        if (std::fabs(b - s.theta_in_deg) < kMatchDeg || b > theta_b_deg) continue;
        for (double p = 0; p < 360.0; p += kReciprocityPhiStepDeg) {
          const double f1 = Sum(lut.SampleAngles(s.theta_in_deg, b, p));
          const double f2 = Sum(lut.SampleAngles(b, s.theta_in_deg, p));
          const double mean = 0.5 * (f1 + f2);
          if (mean > 0) residuals.push_back(std::fabs(f1 - f2) / mean);
        }
      }
      s.reciprocity_pairs = residuals.size();
      if (!residuals.empty()) {
        std::sort(residuals.begin(), residuals.end());
        s.reciprocity_median = residuals[residuals.size() / 2];
        s.reciprocity_max = residuals.back();
      }
    }
    s.energy_margin = std::max(kMinEnergyMargin, s.reciprocity_median);
    for (int c = 0; c < 3; ++c)
      s.energy_flag =
          s.energy_flag || s.albedo_measured[c] + s.albedo_filled[c] > 1.0 + s.energy_margin;
    if (slice)
      for (const Sample& sample : slice->samples) {
        s.saturated += (sample.flags & kFlagSaturated) != 0;
        s.below_noise += (sample.flags & kFlagBelowNoiseFloor) != 0;
      }
    report.slices.push_back(s);
  }
  return report;
}

std::string SanityReportJson(const SanityReport& report) {
  using nlohmann::ordered_json;
  const auto finite = [](double v) { return std::isfinite(v) ? ordered_json(v) : ordered_json(); };
  const auto triple = [&](const std::array<double, 3>& v) {
    return ordered_json{finite(v[0]), finite(v[1]), finite(v[2])};
  };
  ordered_json j;
  j["theta_b_deg"] = report.theta_b_deg;
  j["slices"] = ordered_json::array();
  for (const SliceSanity& s : report.slices) {
    std::array<double, 3> total{};
    for (int c = 0; c < 3; ++c) total[c] = s.albedo_measured[c] + s.albedo_filled[c];
    ordered_json e;
    e["theta_in"] = s.theta_in_deg;
    e["measured"] = s.measured;
    e["albedo_measured"] = triple(s.albedo_measured);
    e["albedo_filled"] = triple(s.albedo_filled);
    e["albedo"] = triple(total);
    if (s.reciprocity_pairs > 0)
      e["reciprocity"] = {{"pairs", s.reciprocity_pairs},
                          {"median_relative", finite(s.reciprocity_median)},
                          {"max_relative", finite(s.reciprocity_max)}};
    else
      e["reciprocity"] = nullptr;
    e["energy_margin"] = finite(s.energy_margin);
    e["energy_flag"] = s.energy_flag;
    e["saturated"] = s.saturated;
    e["below_noise_floor"] = s.below_noise;
    j["slices"].push_back(std::move(e));
  }
  return j.dump();
}

}  // namespace brdf::processing
