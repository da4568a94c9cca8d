#include "brdf/processing/beyond.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/models.h"

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

namespace brdf::processing {
namespace {

constexpr double kGrazingDeg = 89.5;  // the model is read here at and below the horizon
constexpr double kBlendDeg = 5.0;     // half width of the reciprocity/continuation seam
constexpr double kMaxRatio = 16.0;

// Runs body(j) for every texel row j, on TBB's workers (within any enclosing arena's limit).
template <class Body>
void ForRows(const Body& body) {
  tbb::parallel_for(0, Lut::kHeight, [&](int j) { body(j); });
}

struct View {
  double theta_deg, phi_deg;
};

// The view (θout, φout) of texel (j, i) of the slice at θin (θout up to 180°).
View TexelView(double theta_in_deg, int j, int i) {
  const Vec3 w = SpecularFrame::FromThetaInDeg(theta_in_deg)
                     .FromSpecular(SphericalDirectionDeg(j * Lut::kTexelDeg, i * Lut::kTexelDeg));
  return {RadToDeg(ThetaOf(w)), RadToDeg(PhiOf(w))};
}

// GGX one-α parts at a geometry: f = kd/π + f0·a + b per channel.
struct GgxParts {
  double a = 0, b = 0;
};
GgxParts Parts(const ShadingGeometry& g, double alpha) {
  const double a2 = alpha * alpha;
  const double s = models::GgxG1(g.n_dot_l, a2) * models::GgxG1(g.n_dot_v, a2) *
                   models::GgxD(g.n_dot_h, a2) / (4.0 * g.n_dot_l * g.n_dot_v);
  const double p5 = models::Pow5(1.0 - g.v_dot_h);
  return {(1.0 - p5) * s, p5 * s};
}

ShadingGeometry GeometryAt(double theta_in_deg, double theta_out_deg, double phi_out_deg) {
  const Vec3 l = SphericalDirectionDeg(std::min(theta_in_deg, kGrazingDeg), 0.0);
  const Vec3 v = SphericalDirectionDeg(std::min(theta_out_deg, kGrazingDeg), phi_out_deg);
  return ShadingGeometry::Of(l, v);
}

struct FitPoint {
  ShadingGeometry g;
  std::array<double, 3> f;
};

// Weighted least squares of kd, f0 ∈ [0, 1] for one channel: Σ w (kd/π + f0·a + b − f)².
struct Normal {
  double saa = 0, sab = 0, sbb = 0, sa = 0, sb = 0, s = 0;  // Σw·(x_k x_l), Σw·x_k·y, Σw·y²
};
double SolveBounded(const Normal& n, double* kd, double* f0) {
  // Unknowns x = (kd/π coefficient 1/π, f0 coefficient a); cost = xᵀAx − 2xᵀr + s.
  const auto cost = [&](double x, double y) {
    return n.saa * x * x + 2 * n.sab * x * y + n.sbb * y * y - 2 * (n.sa * x + n.sb * y) + n.s;
  };
  double best = HUGE_VAL;
  const auto consider = [&](double x, double y) {
    x = std::clamp(x, 0.0, 1.0);
    y = std::clamp(y, 0.0, 1.0);
    const double c = cost(x, y);
    if (c < best) best = c, *kd = x, *f0 = y;
  };
  const double det = n.saa * n.sbb - n.sab * n.sab;
  if (det > 1e-300)
    consider((n.sa * n.sbb - n.sb * n.sab) / det, (n.sb * n.saa - n.sa * n.sab) / det);
  for (double x : {0.0, 1.0}) consider(x, n.sbb > 0 ? (n.sb - n.sab * x) / n.sbb : 0.0);
  for (double y : {0.0, 1.0}) consider(n.saa > 0 ? (n.sa - n.sab * y) / n.saa : 0.0, y);
  return best;
}

double FitAtAlpha(const std::vector<FitPoint>& pts, const std::array<double, 3>& eps, double alpha,
                  FillModel* out) {
  std::array<Normal, 3> n{};
  for (const FitPoint& p : pts) {
    const GgxParts q = Parts(p.g, alpha);
    const double x = kInvPi;
    for (int c = 0; c < 3; ++c) {
      const double w = 1.0 / ((p.f[c] + eps[c]) * (p.f[c] + eps[c]));
      const double y = p.f[c] - q.b;
      n[c].saa += w * x * x, n[c].sab += w * x * q.a, n[c].sbb += w * q.a * q.a;
      n[c].sa += w * x * y, n[c].sb += w * q.a * y, n[c].s += w * y * y;
    }
  }
  double total = 0;
  for (int c = 0; c < 3; ++c) total += SolveBounded(n[c], &out->kd[c], &out->f0[c]);
  out->alpha = alpha;
  return total;
}

// A fill "model" of kHold is M ≡ 1; of kModel the fitted GGX.
struct Ratio {
  const FillModel* model = nullptr;
  std::array<double, 3> operator()(double ti_new, const View& v_new, double ti_old,
                                   const View& v_old) const {
    if (model == nullptr) return {1.0, 1.0, 1.0};
    const auto a = model->Eval(ti_new, v_new.theta_deg, v_new.phi_deg);
    const auto b = model->Eval(ti_old, v_old.theta_deg, v_old.phi_deg);
    std::array<double, 3> r{};
    for (int c = 0; c < 3; ++c)
      r[c] = b[c] > 1e-30 ? std::clamp(a[c] / b[c], 1.0 / kMaxRatio, kMaxRatio) : 1.0;
    return r;
  }
};

// Slices every `step` degrees from 0 to the last measured one (which are kept as they are).
// A slice θ between measured slices θa < θb, weight t = (θ − θa)/(θb − θa), texel (θd, φd):
//   (1 − t)·f(θa)·M(θ)/M(θa) + t·f(θb)·M(θ)/M(θb)
// with M at each slice's own view of that texel: linear in θin at equal (θd, φd) for M ≡ 1,
// and following the model's change with θin otherwise.
Lut Densify(const Lut& measured, double step, const Ratio& ratio) {
  const double delta = measured.DeltaInDeg();
  const int per = static_cast<int>(std::lround(delta / step));
  if (per <= 1) return measured;
  Lut out;
  out.Resize(static_cast<std::size_t>((measured.slices() - 1) * per + 1));
  for (int k = 0; k < out.slices(); ++k) {
    const double theta = k * step;
    out.theta_in_deg[k] = theta;
    const int a = k / per;
    if (k % per == 0) {
      std::copy_n(measured.Texel(a, 0, 0), static_cast<std::size_t>(Lut::kHeight) * Lut::kWidth * 3,
                  out.Texel(k, 0, 0));
      continue;
    }
    const int b = a + 1;
    const double t = static_cast<double>(k % per) / per;
    const double ta = measured.theta_in_deg[a], tb = measured.theta_in_deg[b];
    ForRows([&](int j) {
      for (int i = 0; i < Lut::kWidth; ++i) {
        const View v = TexelView(theta, j, i);
        const auto ra = ratio(theta, v, ta, TexelView(ta, j, i));
        const auto rb = ratio(theta, v, tb, TexelView(tb, j, i));
        const float* fa = measured.Texel(a, j, i);
        const float* fb = measured.Texel(b, j, i);
        float* dst = out.Texel(k, j, i);
        for (int c = 0; c < 3; ++c)
          dst[c] = static_cast<float>((1.0 - t) * fa[c] * ra[c] + t * fb[c] * rb[c]);
      }
    });
  }
  return out;
}

// Directional albedo per channel of slice k (its upper-hemisphere texels, column 360 left out),
// and the part of it from texels for which `filled` is true.
template <class Filled>
void Albedo(const Lut& lut, int k, Filled filled, std::array<double, 3>* total,
            std::array<double, 3>* fill) {
  *total = {0, 0, 0};
  *fill = {0, 0, 0};
  const double t = lut.theta_in_deg[k];
  for (int j = 0; j < Lut::kHeight; ++j) {
    // The texel's cell: θd ∈ [j − ½, j + ½]° (clipped at the poles), φd ∈ [i − ½, i + ½]°.
    const double dw = (std::cos(DegToRad(std::max(j - 0.5, 0.0))) -
                       std::cos(DegToRad(std::min(j + 0.5, 180.0)))) *
                      DegToRad(Lut::kTexelDeg);
    for (int i = 0; i < Lut::kWidth - 1; ++i) {
      const View v = TexelView(t, j, i);
      if (v.theta_deg >= 90.0) continue;
      const double w = dw * std::cos(DegToRad(v.theta_deg));
      const float* f = lut.Texel(k, j, i);
      const bool is_fill = filled(j, i, v);
      for (int c = 0; c < 3; ++c) {
        (*total)[c] += w * f[c];
        if (is_fill) (*fill)[c] += w * f[c];
      }
    }
  }
}

// Scales the filled texels of slice k so that its albedo is at most 1 per channel.
template <class Filled>
void LimitAlbedo(Lut* lut, int k, Filled filled, BeyondReport* report) {
  std::array<double, 3> total, fill;
  Albedo(*lut, k, filled, &total, &fill);
  for (int c = 0; c < 3; ++c) {
    double albedo = total[c];
    if (total[c] > 1.0 && fill[c] > 0) {
      const double s = std::max(0.0, (1.0 - (total[c] - fill[c])) / fill[c]);
      for (int j = 0; j < Lut::kHeight; ++j)
        for (int i = 0; i < Lut::kWidth; ++i)
          if (filled(j, i, TexelView(lut->theta_in_deg[k], j, i))) lut->Texel(k, j, i)[c] *= s;
      albedo = total[c] - fill[c] + fill[c] * s;
      ++report->albedo_scaled_channels;
    }
    report->max_albedo = std::max(report->max_albedo, albedo);
  }
}

// The fill of `measured` by `ratio` (no validation, no method choice).
Lut Fill(const Lut& measured_in, double theta_b, double max_theta_in, double step,
         const Ratio& ratio, BeyondReport* report) {
  Lut out = measured_in;
  const int k_meas = measured_in.slices();
  const double last = measured_in.theta_in_deg.back();
  // 1. The θout band of the measured slices.
  for (int k = 0; k < k_meas; ++k) {
    const double t = measured_in.theta_in_deg[k];
    if (ratio.model == nullptr) break;  // M ≡ 1: the band stays as it is
    ForRows([&](int j) {
      for (int i = 0; i < Lut::kWidth; ++i) {
        const View v = TexelView(t, j, i);
        if (v.theta_deg <= theta_b) continue;
        const auto r = ratio(t, v, t, View{theta_b, v.phi_deg});
        float* f = out.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) f[c] = static_cast<float>(f[c] * r[c]);
      }
    });
    LimitAlbedo(
        &out, k, [&](int, int, const View& v) { return v.theta_deg > theta_b; }, report);
  }
  // 2. Slices between the measured ones, when the step is finer.
  if (step > 0) {
    out = Densify(out, step, ratio);
    for (double t : out.theta_in_deg)
      if (std::none_of(measured_in.theta_in_deg.begin(), measured_in.theta_in_deg.end(),
                       [&](double m) { return std::fabs(m - t) < 1e-6; }))
        report->inserted_theta_in_deg.push_back(t);
  }
  const int k_meas_step = out.slices();
  const double delta = out.DeltaInDeg();
  const Lut banded = out;  // measured slices with their band: what reciprocity reads
  // 3. New slices beyond the last measured one.
  const int k_total = static_cast<int>(std::floor(max_theta_in / delta + 1e-9)) + 1;
  for (int k = k_meas_step; k < k_total; ++k) {
    const double t = k * delta;
    out.theta_in_deg.push_back(t);
    out.texels.resize(static_cast<std::size_t>(k + 1) * Lut::kHeight * Lut::kWidth * 3);
    ForRows([&](int j) {
      for (int i = 0; i < Lut::kWidth; ++i) {
        const View v = TexelView(t, j, i);
        const double to = std::min(v.theta_deg, 90.0);
        const double w = std::clamp((to - (last - kBlendDeg)) / (2 * kBlendDeg), 0.0, 1.0);
        std::array<double, 3> value{};
        if (w < 1.0) {
          const auto f = banded.SampleTexture(std::min(to, last), std::min(t, 90.0), -v.phi_deg);
          for (int c = 0; c < 3; ++c) value[c] = (1.0 - w) * f[c];
        }
        if (w > 0.0) {
          const View below = TexelView(t - delta, j, i);
          const auto r = ratio(t, v, t - delta, below);
          const float* f = out.Texel(k - 1, j, i);
          for (int c = 0; c < 3; ++c) value[c] += w * f[c] * r[c];
        }
        float* dst = out.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) dst[c] = static_cast<float>(value[c]);
      }
    });
    // Column 360 repeats column 0 (docs/design.md §5).
    for (int j = 0; j < Lut::kHeight; ++j)
      std::copy_n(out.Texel(k, j, 0), 3, out.Texel(k, j, Lut::kWidth - 1));
    LimitAlbedo(
        &out, k, [](int, int, const View&) { return true; }, report);
    report->extrapolated_theta_in_deg.push_back(t);
  }
  return out;
}

