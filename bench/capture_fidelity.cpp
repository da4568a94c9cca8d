// Where the preview of a reference-geometry capture departs from the material it was captured
// from (docs/preview.md, "Captures"). Prints, for GGX α = 0.35 and RGL paper_white, the relative
// RMS difference between the preview of an evaluator and the preview of the truth, both by the
// deterministic quadrature with the settings of tests/processing/preview_test.cpp
// (40 × 40 sphere, studio map 96 × 48, one subdivision), over every sphere pixel and over the
// pixels seen within the measured θout = 75°.
//
// The evaluators turn the sources of error on one at a time. "Oracle" evaluators read the truth
// itself at the measured θin (0, 20, 40, 60°), so they have no resampling error:
//   frame      fixed: linear in θin at a fixed ω_out (the former processing::MeasurementBrdf);
//              specular: linear in θin at fixed specular-frame coordinates (docs/design.md §5);
//   beyond 60° truth: the true value (no error from the missing slices);
//              nearest: the 60° slice (at the fixed ω_out or at the same (θd, φd));
//              reciprocal: light and view swapped when the light is the lower of the two
//              (f(ωi, ωo) = f(ωo, ωi)), nearest slice when both are beyond 60°;
//   θout       truth (read up to 89.5°) or held at 75° beyond it (the §6 default p = 1).
// The real evaluator is the capture's float LUT (the `brdf eval` / `brdf preview` path), with
// and without the reciprocity step of Lut::SampleAngles (Lut::SampleTexture alone); the
// fixed-frame oracle with the 60° slice held and θout held at 75° is what the former
// processing::MeasurementBrdf computed (up to its interpolation of the 1° capture grid).
//
//   usage: capture_fidelity [BRDF_DATA_DIR]    (paper_white is read from <dir>/rgl/)
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/lut_brdf.h"
#include "brdf/core/rgl.h"
#include "brdf/preview/preview.h"
#include "brdf/processing/measurement_brdf.h"

namespace {

using namespace brdf;

enum class Frame { kFixed, kSpecular };
enum class Beyond { kTruth, kNearest, kReciprocal };

Vec3 Dir(double theta_deg, double phi_deg) { return SphericalDirectionDeg(theta_deg, phi_deg); }

// S(θm) of docs/design.md §5, written out (its own inverse).
Vec3 S(double theta_m_deg, const Vec3& w) {
  const double c = std::cos(DegToRad(theta_m_deg)), s = std::sin(DegToRad(theta_m_deg));
  return {-c * w.x - s * w.z, -w.y, -s * w.x + c * w.z};
}

class SliceOracle final : public BrdfSource {
 public:
  SliceOracle(const BrdfSource& truth, std::vector<double> theta_in, Frame frame, Beyond beyond,
              double theta_out_cap_deg)
      : truth_(truth),
        theta_in_(std::move(theta_in)),
        frame_(frame),
        beyond_(beyond),
        cap_(theta_out_cap_deg) {}
  std::string Name() const override { return "oracle"; }

  Rgb Eval(const Vec3& wi_in, const Vec3& wo_in) const override {
    if (!(wi_in.z > 0) || !(wo_in.z > 0)) return {0, 0, 0};
    Vec3 wi = wi_in, wo = wo_in;
    const double last = theta_in_.back();
    if (beyond_ == Beyond::kReciprocal && ThetaOf(wi) > DegToRad(last) && wo.z > wi.z)
      std::swap(wi, wo);
    const double ti = RadToDeg(ThetaOf(wi));
    const double phi_in = std::hypot(wi.x, wi.y) > 0 ? RadToDeg(PhiOf(wi)) : 0.0;
    // The view relative to the light at φin = 0.
    const Vec3 v = Dir(RadToDeg(ThetaOf(wo)), RadToDeg(PhiOf(wo)) - phi_in);
    if (ti > last && beyond_ == Beyond::kTruth) return At(ti, v);
    const double t = std::min(ti, last);
    std::size_t hi = 1;
    while (hi + 1 < theta_in_.size() && theta_in_[hi] < t) ++hi;
    const double a = theta_in_[hi - 1], b = theta_in_[hi];
    const double w = std::clamp((t - a) / (b - a), 0.0, 1.0);
    const Rgb fa = At(a, frame_ == Frame::kFixed ? v : S(a, S(ti, v)));
    const Rgb fb = At(b, frame_ == Frame::kFixed ? v : S(b, S(ti, v)));
    return {fa[0] + (fb[0] - fa[0]) * w, fa[1] + (fb[1] - fa[1]) * w, fa[2] + (fb[2] - fa[2]) * w};
  }

