// The object of a preview, placed at the origin inside the unit bounding sphere, and ray
// queries against it. Private to brdf_preview.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/preview/preview.h"

namespace brdf::preview::detail {

struct Hit {
  double t = 0.0;
  Vec3 position;
  Vec3 normal;            // shading normal, unit, on the side the ray came from
  Vec3 geometric_normal;  // unit, on the side the ray came from
};

class Scene {
 public:
  // The sphere has radius 1; the plane is the square |x|, |y| ≤ 1/√2 at z = 0 (both inside the
  // unit sphere); a mesh is centred on its bounding box and scaled so the box's half diagonal
  // is 1. Throws InvalidArgument for an empty mesh or one with non-finite extent.
  Scene(Shape shape, const Mesh* mesh);

  // Closest hit with t > t_min along o + t·d (d unit).
  bool Intersect(const Vec3& o, const Vec3& d, Hit* hit) const;
  // Whether anything lies along o + t·d for t > t_min (the map is at infinity).
  bool Occluded(const Vec3& o, const Vec3& d) const;
  // The sphere and the plane never shadow themselves.
  bool Convex() const { return shape_ != Shape::kMesh; }

 private:
  struct Node {
    Vec3 lo, hi;
    std::uint32_t first = 0, count = 0;  // leaf: triangles [first, first + count)
    std::uint32_t left = 0, right = 0;   // inner: children
  };
  std::uint32_t Build(std::uint32_t first, std::uint32_t count, int depth);
  template <bool kAnyHit>
  bool Traverse(const Vec3& o, const Vec3& d, double t_max, Hit* hit) const;

  Shape shape_;
  std::vector<Vec3> positions_, normals_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  std::vector<Vec3> centroids_;
  std::vector<Node> nodes_;
};

}  // namespace brdf::preview::detail