LeaveLastSliceOut Validate(const Lut& measured, double theta_b, const Lut& filled) {
  LeaveLastSliceOut v;
  const int k = measured.slices() - 1;
  v.theta_in_deg = measured.theta_in_deg[k];
  const int kf = static_cast<int>(
      std::find_if(filled.theta_in_deg.begin(), filled.theta_in_deg.end(),
                   [&](double t) { return std::fabs(t - v.theta_in_deg) < 1e-6; }) -
      filled.theta_in_deg.begin());
  std::vector<double> got, want;
  for (int j = 0; j < Lut::kHeight; ++j)
    for (int i = 0; i < Lut::kWidth - 1; ++i) {
      if (TexelView(v.theta_in_deg, j, i).theta_deg > theta_b) continue;
      const float* a = filled.Texel(kf, j, i);
      const float* b = measured.Texel(k, j, i);
      got.push_back(double(a[0]) + a[1] + a[2]);
      want.push_back(double(b[0]) + b[1] + b[2]);
    }
  const double floor = 1e-3 * *std::max_element(want.begin(), want.end());
  std::vector<double> e(got.size());
  for (std::size_t n = 0; n < e.size(); ++n)
    e[n] = std::fabs(got[n] - want[n]) / std::max(want[n], floor);
  v.texels = e.size();
  const auto at = [&](double q) {
    std::vector<double> s = e;
    const std::size_t n =
        std::min(s.size() - 1, static_cast<std::size_t>(q * (s.size() - 1) + 0.5));
    std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(n), s.end());
    return s[n];
  };
  v.median = at(0.5);
  v.p90 = at(0.9);
  return v;
}