 private:
  // The truth with the light at (θin, 0), the view direction's polar angle held at the cap
  // (below the horizon too: the LUT's edge extension).
  Rgb At(double theta_in_deg, const Vec3& v) const {
    const double theta = std::min(RadToDeg(std::acos(std::clamp(v.z, -1.0, 1.0))), cap_);
    const double phi = std::hypot(v.x, v.y) > 0 ? RadToDeg(PhiOf(v)) : 0.0;
    return truth_.Eval(Dir(theta_in_deg, 0), Dir(theta, phi));
  }
  const BrdfSource& truth_;
  std::vector<double> theta_in_;
  Frame frame_;
  Beyond beyond_;
  double cap_;
};

// The LUT read without the reciprocity step (Lut::SampleTexture): the nearest slice beyond
// the measured θin range whatever the view.
class NearestSlice final : public BrdfSource {
 public:
  explicit NearestSlice(const LutBrdf& inner) : lut_(inner.lut()) {}
  std::string Name() const override { return "nearest-slice"; }
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    if (!(wi.z > 0) || !(wo.z > 0)) return {0, 0, 0};
    const double phi = std::hypot(wi.x, wi.y) > 0 ? RadToDeg(PhiOf(wo) - PhiOf(wi)) : 0.0;
    const auto f = lut_.SampleTexture(RadToDeg(ThetaOf(wi)), RadToDeg(ThetaOf(wo)), phi);
    return {f[0], f[1], f[2]};
  }

 private:
  const Lut& lut_;
};

Measurement CaptureOf(const BrdfSource& source, const std::vector<double>& theta_in,
                      int theta_out_max_deg) {
  Measurement meas;
  meas.metadata.sample_name = source.Name();
  for (double ti : theta_in) {
    Slice slice;
    slice.theta_in_deg = ti;
    for (int a = 0; a <= theta_out_max_deg; ++a)
      for (int b = 0; b < 360; ++b) {
        Sample s;
        s.theta_in_deg = static_cast<float>(ti);
        s.theta_out_deg = static_cast<float>(a);
        s.phi_out_deg = static_cast<float>(b);
        const Rgb f = source.Eval(Dir(ti, 0), Dir(a, b));
        for (int c = 0; c < 3; ++c) s.rgb[c] = static_cast<float>(f[c]);
        slice.samples.push_back(s);
      }
    meas.slices.push_back(std::move(slice));
  }
  return meas;
}

struct Differences {
  double all, within75, within60;
};

class Harness {
 public:
  explicit Harness(const BrdfSource& truth) : truth_(truth) {
    o_.width = o_.height = 40;
    o_.estimator = preview::Estimator::kQuadrature;
    o_.quadrature_subdivisions = 1;
    o_.jobs = 2;
    reference_ = preview::RenderPreview(truth, studio_, o_);
  }
  Differences Compare(const BrdfSource& candidate) const {
    preview::PreviewImage a = preview::RenderPreview(candidate, studio_, o_);
    preview::PreviewImage b = reference_;
    Differences d;
    d.all = preview::CompareImages(a, b).relative_rms;
    d.within75 = Within(a, b, 75.0);
    d.within60 = Within(a, b, 60.0);
    return d;
  }

 private:
  // The difference over the pixels whose view direction is within `max_view_deg` of the normal
  // (preview.h's camera: on +x, orthographic, the unit sphere spanning `fill` of the height).
  double Within(preview::PreviewImage a, preview::PreviewImage b, double max_view_deg) const {
    for (int y = 0; y < o_.height; ++y)
      for (int x = 0; x < o_.width; ++x) {
        const double s = ((x + 0.5) / o_.width * 2.0 - 1.0) / o_.camera.fill;
        const double t = (1.0 - (y + 0.5) / o_.height * 2.0) / o_.camera.fill;
        const double r2 = s * s + t * t;
        if (r2 >= 1.0 || RadToDeg(std::acos(std::sqrt(1.0 - r2))) > max_view_deg)
          a.object[y * o_.width + x] = b.object[y * o_.width + x] = 0;
      }
    return preview::CompareImages(a, b).relative_rms;
  }
  const BrdfSource& truth_;
  preview::EnvironmentMap studio_ = preview::EnvironmentMap::Studio(96, 48);
  preview::PreviewOptions o_;
  preview::PreviewImage reference_;
};

