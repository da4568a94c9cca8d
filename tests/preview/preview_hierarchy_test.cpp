// The environment-map hierarchy of the hierarchical preview (preview/src/
// hierarchical.h, private to brdf_preview). The cells' integrals are checked against a direct
// numerical quadrature written here (midpoint rule over θ and φ, not the closed forms the
// hierarchy uses), their bounding cones against directions sampled over each cell, and the
// solid angles against 4π.
#include "hierarchical.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/preview/preview.h"

namespace brdf::preview::detail {
namespace {

// A map with odd sizes (so the cells at the right and bottom edges of the upper levels are
// clipped) and uneven, deterministic pixel values.
EnvironmentMap UnevenMap(int width, int height) {
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  std::uint64_t x = 0x9e3779b97f4a7c15ull;
  for (float& v : rgb) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    v = static_cast<float>((x >> 40) % 1000) / 250.0f;  // 0 … 4
  }
  return EnvironmentMap(width, height, std::move(rgb), "uneven");
}

double Lum(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// ∫ g(a) da over [a0, a1] by the midpoint rule with n points.
template <class G>
double Midpoint(double a0, double a1, int n, G g) {
  const double h = (a1 - a0) / n;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) sum += g(a0 + (k + 0.5) * h);
  return sum * h;
}

// Per pixel, by quadrature: Ω = ∫∫ sinθ dθ dφ and M/Y = ∫∫ ω sinθ dθ dφ. The integrand is a
// product of a θ and a φ factor, so each factor's integral is taken on its own axis.
struct PixelIntegrals {
  std::vector<double> row_sin, row_sin2, row_sincos;  // per row: ∫ sinθ, ∫ sin²θ, ∫ sinθcosθ
  std::vector<double> col_len, col_cos, col_sin;      // per column: ∫ dφ, ∫ cosφ, ∫ sinφ
  PixelIntegrals(int width, int height) {
    constexpr int kPoints = 4000;
    for (int j = 0; j < height; ++j) {
      const double t0 = j * kPi / height, t1 = (j + 1) * kPi / height;
      row_sin.push_back(Midpoint(t0, t1, kPoints, [](double t) { return std::sin(t); }));
      row_sin2.push_back(
          Midpoint(t0, t1, kPoints, [](double t) { return std::sin(t) * std::sin(t); }));
      row_sincos.push_back(
          Midpoint(t0, t1, kPoints, [](double t) { return std::sin(t) * std::cos(t); }));
    }
    for (int i = 0; i < width; ++i) {
      const double p0 = i * 2.0 * kPi / width, p1 = (i + 1) * 2.0 * kPi / width;
      col_len.push_back(p1 - p0);
      col_cos.push_back(Midpoint(p0, p1, kPoints, [](double p) { return std::cos(p); }));
      col_sin.push_back(Midpoint(p0, p1, kPoints, [](double p) { return std::sin(p); }));
    }
  }
};

TEST(PreviewHierarchy, CellIntegralsMatchQuadrature) {
  const int w0 = 37, h0 = 19;
  const EnvironmentMap map = UnevenMap(w0, h0);
  const MapHierarchy hierarchy(map, 4, 3);
  ASSERT_GE(hierarchy.levels(), 4);
  const PixelIntegrals q(w0, h0);
  for (int level = 0; level < hierarchy.levels(); ++level) {
    const int span = 1 << level;
    EXPECT_EQ(hierarchy.width(level), (w0 + span - 1) / span);
    EXPECT_EQ(hierarchy.height(level), (h0 + span - 1) / span);
    double total_solid_angle = 0.0;
    for (int j = 0; j < hierarchy.height(level); ++j)
      for (int i = 0; i < hierarchy.width(level); ++i) {
        double e[3] = {0, 0, 0}, m[3] = {0, 0, 0}, y = 0, solid_angle = 0;
        for (int b = j * span; b < std::min((j + 1) * span, h0); ++b)
          for (int a = i * span; a < std::min((i + 1) * span, w0); ++a) {
            const float* px = map.Pixel(a, b);
            const double omega = q.row_sin[b] * q.col_len[a];
            solid_angle += omega;
            for (int c = 0; c < 3; ++c) e[c] += px[c] * omega;
            y += Lum(px) * omega;
            m[0] += Lum(px) * q.row_sin2[b] * q.col_cos[a];
            m[1] += Lum(px) * q.row_sin2[b] * q.col_sin[a];
            m[2] += Lum(px) * q.row_sincos[b] * q.col_len[a];
          }
        total_solid_angle += solid_angle;
        const MapHierarchy::Cell& cell = hierarchy.At(level, i, j);
        // Stored as floats: a relative 1e-6 is float rounding plus the quadrature's error.
        SCOPED_TRACE("level " + std::to_string(level) + " cell " + std::to_string(i) + ", " +
                     std::to_string(j));
        EXPECT_NEAR(cell.solid_angle, solid_angle, 1e-6 * solid_angle);
        EXPECT_NEAR(cell.luminance, y, 1e-6 * y);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(cell.radiance_solid_angle[c], e[c], 1e-6 * e[c] + 1e-12);
        // |M| ≤ Y, so Y sets the scale of every component.
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(cell.luminance_moment[c], m[c], 1e-6 * y);
        const double length = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(cell.centroid[c], m[c] / length, 1e-5);
      }
    EXPECT_NEAR(total_solid_angle, 4.0 * kPi, 1e-9) << "level " << level;
  }
}

TEST(PreviewHierarchy, BoundingConesHoldTheirCellsTightly) {
  const int w0 = 37, h0 = 19;
  const EnvironmentMap map = UnevenMap(w0, h0);  // outlives the hierarchy, which reads it
  const MapHierarchy hierarchy(map, 4, 2);
  for (int level = 0; level < hierarchy.levels(); ++level) {
    const int span = 1 << level;
    for (int j = 0; j < hierarchy.height(level); ++j)
      for (int i = 0; i < hierarchy.width(level); ++i) {
        const double t0 = std::min(j * span, h0) * kPi / h0;
        const double t1 = std::min((j + 1) * span, h0) * kPi / h0;
        const double p0 = std::min(i * span, w0) * 2.0 * kPi / w0;
        const double p1 = std::min((i + 1) * span, w0) * 2.0 * kPi / w0;
        const MapHierarchy::Cell& cell = hierarchy.At(level, i, j);
        SCOPED_TRACE("level " + std::to_string(level) + " cell " + std::to_string(i) + ", " +
                     std::to_string(j));
        const Vec3 centre = SphericalDirection(0.5 * (t0 + t1), 0.5 * (p0 + p1));
        EXPECT_NEAR(cell.axis[0], centre.x, 1e-6);
        EXPECT_NEAR(cell.axis[1], centre.y, 1e-6);
        EXPECT_NEAR(cell.axis[2], centre.z, 1e-6);
        const double radius = std::atan2(cell.sin_radius, cell.cos_radius);
        EXPECT_NEAR(cell.sin_radius * cell.sin_radius + cell.cos_radius * cell.cos_radius, 1.0,
                    1e-6);
        // The farthest of a 33 × 33 grid of directions over the cell, edges included.
        double farthest = 0.0;
        constexpr int kGrid = 32;
        for (int a = 0; a <= kGrid; ++a)
          for (int b = 0; b <= kGrid; ++b) {
            const Vec3 w =
                SphericalDirection(t0 + (t1 - t0) * a / kGrid, p0 + (p1 - p0) * b / kGrid);
            farthest = std::max(farthest, std::acos(std::clamp(Dot(w, centre), -1.0, 1.0)));
          }
        // Within the documented margin (1 % + 1e-5 rad) of the farthest point. A cone is capped
        // at 90°, which SideOf() reads as always straddling the horizon: only cells wider than a
        // hemisphere (this small map's top levels) reach it.
        const double wanted = farthest * 1.01 + 1e-5;
        if (wanted < 0.5 * kPi) {
          EXPECT_GE(radius, farthest);
          EXPECT_LE(radius, wanted + 1e-6);
        } else {
          EXPECT_NEAR(radius, 0.5 * kPi, 1e-6);
        }
      }
  }
}

}  // namespace
}  // namespace brdf::preview::detail
