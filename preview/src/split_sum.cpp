// SplitSumLighting (split_sum.h): SH irradiance and the GGX-prefiltered mip pyramid of a map.
#include "split_sum.h"

#include <algorithm>
#include <cmath>

#include "preview_internal.h"

namespace brdf::preview::detail {
namespace {

// The real SH basis up to ℓ = 2 at unit w (the usual constants).
void ShBasis(const Vec3& w, double* y) {
  y[0] = 0.282094791773878;
  y[1] = 0.488602511902920 * w.y;
  y[2] = 0.488602511902920 * w.z;
  y[3] = 0.488602511902920 * w.x;
  y[4] = 1.092548430592079 * w.x * w.y;
  y[5] = 1.092548430592079 * w.y * w.z;
  y[6] = 0.315391565252520 * (3.0 * w.z * w.z - 1.0);
  y[7] = 1.092548430592079 * w.x * w.z;
  y[8] = 0.546274215296040 * (w.x * w.x - w.y * w.y);
}

double RadicalInverse(unsigned bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return static_cast<double>(bits) * 2.3283064365386963e-10;
}

}  // namespace

SplitSumLighting::SplitSumLighting(const EnvironmentMap& map) {
  const int w = map.width(), h = map.height();
  // SH projection: each pixel's exact solid angle, its centre direction.
  for (int j = 0; j < h; ++j) {
    const double t0 = kPi * j / h, t1 = kPi * (j + 1) / h;
    const double solid_angle = (std::cos(t0) - std::cos(t1)) * 2.0 * kPi / w;
    const double theta = 0.5 * (t0 + t1);
    for (int i = 0; i < w; ++i) {
      const float* px = map.Pixel(i, j);
      double y[9];
      ShBasis(SphericalDirection(theta, (i + 0.5) * 2.0 * kPi / w), y);
      for (int k = 0; k < 9; ++k)
        for (int c = 0; c < 3; ++c) sh_[k][c] += px[c] * y[k] * solid_angle;
    }
  }
  // The pyramid: each level averages 2 × 2 texels weighted by their solid angles (∝ the row's
  // cosθ difference), down to 4 × 2 (an odd size keeps its last column/row alone).
  Level base;
  base.width = w;
  base.height = h;
  base.rgb = map.rgb();
  texel_solid_angle_ = 4.0 * kPi / (static_cast<double>(w) * h);
  levels_.push_back(std::move(base));
  while (levels_.back().width > 4 && levels_.back().height > 2) {
    const Level& fine = levels_.back();
    Level coarse;
    coarse.width = (fine.width + 1) / 2;
    coarse.height = (fine.height + 1) / 2;
    coarse.rgb.assign(static_cast<std::size_t>(coarse.width) * coarse.height * 3, 0.0f);
    for (int j = 0; j < coarse.height; ++j)
      for (int i = 0; i < coarse.width; ++i) {
        double sum[3] = {0, 0, 0}, weight = 0.0;
        for (int dj = 0; dj < 2; ++dj) {
          const int fj = 2 * j + dj;
          if (fj >= fine.height) continue;
          const double row =
              std::cos(kPi * fj / fine.height) - std::cos(kPi * (fj + 1) / fine.height);
          for (int di = 0; di < 2; ++di) {
            const int fi = 2 * i + di;
            if (fi >= fine.width) continue;
            const float* px = &fine.rgb[(static_cast<std::size_t>(fj) * fine.width + fi) * 3];
            for (int c = 0; c < 3; ++c) sum[c] += row * px[c];
            weight += row;
          }
        }
        for (int c = 0; c < 3; ++c)
          coarse.rgb[(static_cast<std::size_t>(j) * coarse.width + i) * 3 + c] =
              static_cast<float>(weight > 0.0 ? sum[c] / weight : 0.0);
      }
    levels_.push_back(std::move(coarse));
  }
}

Rgb SplitSumLighting::Irradiance(const Vec3& n) const {
  static constexpr double kBand[9] = {1.0,  2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25,
                                      0.25, 0.25,      0.25,      0.25};  // Â_ℓ/π
  double y[9];
  ShBasis(n, y);
  Rgb e = {0, 0, 0};
  for (int k = 0; k < 9; ++k)
    for (int c = 0; c < 3; ++c) e[c] += kBand[k] * sh_[k][c] * y[k];
  for (double& v : e) v = std::max(0.0, v);
  return e;
}

Rgb SplitSumLighting::Bilinear(const Level& level, double phi, double theta) const {
  const double x = phi * (0.5 * kInvPi) * level.width - 0.5;
  const double y = std::clamp(theta * kInvPi * level.height - 0.5, 0.0, level.height - 1.0);
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const int y1 = std::min(y0 + 1, level.height - 1);
  auto wrap = [&](int i) { return ((i % level.width) + level.width) % level.width; };
  const int xa = wrap(x0), xb = wrap(x0 + 1);
  Rgb out = {0, 0, 0};
  const std::size_t w = static_cast<std::size_t>(level.width);
  const float* p00 = &level.rgb[(y0 * w + xa) * 3];
  const float* p10 = &level.rgb[(y0 * w + xb) * 3];
  const float* p01 = &level.rgb[(y1 * w + xa) * 3];
  const float* p11 = &level.rgb[(y1 * w + xb) * 3];
  for (int c = 0; c < 3; ++c)
    out[c] = (1 - fy) * ((1 - fx) * p00[c] + fx * p10[c]) + fy * ((1 - fx) * p01[c] + fx * p11[c]);
  return out;
}

Rgb SplitSumLighting::Lookup(const Vec3& w, double lod) const {
  const double phi = PhiOf(w), theta = ThetaOf(w);
  const double top = static_cast<double>(levels_.size() - 1);
  lod = std::clamp(lod, 0.0, top);
  const int l0 = static_cast<int>(std::floor(lod));
  const int l1 = std::min(l0 + 1, static_cast<int>(top));
  const double f = lod - l0;
  const Rgb a = Bilinear(levels_[l0], phi, theta);
  if (f == 0.0 || l1 == l0) return a;
  const Rgb b = Bilinear(levels_[l1], phi, theta);
  return {(1 - f) * a[0] + f * b[0], (1 - f) * a[1] + f * b[1], (1 - f) * a[2] + f * b[2]};
}

Rgb SplitSumLighting::Prefiltered(double alpha, const Vec3& r) const {
  const Frame frame = Frame::FromNormal(r);
  const double a2 = alpha * alpha;
  Rgb sum = {0, 0, 0};
  double weight = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double u = (i + 0.5) / kSamples, v = RadicalInverse(static_cast<unsigned>(i));
    const double tan2 = a2 * u / (1.0 - u);
    const double cos_h = 1.0 / std::sqrt(1.0 + tan2);
    const double sin_h = std::sqrt(std::max(0.0, 1.0 - cos_h * cos_h));
    const double phi = 2.0 * kPi * v;
    const double cos_l = 2.0 * cos_h * cos_h - 1.0;  // R·l
    if (cos_l <= 0.0) continue;
    // l = 2(R·h)h − R in the frame of R.
    const Vec3 h = {sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h};
    const Vec3 l_local = {2.0 * cos_h * h.x, 2.0 * cos_h * h.y, 2.0 * cos_h * h.z - 1.0};
    // pdf(l) = D(h)/4 (the sampling density D·cosθh over h, Jacobian 1/(4 R·h)).
    const double d = a2 / (kPi * std::pow(cos_h, 4) * (a2 + tan2) * (a2 + tan2));
    const double sample_solid_angle = 1.0 / (kSamples * 0.25 * d);
    const double lod = 0.5 * std::log2(sample_solid_angle / texel_solid_angle_) + 1.0;
    const Rgb c = Lookup(frame.ToWorld(l_local), lod);
    for (int k = 0; k < 3; ++k) sum[k] += c[k] * cos_l;
    weight += cos_l;
  }
  if (!(weight > 0.0)) return Lookup(r, 0.0);
  return {sum[0] / weight, sum[1] / weight, sum[2] / weight};
}

}  // namespace brdf::preview::detail