bool Uniform(const Lut& lut) {
  const double delta = lut.DeltaInDeg();
  if (lut.slices() < 2 || !(delta > 0) || std::fabs(lut.theta_in_deg[0]) > 1e-9) return false;
  for (int k = 0; k < lut.slices(); ++k)
    if (std::fabs(lut.theta_in_deg[k] - k * delta) > 1e-6) return false;
  return true;
}

}  // namespace

std::string_view BeyondMethodName(BeyondMethod method) {
  switch (method) {
    case BeyondMethod::kClamp:
      return "clamp";
    case BeyondMethod::kHold:
      return "hold";
    case BeyondMethod::kModel:
      return "model";
    case BeyondMethod::kAuto:
      return "auto";
  }
  return "clamp";
}

BeyondMethod ParseBeyondMethod(std::string_view text) {
  for (BeyondMethod m :
       {BeyondMethod::kClamp, BeyondMethod::kHold, BeyondMethod::kModel, BeyondMethod::kAuto})
    if (text == BeyondMethodName(m)) return m;
  throw InvalidArgument("--beyond: expected clamp, hold, model or auto, got '" + std::string(text) +
                        "'");
}

void BeyondOptions::Validate() const {
  if (!(max_theta_in_deg > 0.0 && max_theta_in_deg <= 90.0))
    throw InvalidArgument("beyond: the largest extrapolated θin must be in (0°, 90°], got " +
                          std::to_string(max_theta_in_deg));
  if (subdivisions < 1 || subdivisions > 20)
    throw InvalidArgument("beyond: subdivisions of the measured θin step must be in [1, 20], got " +
                          std::to_string(subdivisions));
}

