#include "brdf/viewer/view_source.h"

#include <algorithm>
#include <cmath>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/virtual_capture.h"
#include "brdf/processing/resample.h"
#include "brdf/viewer/lobe.h"

namespace brdf::viewer {
namespace {

int WrapPhiCell(int p) {
  const int r = p % CoverageMap::kPhiCells;
  return r < 0 ? r + CoverageMap::kPhiCells : r;
}

// Marks the 1° cells within (radius_theta, radius_phi) degrees of (theta, phi).
void MarkAround(CoverageMap& map, double theta, double phi, double radius_theta,
                double radius_phi) {
  constexpr double kEps = 1e-6;
  const int t0 = std::max(0, static_cast<int>(std::ceil(theta - radius_theta - kEps)));
  const int t1 = std::min(CoverageMap::kThetaCells - 1,
                          static_cast<int>(std::floor(theta + radius_theta + kEps)));
  if (radius_phi >= 180.0) {
    for (int t = t0; t <= t1; ++t) {
      std::fill_n(map.measured.begin() + t * CoverageMap::kPhiCells, CoverageMap::kPhiCells, 1);
    }
    return;
  }
  const int p0 = static_cast<int>(std::ceil(phi - radius_phi - kEps));
  const int p1 = static_cast<int>(std::floor(phi + radius_phi + kEps));
  for (int t = t0; t <= t1; ++t) {
    for (int p = p0; p <= p1; ++p) {
      map.measured[static_cast<std::size_t>(t) * CoverageMap::kPhiCells + WrapPhiCell(p)] = 1;
    }
  }
}

CoverageMap CoverageOfSlice(const Slice& slice, const processing::SliceResampleReport& report,
                            double theta_b_deg) {
  CoverageMap map;
  map.theta_in_deg = slice.theta_in_deg;
  map.measured.assign(static_cast<std::size_t>(CoverageMap::kThetaCells) * CoverageMap::kPhiCells,
                      0);
  // A sample stands for the directions closer to it than to the next lattice node; for
  // scattered data the typical spacing over the measured cap plays the lattice step.
  double step_theta = report.grid_step_theta_deg;
  double step_phi = report.grid_step_phi_deg;
  const bool regular = report.method == processing::InterpolationMethod::kRegularGrid &&
                       step_theta > 0 && step_phi > 0;
  if (!regular) {
    const double cap_sr = 2.0 * kPi * (1.0 - std::cos(DegToRad(std::max(theta_b_deg, 1.0))));
    const double n = std::max<double>(1.0, static_cast<double>(report.valid_samples));
    step_theta = RadToDeg(std::sqrt(cap_sr / n)) * 1.5;
  }
  for (const Sample& s : slice.samples) {
    if ((s.flags & kFlagInvalid) != 0) continue;
    double theta = s.theta_out_deg;
    double phi = s.phi_out_deg - slice.phi_in_deg;
    if (theta < 0) {
      theta = -theta;
      phi += 180.0;
    }
    phi = WrapDeg360(phi);
    const double radius_theta = std::max(0.5, step_theta / 2.0);
    double radius_phi = 0;
    if (regular) {
      radius_phi = std::max(0.5, step_phi / 2.0);
    } else {
      const double s_theta = std::sin(DegToRad(std::max(theta, 0.5)));
      radius_phi = std::min(180.0, radius_theta / s_theta);
    }
    if (theta < 1e-6) radius_phi = 180.0;  // the pole is one direction for every φ
    MarkAround(map, theta, phi, radius_theta, radius_phi);
  }
  return map;
}

int Severity(Coverage c) { return static_cast<int>(c); }

}  // namespace

const char* CoverageName(Coverage coverage) {
  switch (coverage) {
    case Coverage::kMeasured:
      return "measured";
    case Coverage::kExtrapolated:
      return "extrapolated";
    case Coverage::kUnmeasured:
      return "unmeasured";
  }
  return "?";
}

bool CoverageMap::MeasuredAt(double theta_out_deg, double phi_out_deg) const {
  const int t = std::clamp(static_cast<int>(std::lround(theta_out_deg)), 0, kThetaCells - 1);
  const int p = WrapPhiCell(static_cast<int>(std::lround(WrapDeg360(phi_out_deg))));
  return measured[static_cast<std::size_t>(t) * kPhiCells + p] != 0;
}

Coverage ViewSource::CoverageAt(double theta_in_deg, double theta_out_deg,
                                double phi_out_deg) const {
  if (theta_out_deg > theta_b_deg + 1e-9) return Coverage::kExtrapolated;
  if (coverage.empty() || lut.slices() == 0) return Coverage::kMeasured;
  // The LUT blends slices k and k+1 at the same specular-frame coordinates (θd, φd), which
  // are different outgoing directions in each slice: check each slice at its own direction.
  const double k_real =
      std::clamp(lut.SliceCoordinate(theta_in_deg), 0.0, static_cast<double>(lut.slices() - 1));
  const int k0 = static_cast<int>(std::floor(k_real));
  const int k1 = std::min(k0 + 1, lut.slices() - 1);
  const double frac = k_real - k0;
  const Vec3 w_d = SpecularFrame::FromThetaInDeg(theta_in_deg)
                       .ToSpecular(SphericalDirectionDeg(theta_out_deg, phi_out_deg));
  Coverage worst = Coverage::kMeasured;
  for (int k : {k0, k1}) {
    if (k == k1 && (k1 == k0 || frac < 1e-9)) continue;
    if (k == k0 && frac > 1.0 - 1e-9) continue;
    const Vec3 w_k = SpecularFrame::FromThetaInDeg(lut.theta_in_deg[k]).FromSpecular(w_d);
    const double theta_k = RadToDeg(ThetaOf(w_k));
    Coverage c = Coverage::kMeasured;
    if (coverage[k].filled || theta_k > theta_b_deg + 1e-9) {
      c = Coverage::kExtrapolated;
    } else if (!coverage[k].MeasuredAt(theta_k, RadToDeg(PhiOf(w_k)))) {
      c = Coverage::kUnmeasured;
    }
    if (Severity(c) > Severity(worst)) worst = c;
  }
  return worst;
}

double ViewSource::MaxValue(int channel) const {
  double max_value = 0;
  const Channel ch = static_cast<Channel>(std::clamp(channel, 0, 3));
  for (std::size_t n = 0; n + 2 < lut.texels.size(); n += 3) {
    max_value = std::max(max_value, ChannelValue(&lut.texels[n], ch));
  }
  return max_value;
}

ViewSource ViewSourceFromResampled(const Measurement& measurement, Lut lut,
                                   const processing::ResampleReport& report, std::string name) {
  ViewSource out;
  out.name = std::move(name);
  out.lut = std::move(lut);
  out.theta_b_deg = report.theta_b_deg;
  for (int k = 0; k < out.lut.slices(); ++k) {
    const double theta_in = out.lut.theta_in_deg[k];
    const auto slice =
        std::find_if(measurement.slices.begin(), measurement.slices.end(),
                     [&](const Slice& s) { return std::abs(s.theta_in_deg - theta_in) < 1e-3; });
    const auto rep = std::find_if(report.slices.begin(), report.slices.end(),
                                  [&](const processing::SliceResampleReport& r) {
                                    return std::abs(r.theta_in_deg - theta_in) < 1e-3;
                                  });
    if (slice == measurement.slices.end() && rep == report.slices.end()) {
      CoverageMap filled;  // a slice of the blind-spot fill: nothing measured
      filled.theta_in_deg = theta_in;
      filled.measured.assign(
          static_cast<std::size_t>(CoverageMap::kThetaCells) * CoverageMap::kPhiCells, 0);
      filled.filled = true;
      out.coverage.push_back(std::move(filled));
      continue;
    }
    if (slice == measurement.slices.end() || rep == report.slices.end()) {
      throw InvalidArgument("the measurement has no slice at θin = " + std::to_string(theta_in) +
                            "° although its LUT does");
    }
    out.coverage.push_back(CoverageOfSlice(*slice, *rep, report.theta_b_deg));
  }
  return out;
}

ViewSource ViewSourceFromMeasurement(const Measurement& measurement,
                                     const processing::ExtrapolationParams& params,
                                     std::string name) {
  processing::ResampleOptions options;
  options.beyond.method = processing::kDefaultBeyondMethod;
  options.beyond.subdivisions = processing::kDefaultBeyondSubdivisions;
  processing::ResampleReport report;
  Lut lut = processing::BuildLut(measurement, params, options, &report);
  return ViewSourceFromResampled(measurement, std::move(lut), report, std::move(name));
}

ViewSource ViewSourceFromLut(Lut lut, std::string name, double theta_b_deg) {
  ViewSource out;
  out.name = std::move(name);
  out.lut = std::move(lut);
  out.theta_b_deg = theta_b_deg;
  return out;
}

ViewSource ViewSourceFromBrdf(const BrdfSource& source, std::string name) {
  return ViewSourceFromMeasurement(CaptureNoiseFree(source), {}, std::move(name));
}

}  // namespace brdf::viewer
