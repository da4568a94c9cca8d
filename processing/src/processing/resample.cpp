#include "brdf/processing/resample.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "slice_interpolator.h"

namespace brdf::processing {
namespace {

constexpr double kThetaInTolDeg = 1e-3;
// Texels 1° from the nadir are 0.017 away from the axis; rounding puts the nadir ~1e-16 away.
constexpr double kNadirRadius2 = 1e-18;

std::string Who(const Measurement& m) {
  return m.metadata.sample_name.empty() ? "measurement"
                                        : "measurement '" + m.metadata.sample_name + "'";
}

// Slice indices in ascending θin, checked against docs/design.md §5's θin,k = k·Δin (only distinct
// when !uniform; *delta_in is then 0).
std::vector<std::size_t> ThetaInOrder(const Measurement& m, bool uniform, double* delta_in) {
  if (m.slices.empty()) throw InvalidArgument(Who(m) + " has no slices; cannot build a LUT");
  std::vector<std::size_t> order(m.slices.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  for (std::size_t i : order) detail::CheckSliceThetaIn(m.slices[i], i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return m.slices[a].theta_in_deg < m.slices[b].theta_in_deg;
  });
  std::string list;
  for (std::size_t i : order)
    list += (list.empty() ? "" : ", ") + NumberText(m.slices[i].theta_in_deg);
  const auto fail = [&](const std::string& why) {
    throw InvalidArgument(Who(m) +
                          ": the LUT needs incidence angles θin,k = k·Δin starting at 0° "
                          "(docs/design.md §5), got θin = " +
                          list + "°: " + why);
  };
  for (std::size_t k = 1; k < order.size(); ++k)
    if (m.slices[order[k]].theta_in_deg - m.slices[order[k - 1]].theta_in_deg <= kThetaInTolDeg)
      fail("duplicate incidence angle " + NumberText(m.slices[order[k]].theta_in_deg) +
           "° (slices " + std::to_string(order[k - 1]) + " and " + std::to_string(order[k]) + ")");
  *delta_in = 0.0;
  if (!uniform) return order;
  const double first = m.slices[order.front()].theta_in_deg;
  if (std::fabs(first) > kThetaInTolDeg) fail("the first is not 0°");
  *delta_in = 0.0;
  if (order.size() == 1) return order;
  const double delta =
      (m.slices[order.back()].theta_in_deg - first) / static_cast<double>(order.size() - 1);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const double expected = static_cast<double>(k) * delta;
    if (std::fabs(m.slices[order[k]].theta_in_deg - expected) > kThetaInTolDeg)
      fail("the steps are not uniform (expected " + NumberText(expected) + "° as number " +
           std::to_string(k + 1) + " in ascending order)");
  }
  *delta_in = delta;
  return order;
}

}  // namespace

std::string_view InterpolationMethodName(InterpolationMethod method) {
  switch (method) {
    case InterpolationMethod::kRegularGrid:
      return "regular-grid";
    case InterpolationMethod::kScattered:
      return "scattered";
  }
  return "unknown";
}

void ResampleOptions::Validate() const {
  beyond.Validate();
  if (neighbours < 4 || neighbours > 64)
    throw InvalidArgument("resample option neighbours must be in [4, 64], got " +
                          std::to_string(neighbours));
}