std::array<double, 3> FillModel::Eval(double theta_in_deg, double theta_out_deg,
                                      double phi_out_deg) const {
  const ShadingGeometry g = GeometryAt(theta_in_deg, theta_out_deg, phi_out_deg);
  const GgxParts q = Parts(g, alpha);
  std::array<double, 3> f{};
  for (int c = 0; c < 3; ++c) f[c] = kd[c] * kInvPi + f0[c] * q.a + q.b;
  return f;
}

std::string BeyondReportJson(const BeyondReport& r) {
  using nlohmann::ordered_json;
  ordered_json j;
  j["method"] = std::string(BeyondMethodName(r.used));
  j["requested"] = std::string(BeyondMethodName(r.requested));
  j["measured_theta_in"] = r.measured_theta_in_deg;
  j["extrapolated_theta_in"] = r.extrapolated_theta_in_deg;
  j["inserted_theta_in"] = r.inserted_theta_in_deg;
  j["subdivisions"] = r.subdivisions;
  const auto loo = [](const std::optional<LeaveLastSliceOut>& v) {
    if (!v) return ordered_json(nullptr);
    return ordered_json{{"theta_in", v->theta_in_deg},
                        {"median_relative_error", v->median},
                        {"p90_relative_error", v->p90},
                        {"texels", v->texels}};
  };
  j["leave_last_slice_out"] = loo(r.validation);
  j["leave_last_slice_out_hold"] = loo(r.validation_hold);
  j["leave_last_slice_out_model"] = loo(r.validation_model);
  if (r.model) {
    j["model"] = {{"model", "ggx"},
                  {"kd", r.model->kd},
                  {"f0", r.model->f0},
                  {"alpha", r.model->alpha},
                  {"median_relative_error", r.model->median_relative_error}};
  } else {
    j["model"] = nullptr;
  }
  j["max_albedo"] = r.max_albedo;
  return j.dump();
}