void Row(const char* what, const Differences& d) {
  std::printf("  %-58s %7.2f %% %7.2f %% %7.2f %%\n", what, 100 * d.all, 100 * d.within75,
              100 * d.within60);
  std::fflush(stdout);
}

void Decompose(const BrdfSource& truth, const char* title) {
  const std::vector<double> ref = {0, 20, 40, 60};
  const Harness h(truth);
  std::printf("%s\n  %-58s %9s %9s %9s\n", title, "evaluator", "all px", "view≤75°", "view≤60°");
  constexpr double kNoCap = 89.5, kCap = 75.0;
  struct OracleRow {
    const char* what;
    Frame frame;
    Beyond beyond;
    double cap_deg;
  };
  for (const OracleRow& r : {
           OracleRow{"oracle fixed-frame,  truth beyond 60°, θout truth", Frame::kFixed,
                     Beyond::kTruth, kNoCap},
           OracleRow{"oracle specular,     truth beyond 60°, θout truth", Frame::kSpecular,
                     Beyond::kTruth, kNoCap},
           OracleRow{"oracle fixed-frame,  hold 60° slice,   θout truth", Frame::kFixed,
                     Beyond::kNearest, kNoCap},
           OracleRow{"oracle specular,     nearest slice,    θout truth", Frame::kSpecular,
                     Beyond::kNearest, kNoCap},
           OracleRow{"oracle specular,     reciprocal,       θout truth", Frame::kSpecular,
                     Beyond::kReciprocal, kNoCap},
           OracleRow{"oracle specular,     truth beyond 60°, θout held at 75°", Frame::kSpecular,
                     Beyond::kTruth, kCap},
           OracleRow{"oracle fixed-frame,  hold 60° slice,   θout held at 75°", Frame::kFixed,
                     Beyond::kNearest, kCap},
           OracleRow{"oracle specular,     nearest slice,    θout held at 75°", Frame::kSpecular,
                     Beyond::kNearest, kCap},
           OracleRow{"oracle specular,     reciprocal,       θout held at 75°", Frame::kSpecular,
                     Beyond::kReciprocal, kCap},
       })
    Row(r.what, h.Compare(SliceOracle(truth, ref, r.frame, r.beyond, r.cap_deg)));
  // The capture's own evaluation (processing::MeasurementAsBrdf, what `brdf preview` uses).
  const LutBrdf lut = processing::MeasurementAsBrdf(CaptureOf(truth, ref, 75));
  Row("capture LUT (θout ≤ 75°), nearest slice", h.Compare(NearestSlice(lut)));
  Row("capture LUT (θout ≤ 75°), reciprocal", h.Compare(lut));
  const LutBrdf lut89 = processing::MeasurementAsBrdf(CaptureOf(truth, ref, 89));
  Row("capture LUT (θout ≤ 89°), nearest slice", h.Compare(NearestSlice(lut89)));
  Row("capture LUT (θout ≤ 89°), reciprocal", h.Compare(lut89));
  std::vector<double> dense;
  for (int k = 0; k <= 17; ++k) dense.push_back(5.0 * k);
  Row("capture LUT, θin every 5° (0–85°), θout ≤ 75°",
      h.Compare(processing::MeasurementAsBrdf(CaptureOf(truth, dense, 75))));
}

}  // namespace

int main(int argc, char** argv) {
  const std::string data = argc > 1 ? argv[1] : BRDF_DATA_DIR_DEFAULT;
  Material ggx;
  ggx.model = Model::kGgx;
  ggx.name = "ggx_a035";
  ggx.SetParameter(0, {0.35, 0.2, 0.1});
  ggx.SetParameter(1, {0.04, 0.04, 0.04});
  ggx.SetParameter(2, {0.35, 0.35, 0.35});
  Decompose(AnalyticBrdf(ggx), "GGX kd (0.35, 0.2, 0.1), f0 0.04, α 0.35");
  Decompose(RglBrdf::Load(data + "/rgl/paper_white_rgb.bsdf"), "RGL paper_white_rgb.bsdf");
}
