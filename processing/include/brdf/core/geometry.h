// Local shading frame, directions and angles (docs/design.md §4).
//
// z is the surface normal; every direction points away from the surface; the spherical
// direction is ω(θ, φ) = (sinθ cosφ, sinθ sinφ, cosθ). Functions here take and return radians
// unless the name ends in `Deg`. Vec3T is templated so the analytic models can be evaluated
// with Ceres Jets as well as doubles.
#pragma once

#include <cmath>
#include <numbers>

namespace brdf {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kInvPi = 1.0 / std::numbers::pi;

constexpr double DegToRad(double deg) { return deg * (kPi / 180.0); }
constexpr double RadToDeg(double rad) { return rad * (180.0 / kPi); }

template <class T>
struct Vec3T {
  T x{}, y{}, z{};

  friend Vec3T operator+(const Vec3T& a, const Vec3T& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
  }
  friend Vec3T operator-(const Vec3T& a, const Vec3T& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
  }
  friend Vec3T operator*(const Vec3T& a, const T& s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Vec3T operator*(const T& s, const Vec3T& a) { return {a.x * s, a.y * s, a.z * s}; }
};
using Vec3 = Vec3T<double>;

template <class T>
T Dot(const Vec3T<T>& a, const Vec3T<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <class T>
Vec3T<T> Normalize(const Vec3T<T>& a) {
  using std::sqrt;
  const T len = sqrt(Dot(a, a));
  return {a.x / len, a.y / len, a.z / len};
}

inline Vec3 SphericalDirection(double theta_rad, double phi_rad) {
  const double s = std::sin(theta_rad);
  return {s * std::cos(phi_rad), s * std::sin(phi_rad), std::cos(theta_rad)};
}

inline Vec3 SphericalDirectionDeg(double theta_deg, double phi_deg) {
  return SphericalDirection(DegToRad(theta_deg), DegToRad(phi_deg));
}

// Polar angle of a unit vector in [0, π]; the clamp keeps acos defined for |z| a few ulp above 1.
inline double ThetaOf(const Vec3& w) { return std::acos(std::fmax(-1.0, std::fmin(1.0, w.z))); }

// Azimuth of a vector in [0, 2π).
inline double PhiOf(const Vec3& w) {
  double phi = std::atan2(w.y, w.x);
  if (phi < 0.0) phi += 2.0 * kPi;
  if (phi >= 2.0 * kPi) phi = 0.0;
  return phi;
}

// Wraps an angle in degrees to [0, 360).
inline double WrapDeg360(double deg) {
  double r = std::fmod(deg, 360.0);
  if (r < 0.0) r += 360.0;
  if (r >= 360.0) r = 0.0;
  return r;
}

// The mirror of l about the normal: r = (−l.x, −l.y, l.z).
template <class T>
Vec3T<T> Reflect(const Vec3T<T>& l) {
  return {-l.x, -l.y, l.z};
}

// The specular frame of docs/design.md §5: S(θm) = [[−cosθm, 0, −sinθm], [0, −1, 0],
// [−sinθm, 0, cosθm]]. ω_d = S(θin)·ω_out maps the mirror direction (θin, φin + 180°) to the
// pole. S is symmetric and orthogonal, so it is its own inverse: ω_out = S(θin)·ω_d.
struct SpecularFrame {
  double cos_m, sin_m;

  static SpecularFrame FromThetaInRad(double theta_in_rad) {
    return {std::cos(theta_in_rad), std::sin(theta_in_rad)};
  }
  static SpecularFrame FromThetaInDeg(double theta_in_deg) {
    return FromThetaInRad(DegToRad(theta_in_deg));
  }

  Vec3 Apply(const Vec3& w) const {
    return {-cos_m * w.x - sin_m * w.z, -w.y, -sin_m * w.x + cos_m * w.z};
  }
  Vec3 ToSpecular(const Vec3& w_out) const { return Apply(w_out); }
  Vec3 FromSpecular(const Vec3& w_d) const { return Apply(w_d); }
};

}  // namespace brdf