FillModel FitFillModel(const Lut& lut, double theta_b) {
  if (lut.slices() == 0 || lut.texels.empty())
    throw InvalidArgument("FitFillModel: the LUT has no slices");
  std::vector<FitPoint> pts;
  std::array<double, 3> mean{};
  for (int k = 0; k < lut.slices(); ++k) {
    const double t = lut.theta_in_deg[k];
    for (int j = 0; j < Lut::kHeight; ++j) {
      // Every texel row near the peak, every third row and column elsewhere.
      const bool near = j <= 20;
      if (!near && j % 3 != 0) continue;
      for (int i = 0; i < Lut::kWidth - 1; i += near ? 2 : 3) {
        const View v = TexelView(t, j, i);
        if (v.theta_deg > theta_b) continue;
        FitPoint p;
        p.g = GeometryAt(t, v.theta_deg, v.phi_deg);
        const float* f = lut.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) p.f[c] = f[c], mean[c] += f[c];
        pts.push_back(p);
      }
    }
  }
  std::array<double, 3> eps{};
  const double all = (mean[0] + mean[1] + mean[2]) / (3.0 * std::max<std::size_t>(pts.size(), 1));
  for (int c = 0; c < 3; ++c) eps[c] = 0.02 * all + 1e-6;
  FillModel best, trial;
  double best_cost = HUGE_VAL;
  const int n_grid = 36;
  const double lo = std::log(0.005), hi = std::log(1.5);
  int best_n = 0;
  for (int n = 0; n < n_grid; ++n) {
    const double c = FitAtAlpha(pts, eps, std::exp(lo + (hi - lo) * n / (n_grid - 1)), &trial);
    if (c < best_cost) best_cost = c, best = trial, best_n = n;
  }
  // Golden section in log α between the grid neighbours.
  double a = lo + (hi - lo) * std::max(0, best_n - 1) / (n_grid - 1);
  double b = lo + (hi - lo) * std::min(n_grid - 1, best_n + 1) / (n_grid - 1);
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  FillModel m1, m2;
  double f1 = FitAtAlpha(pts, eps, std::exp(x1), &m1), f2 = FitAtAlpha(pts, eps, std::exp(x2), &m2);
  for (int it = 0; it < 24; ++it) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, m2 = m1;
      x1 = b - g * (b - a);
      f1 = FitAtAlpha(pts, eps, std::exp(x1), &m1);
    } else {
      a = x1, x1 = x2, f1 = f2, m1 = m2;
      x2 = a + g * (b - a);
      f2 = FitAtAlpha(pts, eps, std::exp(x2), &m2);
    }
  }
  if (f1 < best_cost) best = m1, best_cost = f1;
  if (f2 < best_cost) best = m2, best_cost = f2;
  std::vector<double> rel;
  rel.reserve(pts.size() * 3);
  for (const FitPoint& p : pts) {
    const GgxParts q = Parts(p.g, best.alpha);
    for (int c = 0; c < 3; ++c) {
      const double m = best.kd[c] * kInvPi + best.f0[c] * q.a + q.b;
      rel.push_back(std::fabs(m - p.f[c]) / std::max(p.f[c], 1e-3));
    }
  }
  if (!rel.empty()) {
    std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(rel.size() / 2),
                     rel.end());
    best.median_relative_error = rel[rel.size() / 2];
  }
  best.texels = pts.size();
  return best;
}

