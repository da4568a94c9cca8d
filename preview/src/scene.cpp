// Ray queries for the preview object: analytic sphere and plane, and a bounding volume
// hierarchy over mesh triangles (median split on the longest axis, up to 4 triangles a leaf).
#include "scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "brdf/core/error.h"
#include "preview_internal.h"

namespace brdf::preview::detail {
namespace {

constexpr double kTMin = 1e-7;
constexpr double kHalfSide = 0.70710678118654752;

double Axis(const Vec3& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }
Vec3 Min(const Vec3& a, const Vec3& b) {
  return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z)};
}
Vec3 Max(const Vec3& a, const Vec3& b) {
  return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z)};
}

bool HitsBox(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv_d, double t_max) {
  double t0 = kTMin, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    double near = (Axis(lo, a) - Axis(o, a)) * Axis(inv_d, a);
    double far = (Axis(hi, a) - Axis(o, a)) * Axis(inv_d, a);
    if (near > far) std::swap(near, far);
    far *= 1.0 + 4e-16;  // robust against rounding at box faces (Ize 2013)
    t0 = near > t0 ? near : t0;
    t1 = far < t1 ? far : t1;
    if (t0 > t1) return false;
  }
  return true;
}

// Möller–Trumbore; returns t (infinity when missed) and the barycentrics.
double HitTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                   double* u, double* v) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = Cross(d, e2);
  const double det = Dot(e1, p);
  if (std::fabs(det) < 1e-14) return std::numeric_limits<double>::infinity();
  const double inv = 1.0 / det;
  const Vec3 s = o - a;
  *u = Dot(s, p) * inv;
  if (*u < 0.0 || *u > 1.0) return std::numeric_limits<double>::infinity();
  const Vec3 q = Cross(s, e1);
  *v = Dot(d, q) * inv;
  if (*v < 0.0 || *u + *v > 1.0) return std::numeric_limits<double>::infinity();
  const double t = Dot(e2, q) * inv;
  return t > kTMin ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

Scene::Scene(Shape shape, const Mesh* mesh) : shape_(shape) {
  if (shape != Shape::kMesh) return;
  if (mesh == nullptr || mesh->triangles.empty() || mesh->positions.empty())
    throw InvalidArgument("preview: the mesh has no triangles");
  Vec3 lo = mesh->positions[0], hi = lo;
  for (const Vec3& p : mesh->positions) {
    lo = Min(lo, p);
    hi = Max(hi, p);
  }
  const Vec3 centre = (lo + hi) * 0.5;
  const double radius = Length(hi - lo) * 0.5;
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw InvalidArgument("preview: the mesh has no extent (all vertices at one point)");
  positions_.reserve(mesh->positions.size());
  for (const Vec3& p : mesh->positions) positions_.push_back((p - centre) * (1.0 / radius));
  normals_ = mesh->normals;
  if (normals_.size() != positions_.size())
    throw InvalidArgument("preview: the mesh needs one normal per vertex");
  triangles_ = mesh->triangles;
  for (const auto& t : triangles_)
    for (std::uint32_t i : t)
      if (i >= positions_.size()) throw InvalidArgument("preview: a mesh index is out of range");
  centroids_.reserve(triangles_.size());
  for (const auto& t : triangles_)
    centroids_.push_back((positions_[t[0]] + positions_[t[1]] + positions_[t[2]]) * (1.0 / 3.0));
  nodes_.reserve(2 * triangles_.size() / 4 + 2);
  Build(0, static_cast<std::uint32_t>(triangles_.size()), 0);
}