namespace {

// FindLutInputProblems's checks: the θin list's, then (when `samples`) the samples'.
std::vector<LutInputProblem> FindProblems(const Measurement& m, const ResampleOptions& options,
                                          bool samples) {
  using Kind = LutInputProblem::Kind;
  std::vector<LutInputProblem> out;
  const auto add = [&](Kind kind, int slice, std::string message) {
    LutInputProblem p;
    p.kind = kind;
    p.slice = slice;
    if (slice >= 0) p.theta_in_deg = m.slices[static_cast<std::size_t>(slice)].theta_in_deg;
    p.message = std::move(message);
    out.push_back(std::move(p));
    return &out.back();
  };
  if (m.slices.empty()) {
    add(Kind::kNoSlices, -1, "no slices");
    return out;
  }
  const auto name = [&](std::size_t i) {
    return "slice " + std::to_string(i) + " (θin = " + NumberText(m.slices[i].theta_in_deg) + "°)";
  };
  bool angles_ok = true;
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    const Slice& s = m.slices[i];
    if (!(s.theta_in_deg >= 0.0 && s.theta_in_deg < 90.0)) {
      add(Kind::kThetaInOutOfRange, static_cast<int>(i),
          name(i) + ": θin must be in [0°, 90°) for a reflection measurement");
      angles_ok = false;
    } else if (!std::isfinite(s.phi_in_deg)) {
      add(Kind::kThetaInOutOfRange, static_cast<int>(i), name(i) + ": φin is not a finite number");
      angles_ok = false;
    }
  }
  if (angles_ok) {
    try {
      double delta = 0;
      ThetaInOrder(m, options.require_uniform_theta_in, &delta);
    } catch (const InvalidArgument& e) {
      const std::string text = e.what();
      const std::string prefix = Who(m) + ": ";
      add(text.find("duplicate") != std::string::npos ? Kind::kDuplicateThetaIn
                                                      : Kind::kThetaInNotUniform,
          -1, text.compare(0, prefix.size(), prefix) == 0 ? text.substr(prefix.size()) : text);
    }
  }
  if (!samples) return out;
  float theta_b = 0;
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    const Slice& s = m.slices[i];
    struct Defect {
      std::string what;
      std::size_t count = 0, first = 0;
    };
    std::vector<Defect> defects;
    std::size_t valid = 0, invalid = 0;
    const std::optional<double> allowance =
        options.check_measured_values ? std::optional<double>(detail::NegativeAllowance(s))
                                      : std::nullopt;
    for (std::size_t n = 0; n < s.samples.size(); ++n) {
      const Sample& x = s.samples[n];
      if (x.flags & kFlagInvalid) {
        ++invalid;
        continue;
      }
      if (const char* d = detail::SampleDefect(x, allowance)) {
        auto it = std::find_if(defects.begin(), defects.end(),
                               [&](const Defect& e) { return e.what == d; });
        if (it == defects.end())
          defects.push_back({d, 1, n});
        else
          ++it->count;
        continue;
      }
      ++valid;
      theta_b = std::max(theta_b, std::fabs(x.theta_out_deg));
    }
    for (const Defect& d : defects) {
      const Sample& x = s.samples[d.first];
      const std::string values = "θout " + NumberText(x.theta_out_deg) + "°, φout " +
                                 NumberText(x.phi_out_deg) + "°, rgb " + NumberText(x.rgb[0]) +
                                 " " + NumberText(x.rgb[1]) + " " + NumberText(x.rgb[2]);
      LutInputProblem* p =
          add(Kind::kBadSamples, static_cast<int>(i),
              name(i) + ": " + std::to_string(d.count) + " sample" + (d.count == 1 ? "" : "s") +
                  " with " + d.what + " (first: sample " + std::to_string(d.first) + ", " + values +
                  "); a sample without a usable value must be flagged invalid");
      p->sample_count = d.count;
      p->first_sample = d.first;
    }
    if (valid == 0 && defects.empty())
      add(Kind::kNoValidSample, static_cast<int>(i),
          name(i) + ": no valid sample (" + std::to_string(s.samples.size()) + " samples, " +
              std::to_string(invalid) + " flagged invalid); cannot interpolate");
  }
  if (out.empty() && !(theta_b > 0.0f))
    add(Kind::kDegenerateRange, -1,
        "every valid sample is at θout = 0° (measured range θout 0°–0°): there is nothing to "
        "interpolate or extrapolate from");
  return out;
}

}  // namespace

std::vector<LutInputProblem> FindLutInputProblems(const Measurement& m,
                                                  const ResampleOptions& options) {
  return FindProblems(m, options, true);
}

std::vector<LutInputProblem> FindThetaInProblems(const Measurement& m,
                                                 const ResampleOptions& options) {
  return FindProblems(m, options, false);
}