Lut ExtendBeyondMeasured(const Lut& measured, double theta_b, const BeyondOptions& options,
                         BeyondReport* report) {
  options.Validate();
  BeyondReport local;
  BeyondReport& r = report ? *report : local;
  r = BeyondReport{};
  r.requested = options.method;
  r.measured_theta_in_deg = measured.theta_in_deg;
  const double last = measured.theta_in_deg.empty() ? 0.0 : measured.theta_in_deg.back();
  const double step = measured.DeltaInDeg() / options.subdivisions;
  if (options.method == BeyondMethod::kClamp || !Uniform(measured) ||
      !(options.max_theta_in_deg >= last + step - 1e-9))
    return measured;
  r.subdivisions = options.subdivisions;
  const double fill_step = options.subdivisions > 1 ? step : 0.0;

  // Validation: the fill from all slices but the last, read at the last one.
  const bool validate = measured.slices() >= 3;
  Lut head;
  FillModel head_model;
  if (validate) {
    head.theta_in_deg.assign(measured.theta_in_deg.begin(), measured.theta_in_deg.end() - 1);
    head.texels.assign(
        measured.texels.begin(),
        measured.texels.begin() +
            static_cast<std::ptrdiff_t>(head.theta_in_deg.size() * Lut::kHeight * Lut::kWidth * 3));
  }
  const auto validate_with = [&](const Ratio& ratio) {
    BeyondReport scratch;
    const Lut f = Fill(head, theta_b, last, fill_step, ratio, &scratch);
    return Validate(measured, theta_b, f);
  };
  BeyondMethod use = options.method;
  if (validate && (use == BeyondMethod::kHold || use == BeyondMethod::kAuto))
    r.validation_hold = validate_with(Ratio{});
  if (validate && (use == BeyondMethod::kModel || use == BeyondMethod::kAuto)) {
    head_model = FitFillModel(head, theta_b);
    r.validation_model = validate_with(Ratio{&head_model});
  }
  if (use == BeyondMethod::kAuto) {
    use = BeyondMethod::kModel;
    if (r.validation_hold && r.validation_model) {
      const auto key = [](const LeaveLastSliceOut& v) { return std::pair(v.median, v.p90); };
      if (key(*r.validation_hold) < key(*r.validation_model)) use = BeyondMethod::kHold;
    }
  }
  r.used = use;
  r.validation = use == BeyondMethod::kModel ? r.validation_model : r.validation_hold;
  if (use == BeyondMethod::kModel) {
    r.model = FitFillModel(measured, theta_b);
    return Fill(measured, theta_b, options.max_theta_in_deg, fill_step, Ratio{&*r.model}, &r);
  }
  return Fill(measured, theta_b, options.max_theta_in_deg, fill_step, Ratio{}, &r);
}

}  // namespace brdf::processing