std::uint32_t Scene::Build(std::uint32_t first, std::uint32_t count, int depth) {
  const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  Vec3 lo = positions_[triangles_[first][0]], hi = lo;
  Vec3 clo = centroids_[first], chi = clo;
  for (std::uint32_t k = first; k < first + count; ++k) {
    for (std::uint32_t v : triangles_[k]) {
      lo = Min(lo, positions_[v]);
      hi = Max(hi, positions_[v]);
    }
    clo = Min(clo, centroids_[k]);
    chi = Max(chi, centroids_[k]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  const Vec3 extent = chi - clo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  if (count <= 4 || depth >= 60 || Axis(extent, axis) <= 0.0) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  // Median split: partition triangles (and their centroids) around the middle one.
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), first);
  const std::uint32_t half = count / 2;
  std::nth_element(order.begin(), order.begin() + half, order.end(),
                   [&](std::uint32_t a, std::uint32_t b) {
                     return Axis(centroids_[a], axis) < Axis(centroids_[b], axis);
                   });
  std::vector<std::array<std::uint32_t, 3>> tris(count);
  std::vector<Vec3> cents(count);
  for (std::uint32_t k = 0; k < count; ++k) {
    tris[k] = triangles_[order[k]];
    cents[k] = centroids_[order[k]];
  }
  std::copy(tris.begin(), tris.end(), triangles_.begin() + first);
  std::copy(cents.begin(), cents.end(), centroids_.begin() + first);
  const std::uint32_t left = Build(first, half, depth + 1);
  const std::uint32_t right = Build(first + half, count - half, depth + 1);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

template <bool kAnyHit>
bool Scene::Traverse(const Vec3& o, const Vec3& d, double t_max, Hit* hit) const {
  const Vec3 inv_d = {1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  bool found = false;
  double best_u = 0, best_v = 0;
  std::uint32_t best_tri = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!HitsBox(node.lo, node.hi, o, inv_d, t_max)) continue;
    if (node.count > 0) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const auto& t = triangles_[k];
        double u = 0, v = 0;
        const double th =
            HitTriangle(o, d, positions_[t[0]], positions_[t[1]], positions_[t[2]], &u, &v);
        if (th < t_max) {
          if (kAnyHit) return true;
          t_max = th;
          best_u = u;
          best_v = v;
          best_tri = k;
          found = true;
        }
      }
    } else if (top + 2 <= 128) {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
  if (!found || kAnyHit) return found;
  const auto& t = triangles_[best_tri];
  hit->t = t_max;
  hit->position = o + d * t_max;
  Vec3 gn =
      Normalize(Cross(positions_[t[1]] - positions_[t[0]], positions_[t[2]] - positions_[t[0]]));
  Vec3 sn =
      normals_[t[0]] * (1.0 - best_u - best_v) + normals_[t[1]] * best_u + normals_[t[2]] * best_v;
  const double len = Length(sn);
  sn = len > 0.0 ? sn * (1.0 / len) : gn;
  // Two-sided: both normals face the ray's origin.
  if (Dot(gn, d) > 0.0) gn = gn * -1.0;
  if (Dot(sn, gn) < 0.0) sn = sn * -1.0;
  hit->geometric_normal = gn;
  hit->normal = sn;
  return true;
}

bool Scene::Intersect(const Vec3& o, const Vec3& d, Hit* hit) const {
  switch (shape_) {
    case Shape::kSphere: {
      const double b = Dot(o, d);
      const double c = Dot(o, o) - 1.0;
      const double disc = b * b - c;
      if (disc < 0.0) return false;
      const double root = std::sqrt(disc);
      double t = -b - root;
      if (t <= kTMin) t = -b + root;
      if (t <= kTMin) return false;
      hit->t = t;
      hit->position = o + d * t;
      hit->normal = Normalize(hit->position);
      hit->geometric_normal = hit->normal;
      return true;
    }
    case Shape::kPlane: {
      if (d.z == 0.0) return false;
      const double t = -o.z / d.z;
      if (t <= kTMin) return false;
      const Vec3 p = o + d * t;
      if (std::fabs(p.x) > kHalfSide || std::fabs(p.y) > kHalfSide) return false;
      hit->t = t;
      hit->position = {p.x, p.y, 0.0};
      hit->normal = {0.0, 0.0, d.z < 0.0 ? 1.0 : -1.0};
      hit->geometric_normal = hit->normal;
      return true;
    }
    case Shape::kMesh:
      return Traverse<false>(o, d, std::numeric_limits<double>::infinity(), hit);
  }
  return false;
}

bool Scene::Occluded(const Vec3& o, const Vec3& d) const {
  if (Convex()) return false;
  return Traverse<true>(o, d, std::numeric_limits<double>::infinity(), nullptr);
}

}  // namespace brdf::preview::detail
