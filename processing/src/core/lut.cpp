#include "brdf/core/lut.h"

#include <algorithm>
#include <cmath>

#include "brdf/core/geometry.h"
#include "brdf/core/lut_brdf.h"

namespace brdf {
namespace {

// Texel-space position of a normalised coordinate, GPU style: x = u·N − 0.5, clamped so
// that both taps stay inside [0, N − 1] (clamp-to-edge).
struct Taps {
  int i0, i1;
  float t;
};

inline Taps LinearTaps(double u, int n) {
  const double x = u * n - 0.5;
  const double fl = std::floor(x);
  int i0 = static_cast<int>(fl);
  float t = static_cast<float>(x - fl);
  int i1 = i0 + 1;
  i0 = std::clamp(i0, 0, n - 1);
  i1 = std::clamp(i1, 0, n - 1);
  return {i0, i1, t};
}

}  // namespace

double Lut::DeltaInDeg() const {
  return theta_in_deg.size() >= 2 ? theta_in_deg[1] - theta_in_deg[0] : 0.0;
}

std::array<float, 3> Lut::SampleTrilinear(double u, double v, double w) const {
  std::array<float, 3> out{};
  if (texels.empty()) return out;
  const Taps tu = LinearTaps(u, kWidth), tv = LinearTaps(v, kHeight), tw = LinearTaps(w, slices());
  // The eight texels' offsets once for the three channels (the hot loop of eval_deg and the
  // previews); each channel is filtered as a GPU filters: along u, then v, then w.
  const float* t = texels.data();
  const std::size_t row00 = Index(tw.i0, tv.i0, 0), row01 = Index(tw.i0, tv.i1, 0),
                    row10 = Index(tw.i1, tv.i0, 0), row11 = Index(tw.i1, tv.i1, 0);
  const std::size_t x0 = 3 * static_cast<std::size_t>(tu.i0),
                    x1 = 3 * static_cast<std::size_t>(tu.i1);
  const auto bilinear = [&](std::size_t top_row, std::size_t bottom_row, int c) {
    const float a = t[top_row + x0 + c], b = t[top_row + x1 + c];
    const float d = t[bottom_row + x0 + c], e = t[bottom_row + x1 + c];
    const float top = a + (b - a) * tu.t, bottom = d + (e - d) * tu.t;
    return top + (bottom - top) * tv.t;
  };
  for (int c = 0; c < 3; ++c) {
    const float s0 = bilinear(row00, row01, c), s1 = bilinear(row10, row11, c);
    out[c] = s0 + (s1 - s0) * tw.t;
  }
  return out;
}

double Lut::SliceCoordinate(double theta_in) const {
  const double delta = DeltaInDeg();
  if (theta_in_deg.size() < 2 || !(delta > 0)) return 0.0;
  bool uniform = true;
  for (std::size_t k = 0; k < theta_in_deg.size() && uniform; ++k)
    uniform =
        std::fabs(theta_in_deg[k] - (theta_in_deg.front() + static_cast<double>(k) * delta)) <=
        1e-9 * std::max(1.0, std::fabs(theta_in_deg[k]));
  if (uniform) return (theta_in - theta_in_deg.front()) / delta;
  // Piecewise linear between neighbouring entries; beyond the ends, extended with the end
  // intervals' spacing (the sampler clamps anyway).
  const auto upper = std::upper_bound(theta_in_deg.begin(), theta_in_deg.end(), theta_in);
  std::size_t i = static_cast<std::size_t>(upper - theta_in_deg.begin());
  i = std::clamp<std::size_t>(i, 1, theta_in_deg.size() - 1);
  const double a = theta_in_deg[i - 1], b = theta_in_deg[i];
  return static_cast<double>(i - 1) + (theta_in - a) / (b - a);
}

bool Lut::ExchangesLightAndView(double theta_in, double theta_out_deg) const {
  if (theta_in_deg.empty()) return false;
  const double lo = theta_in_deg.front(), hi = theta_in_deg.back();
  const auto outside = [&](double t) { return std::max({lo - t, t - hi, 0.0}); };
  const double d_in = outside(theta_in);
  return d_in > kThetaInToleranceDeg && outside(theta_out_deg) < d_in;
}

std::array<float, 3> Lut::SampleAngles(double theta_in, double theta_out_deg,
                                       double phi_out_deg) const {
  if (ExchangesLightAndView(theta_in, theta_out_deg))
    return SampleTexture(theta_out_deg, theta_in, -phi_out_deg);
  return SampleTexture(theta_in, theta_out_deg, phi_out_deg);
}

std::array<float, 3> Lut::SampleTexture(double theta_in, double theta_out_deg,
                                        double phi_out_deg) const {
  const std::array<double, 3> c = TextureCoordinates(theta_in, theta_out_deg, phi_out_deg);
  return SampleTrilinear(c[0], c[1], c[2]);
}

std::array<double, 3> Lut::TextureCoordinates(double theta_in, double theta_out_deg,
                                              double phi_out_deg) const {
  const Vec3 w_out = SphericalDirectionDeg(theta_out_deg, phi_out_deg);
  const SpecularFrame frame = SpecularFrame::FromThetaInDeg(theta_in);
  return TextureCoordinatesFrame(frame.cos_m, frame.sin_m, SliceCoordinate(theta_in), w_out.x,
                                 w_out.y, w_out.z);
}

std::array<float, 3> Lut::SampleTextureFrame(double cos_in, double sin_in, double k, double x,
                                             double y, double z) const {
  const std::array<double, 3> c = TextureCoordinatesFrame(cos_in, sin_in, k, x, y, z);
  return SampleTrilinear(c[0], c[1], c[2]);
}

std::array<double, 3> Lut::TextureCoordinatesFrame(double cos_in, double sin_in, double k, double x,
                                                   double y, double z) const {
  const Vec3 w_d = SpecularFrame{cos_in, sin_in}.ToSpecular({x, y, z});
  const double theta_d = RadToDeg(ThetaOf(w_d));
  const double phi_d = RadToDeg(PhiOf(w_d));
  const double u = (phi_d / kTexelDeg + 0.5) / kWidth;
  const double v = (theta_d / kTexelDeg + 0.5) / kHeight;
  const double w = (k + 0.5) / slices();
  return {u, v, w};
}

Rgb LutBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return {0.0, 0.0, 0.0};
  const double theta_in_deg = RadToDeg(ThetaOf(wi));
  // Isotropic: only φout − φin matters, and the LUT stores the light at φin = 0.
  const double phi_deg = std::hypot(wi.x, wi.y) > 0.0
                             ? WrapDeg360(RadToDeg(PhiOf(wo)) - RadToDeg(PhiOf(wi)))
                             : RadToDeg(PhiOf(wo));
  const std::array<float, 3> f = lut_.SampleAngles(theta_in_deg, RadToDeg(ThetaOf(wo)), phi_deg);
  return {f[0], f[1], f[2]};
}

}  // namespace brdf
