// Small vector helpers and the pieces of brdf_preview shared between its translation units.
// Private to brdf_preview.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/core/models.h"
#include "brdf/core/parallel.h"
#include "brdf/preview/preview.h"

namespace brdf::preview::detail {

inline Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double Length(const Vec3& a) { return std::sqrt(Dot(a, a)); }
inline double Luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }
inline double MaxChannel(const Rgb& c) { return std::fmax(c[0], std::fmax(c[1], c[2])); }

// Rotation about +z by `angle_rad` (counter-clockwise seen from above: φ increases).
inline Vec3 RotateZ(const Vec3& w, double cos_a, double sin_a) {
  return {cos_a * w.x - sin_a * w.y, sin_a * w.x + cos_a * w.y, w.z};
}

// An orthonormal frame around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
// revisited": continuous except across n.z = 0 sign change, no normalisation needed).
struct Frame {
  Vec3 s, t, n;
  static Frame FromNormal(const Vec3& n) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    return {
        {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}, n};
  }
  Vec3 ToLocal(const Vec3& w) const { return {Dot(w, s), Dot(w, t), Dot(w, n)}; }
  Vec3 ToWorld(const Vec3& w) const { return s * w.x + t * w.y + n * w.z; }
};

// Map pixel of a world-frame direction already rotated into the map's frame.
inline void MapPixelOf(const EnvironmentMap& map, const Vec3& w, int* i, int* j) {
  const double u = PhiOf(w) * (0.5 * kInvPi);
  const double v = ThetaOf(w) * kInvPi;
  *i = std::min(map.width() - 1, std::max(0, static_cast<int>(u * map.width())));
  *j = std::min(map.height() - 1, std::max(0, static_cast<int>(v * map.height())));
}

// The pixels of an .exr or .hdr file (RGB floats, row 0 at the top). The one place that reads
// image files, so the reader can change without touching the map code.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
};
RgbImage ReadEnvironmentImage(const std::string& path);

}  // namespace brdf::preview::detail
