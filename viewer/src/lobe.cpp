#include "brdf/viewer/lobe.h"

#include <algorithm>
#include <cmath>

#include "brdf/core/error.h"

namespace brdf::viewer {
namespace {

Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

}  // namespace

const char* ChannelName(Channel channel) {
  switch (channel) {
    case Channel::kRed:
      return "R";
    case Channel::kGreen:
      return "G";
    case Channel::kBlue:
      return "B";
    case Channel::kLuminance:
      return "luminance";
  }
  return "?";
}

double ChannelValue(const float* rgb, Channel channel) {
  switch (channel) {
    case Channel::kRed:
      return rgb[0];
    case Channel::kGreen:
      return rgb[1];
    case Channel::kBlue:
      return rgb[2];
    case Channel::kLuminance:
      return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
  }
  return 0;
}

void LobeOptions::Validate() const {
  if (!std::isfinite(theta_in_deg) || theta_in_deg < 0 || theta_in_deg >= 90) {
    throw InvalidArgument("lobe θin must be in [0°, 90°), got " + std::to_string(theta_in_deg));
  }
  if (theta_rows < 2 || theta_rows > 1800) {
    throw InvalidArgument("lobe theta_rows must be in 2…1800, got " + std::to_string(theta_rows));
  }
  if (phi_columns < 3 || phi_columns > 3600) {
    throw InvalidArgument("lobe phi_columns must be in 3…3600, got " + std::to_string(phi_columns));
  }
  if (!std::isfinite(log_floor) || log_floor < 0) {
    throw InvalidArgument("lobe log_floor must be ≥ 0, got " + std::to_string(log_floor));
  }
}

int LobeMesh::FarthestVertex() const {
  int best = 0;
  double best_r2 = -1;
  for (std::size_t n = 0; n < points.size(); ++n) {
    const double r2 = Dot(points[n], points[n]);
    if (r2 > best_r2) {
      best_r2 = r2;
      best = static_cast<int>(n);
    }
  }
  return best;
}

LobeMesh BuildLobe(const ViewSource& source, const LobeOptions& options) {
  options.Validate();
  if (source.lut.slices() == 0) throw InvalidArgument("the source has no LUT slices to draw");
  LobeMesh mesh;
  mesh.theta_rows = options.theta_rows;
  mesh.phi_columns = options.phi_columns;
  const int rows = options.theta_rows + 1;
  const int cols = options.phi_columns;
  const std::size_t n = static_cast<std::size_t>(rows) * cols;
  mesh.directions.resize(n);
  mesh.points.resize(n);
  mesh.values.resize(n);
  mesh.coverage.resize(n);

  for (int t = 0; t < rows; ++t) {
    const double theta_deg = 90.0 * t / options.theta_rows;
    const double cos_theta = std::cos(DegToRad(theta_deg));
    for (int c = 0; c < cols; ++c) {
      const double phi_deg = 360.0 * c / cols;
      const std::size_t idx = static_cast<std::size_t>(t) * cols + c;
      mesh.directions[idx] = SphericalDirectionDeg(theta_deg, phi_deg);
      const std::array<float, 3> rgb =
          source.lut.SampleAngles(options.theta_in_deg, theta_deg, phi_deg);
      double q = std::max(0.0, ChannelValue(rgb.data(), options.channel));
      if (options.cosine_weighted) q *= std::max(0.0, cos_theta);
      mesh.values[idx] = q;
      mesh.max_value = std::max(mesh.max_value, q);
      mesh.coverage[idx] = source.CoverageAt(options.theta_in_deg, theta_deg, phi_deg);
    }
  }

  if (options.scale == RadiusScale::kLog) {
    mesh.log_floor = options.log_floor > 0 ? options.log_floor : mesh.max_value * 1e-3;
    if (mesh.log_floor <= 0) mesh.log_floor = 1e-12;  // an all-black source: every radius 0
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double r = options.scale == RadiusScale::kLinear
                         ? mesh.values[i]
                         : std::max(0.0, std::log10(mesh.values[i] / mesh.log_floor));
    mesh.points[i] = mesh.directions[i] * r;
    mesh.max_radius = std::max(mesh.max_radius, r);
  }

  // Outward winding: ∂/∂θ × ∂/∂φ points away from the origin on the sphere.
  mesh.triangles.reserve(static_cast<std::size_t>(options.theta_rows) * cols * 2);
  for (int t = 0; t < options.theta_rows; ++t) {
    for (int c = 0; c < cols; ++c) {
      const int a = t * cols + c;
      const int b = t * cols + (c + 1) % cols;
      const int d = (t + 1) * cols + c;
      const int e = (t + 1) * cols + (c + 1) % cols;
      mesh.triangles.push_back({a, d, e});
      if (t > 0) mesh.triangles.push_back({a, e, b});  // at the pole a and b coincide
    }
  }
  mesh.triangle_coverage.reserve(mesh.triangles.size());
  for (const auto& tri : mesh.triangles) {
    Coverage worst = Coverage::kMeasured;
    for (int v : tri) {
      if (static_cast<int>(mesh.coverage[v]) > static_cast<int>(worst)) worst = mesh.coverage[v];
    }
    mesh.triangle_coverage.push_back(worst);
  }

  mesh.light = SphericalDirectionDeg(options.theta_in_deg, 0.0);
  mesh.mirror = Reflect(mesh.light);
  return mesh;
}

CameraSetup LobeCamera(const LobeMesh& mesh, double arrow_length, double aspect) {
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  auto grow = [&](const Vec3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  };
  for (const Vec3& p : mesh.points) grow(p);
  for (const Vec3& a : {mesh.normal, mesh.light, mesh.mirror}) grow(a * arrow_length);
  CameraSetup camera;
  camera.focal_point = (lo + hi) * 0.5;
  const Vec3 half = (hi - lo) * 0.5;
  const double radius = std::max(1e-9, std::sqrt(Dot(half, half)));
  const double half_v = DegToRad(camera.view_angle_deg / 2);
  const double half_h = std::atan(std::tan(half_v) * std::max(aspect, 1e-3));
  const double distance = 1.05 * radius / std::sin(std::min(half_v, half_h));
  const double elevation = DegToRad(25.0);
  const Vec3 towards_camera{0.0, -std::cos(elevation), std::sin(elevation)};
  camera.position = camera.focal_point + towards_camera * distance;
  // Up is +z projected onto the image plane, so the normal arrow points up on screen.
  const Vec3 right = Normalize(Cross(towards_camera * -1.0, Vec3{0, 0, 1}));
  camera.view_up = Normalize(Cross(right, towards_camera * -1.0));
  return camera;
}

}  // namespace brdf::viewer