Lut BuildLut(const Measurement& measurement, const ExtrapolationParams& params,
             const ResampleOptions& options, ResampleReport* report) {
  params.Validate();
  options.Validate();
  if (const std::vector<LutInputProblem> problems = FindLutInputProblems(measurement, options);
      !problems.empty())
    throw InvalidArgument(Who(measurement) + ": " + problems.front().message);
  double delta_in = 0;
  const std::vector<std::size_t> order =
      ThetaInOrder(measurement, options.require_uniform_theta_in, &delta_in);
  const int k_slices = static_cast<int>(order.size());

  std::vector<std::unique_ptr<detail::SliceInterpolator>> slices(order.size());
  const auto build_slice = [&](std::size_t k) {
    slices[k] = std::make_unique<detail::SliceInterpolator>(measurement.slices[order[k]], order[k],
                                                            options);
  };
  if (options.parallel && order.size() > 1) {
    tbb::parallel_for(std::size_t{0}, order.size(), build_slice);
  } else {
    for (std::size_t k = 0; k < order.size(); ++k) build_slice(k);
  }
  double theta_b = 0;
  for (const auto& s : slices) theta_b = std::max(theta_b, s->report().max_theta_out_deg);
  for (const auto& s : slices) s->PrepareHorizon(theta_b);
  const double factor_90 = ExtrapolationFactor(90.0, theta_b, params);

  Lut lut;
  lut.Resize(order.size());
  for (int k = 0; k < k_slices; ++k)
    lut.theta_in_deg[static_cast<std::size_t>(k)] =
        options.require_uniform_theta_in
            ? k * delta_in
            : measurement.slices[order[static_cast<std::size_t>(k)]].theta_in_deg;

  // Texel directions ω_d at texel centres (θd, φd) = (j·1°, i·1°); column 360 is copied from
  // column 0 afterwards so the seam is bit-identical.
  constexpr int kW = Lut::kWidth, kH = Lut::kHeight, kCols = kW - 1;
  std::vector<double> sin_t(kH), cos_t(kH), sin_p(kCols), cos_p(kCols);
  for (int j = 0; j < kH; ++j) {
    sin_t[static_cast<std::size_t>(j)] = std::sin(DegToRad(j * Lut::kTexelDeg));
    cos_t[static_cast<std::size_t>(j)] = std::cos(DegToRad(j * Lut::kTexelDeg));
  }
  for (int i = 0; i < kCols; ++i) {
    sin_p[static_cast<std::size_t>(i)] = std::sin(DegToRad(i * Lut::kTexelDeg));
    cos_p[static_cast<std::size_t>(i)] = std::cos(DegToRad(i * Lut::kTexelDeg));
  }
  // Rows 0 and 180 are single directions each (sin(π) is not exactly 0 in floating point).
  sin_t[0] = 0.0;
  sin_t[kH - 1] = 0.0;

  // The texel's value from its outgoing direction (ω_out, θout, φout) per docs/design.md §5 and §6.
  const auto texel_value = [&](const detail::SliceInterpolator& slice, const Vec3& w_out,
                               double theta_out, double phi_out) {
    Rgb v;
    if (w_out.z <= 0.0) {  // at or below the horizon: the 90° value at this φout
      // Straight down (the nadir) every φout meets, and rounding noise would pick one at
      // random: like the pole of a measurement, the nadir takes the mean over all φout.
      const bool nadir = w_out.x * w_out.x + w_out.y * w_out.y < kNadirRadius2;
      v = nadir ? slice.HorizonMean() : slice.Horizon(phi_out);
      for (double& c : v) c *= factor_90;
    } else if (theta_out <= theta_b) {
      v = slice.At(theta_out, phi_out, w_out);
    } else {
      const double f = ExtrapolationFactor(theta_out, theta_b, params);
      v = slice.Horizon(phi_out);
      for (double& c : v) c *= f;
    }
    return v;
  };
  const auto do_row = [&](int row) {
    const int k = row / kH, j = row % kH;
    const detail::SliceInterpolator& slice = *slices[static_cast<std::size_t>(k)];
    const SpecularFrame frame =
        SpecularFrame::FromThetaInDeg(lut.theta_in_deg[static_cast<std::size_t>(k)]);
    const double st = sin_t[static_cast<std::size_t>(j)], ct = cos_t[static_cast<std::size_t>(j)];
    float* out = lut.Texel(k, j, 0);
    const auto store = [out](int i, const Rgb& v) {
      for (int c = 0; c < 3; ++c)
        out[i * 3 + c] = static_cast<float>(v[static_cast<std::size_t>(c)]);
    };
    // S(θin) keeps the xz-plane, so columns i and 360 − i are mirror images (y → −y): the same
    // θout and φout → 360° − φout. The angles are computed once per mirror pair.
    for (int i = 0; i <= kCols / 2; ++i) {
      const Vec3 w_d{st * cos_p[static_cast<std::size_t>(i)],
                     st * sin_p[static_cast<std::size_t>(i)], ct};
      const Vec3 w_out = frame.FromSpecular(w_d);
      const double phi_out = RadToDeg(PhiOf(w_out));
      const double theta_out = w_out.z > 0.0 ? RadToDeg(ThetaOf(w_out)) : 90.0;
      store(i, texel_value(slice, w_out, theta_out, phi_out));
      if (i == 0 || i == kCols / 2) continue;
      const Vec3 w_mirror{w_out.x, -w_out.y, w_out.z};
      const double phi_mirror = phi_out > 0.0 ? 360.0 - phi_out : 0.0;
      store(kCols - i, texel_value(slice, w_mirror, theta_out, phi_mirror));
    }
    for (int c = 0; c < 3; ++c) out[kCols * 3 + c] = out[c];
  };
  const int rows = k_slices * kH;
  if (options.parallel) {
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, 8), [&](const tbb::blocked_range<int>& r) {
      for (int row = r.begin(); row < r.end(); ++row) do_row(row);
    });
  } else {
    for (int row = 0; row < rows; ++row) do_row(row);
  }

  if (report) {
    report->theta_b_deg = theta_b;
    report->delta_in_deg = delta_in;
    report->extrapolation = params;
    report->slices.clear();
    for (const auto& s : slices) report->slices.push_back(s->report());
  }
  if (options.beyond.method != BeyondMethod::kClamp)
    return ExtendBeyondMeasured(lut, theta_b, options.beyond, report ? &report->beyond : nullptr);
  if (report) {
    report->beyond = BeyondReport{};
    report->beyond.measured_theta_in_deg = lut.theta_in_deg;
  }
  return lut;
}

}  // namespace brdf::processing
