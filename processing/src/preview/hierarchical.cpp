// The map hierarchy and the adaptive quadrature of the convex-object fast path (hierarchical.h).
#include "hierarchical.h"

#include <algorithm>
#include <cmath>

#include "preview_internal.h"

namespace brdf::preview::detail {
namespace {

// ∫ ω dω over the patch θ ∈ [t0, t1], φ ∈ [p0, p1] (dω = sinθ dθ dφ).
Vec3 PatchMoment(double t0, double t1, double p0, double p1) {
  const double sin_sq = (0.5 * (t1 - t0) - 0.25 * (std::sin(2.0 * t1) - std::sin(2.0 * t0)));
  const double sin_cos = 0.5 * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0));
  return {sin_sq * (std::sin(p1) - std::sin(p0)), sin_sq * (std::cos(p0) - std::cos(p1)),
          sin_cos * (p1 - p0)};
}

void Store(float* out, const Vec3& v) {
  out[0] = static_cast<float>(v.x);
  out[1] = static_cast<float>(v.y);
  out[2] = static_cast<float>(v.z);
}
Vec3 Load(const float* v) { return {v[0], v[1], v[2]}; }

// The bounding cone of the cell θ ∈ [t0, t1], φ ∈ [p0, p1]: the distance from the centre
// direction grows monotonically along each edge (small circles of constant θ, meridians), so a
// corner is the farthest point; a small margin covers float rounding.
void SetCone(double t0, double t1, double p0, double p1, MapHierarchy::Cell* cell) {
  const Vec3 axis = SphericalDirection(0.5 * (t0 + t1), 0.5 * (p0 + p1));
  double radius = 0.0;
  for (double t : {t0, t1})
    for (double p : {p0, p1})
      radius =
          std::max(radius, std::acos(std::clamp(Dot(axis, SphericalDirection(t, p)), -1.0, 1.0)));
  radius = std::min(0.5 * kPi, radius * 1.01 + 1e-5);
  Store(cell->axis, axis);
  cell->sin_radius = static_cast<float>(std::sin(radius));
  cell->cos_radius = static_cast<float>(std::cos(radius));
}

}  // namespace

MapHierarchy::MapHierarchy(const EnvironmentMap& map, int top_columns) {
  const int w0 = map.width(), h0 = map.height();
  width_.push_back(w0);
  height_.push_back(h0);
  while (width_.back() > top_columns && height_.back() > 1) {
    width_.push_back((width_.back() + 1) / 2);
    height_.push_back((height_.back() + 1) / 2);
  }
  cells_.resize(width_.size());
  // Level 0: the map's pixels, in double while summing.
  struct Sums {
    double e[3] = {0, 0, 0};
    Vec3 m{0, 0, 0};
    double y = 0, solid_angle = 0;
  };
  std::vector<Sums> sums(static_cast<std::size_t>(w0) * h0);
  for (int j = 0; j < h0; ++j) {
    const double t0 = j * kPi / h0, t1 = (j + 1) * kPi / h0;
    const double band = std::cos(t0) - std::cos(t1);
    for (int i = 0; i < w0; ++i) {
      const double p0 = i * 2.0 * kPi / w0, p1 = (i + 1) * 2.0 * kPi / w0;
      const float* px = map.Pixel(i, j);
      Sums& s = sums[static_cast<std::size_t>(j) * w0 + i];
      s.solid_angle = band * (p1 - p0);
      for (int c = 0; c < 3; ++c) s.e[c] = px[c] * s.solid_angle;
      s.y = Luminance({px[0], px[1], px[2]}) * s.solid_angle;
      s.m = PatchMoment(t0, t1, p0, p1) * Luminance({px[0], px[1], px[2]});
    }
  }
  for (int level = 0; level < levels(); ++level) {
    const int w = width_[level], h = height_[level];
    if (level > 0) {
      std::vector<Sums> up(static_cast<std::size_t>(w) * h);
      const int wd = width_[level - 1], hd = height_[level - 1];
      for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
          Sums& s = up[static_cast<std::size_t>(j) * w + i];
          for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)
            for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) {
              const Sums& d = sums[static_cast<std::size_t>(b) * wd + a];
              for (int c = 0; c < 3; ++c) s.e[c] += d.e[c];
              s.m = s.m + d.m;
              s.y += d.y;
              s.solid_angle += d.solid_angle;
            }
        }
      sums = std::move(up);
    }
    // Cell (i, j) of this level covers map pixels [i·2^level, (i+1)·2^level) clipped.
    const int span = 1 << level;
    std::vector<Cell>& cells = cells_[level];
    cells.resize(static_cast<std::size_t>(w) * h);
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) {
        const Sums& s = sums[static_cast<std::size_t>(j) * w + i];
        Cell& cell = cells[static_cast<std::size_t>(j) * w + i];
        for (int c = 0; c < 3; ++c) cell.radiance_solid_angle[c] = static_cast<float>(s.e[c]);
        Store(cell.luminance_moment, s.m);
        cell.luminance = static_cast<float>(s.y);
        cell.solid_angle = static_cast<float>(s.solid_angle);
        const double t0 = std::min(j * span, h0) * kPi / h0;
        const double t1 = std::min((j + 1) * span, h0) * kPi / h0;
        const double p0 = std::min(i * span, w0) * 2.0 * kPi / w0;
        const double p1 = std::min((i + 1) * span, w0) * 2.0 * kPi / w0;
        SetCone(t0, t1, p0, p1, &cell);
        const double length = Length(s.m);
        Store(cell.centroid, length > 0.0 ? s.m * (1.0 / length) : Load(cell.axis));
      }
  }
}

struct HierarchicalIntegrator::Query {
  Vec3 s, t, n, wo, mirror;
  double tolerance = 0.0;       // allowed |ΔY| of a cell of 2π sr (scaled by √(Ω/2π))
  double large_estimate = 0.0;  // cells estimated above this are always split
  mutable std::uint64_t evaluations = 0;  // counted for the benchmark figures
};

namespace {

enum class Side { kBelow, kAbove, kStraddles };

Side SideOf(const Vec3& n, const MapHierarchy::Cell& cell) {
  const double d = n.x * cell.axis[0] + n.y * cell.axis[1] + n.z * cell.axis[2];
  if (d >= cell.sin_radius) return Side::kAbove;
  if (d <= -cell.sin_radius) return Side::kBelow;
  return Side::kStraddles;
}

// The split threshold's dependence on a cell's solid angle Ω: (Ω/2π)^0.1, nearly the same
// absolute allowance for every cell. A threshold ∝ √(Ω/2π) (errors of many cells adding like
// independent ones) refines small cells far more: measured on six materials (docs/benchmarks.md,
// "Split threshold"), the nearly flat one gives the same or a lower image error for 20-30 % fewer
// BRDF evaluations on glossy materials and the same on matte ones. The sharp features that
// need small cells are few per pixel, and their errors are what the image error is made of.
double SizeFactor(double solid_angle_sr) {
  return std::pow(solid_angle_sr / (2.0 * kPi), 0.1);
}

bool ContainsMirror(const Vec3& r, const MapHierarchy::Cell& cell) {
  return r.x * cell.axis[0] + r.y * cell.axis[1] + r.z * cell.axis[2] >= cell.cos_radius;
}

}  // namespace

// The part of a cell above the horizon: the sums of its descendants that lie above it, down to
// `level` `stop` (straddling cells there are taken whole; their signed n·M is nearly exact).
void HierarchicalIntegrator::Clip(const Query& q, int level, int i, int j, int stop,
                                  CellSums* out) const {
  const MapHierarchy::Cell& cell = map_.At(level, i, j);
  const Side side = SideOf(q.n, cell);
  if (side == Side::kBelow) return;
  if (side == Side::kAbove) {
    for (int c = 0; c < 3; ++c) {
      out->e[c] += cell.radiance_solid_angle[c];
      out->m[c] += cell.luminance_moment[c];
    }
    out->y += cell.luminance;
    return;
  }
  if (level <= stop) {
    // A small cell across the horizon: its cosines taken as spread uniformly over d ± ρ (d the
    // luminance-weighted mean), with the variance of a square's projection, ρ = half the side
    // = the half-diagonal (cone radius) / √2. The part above then holds the fraction
    // a = (d + ρ)/2ρ of the light and ∫ L·max(0, cos) = Y·(d + ρ)²/4ρ. Only the component of M
    // along n changes, so the centroid keeps its direction across the horizon.
    if (!(cell.luminance > 0.0f)) return;
    const Vec3 m = Load(cell.luminance_moment);
    const double rho = std::max(1e-9, cell.sin_radius / std::sqrt(2.0));
    const double d = std::clamp(Dot(q.n, m) / cell.luminance, -rho, rho);
    const double above = (d + rho) / (2.0 * rho);
    const double clipped_cos = cell.luminance * (d + rho) * (d + rho) / (4.0 * rho);
    const Vec3 m_above = m * above + q.n * (clipped_cos - above * Dot(q.n, m));
    for (int c = 0; c < 3; ++c) out->e[c] += cell.radiance_solid_angle[c] * above;
    out->m[0] += m_above.x;
    out->m[1] += m_above.y;
    out->m[2] += m_above.z;
    out->y += cell.luminance * above;
    return;
  }
  const int wd = map_.width(level - 1), hd = map_.height(level - 1);
  for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)
    for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) Clip(q, level - 1, a, b, stop, out);
}

Rgb HierarchicalIntegrator::Estimate(const Query& q, int level, int i, int j,
                                     bool straddles) const {
  const MapHierarchy::Cell& cell = map_.At(level, i, j);
  if (!(cell.luminance > 0.0f)) return {0, 0, 0};
  CellSums sums;
  Vec3 centroid;
  if (straddles) {
    Clip(q, level, i, j, horizon_level_, &sums);
    const Vec3 m = {sums.m[0], sums.m[1], sums.m[2]};
    const double length = Length(m);
    if (!(length > 0.0)) return {0, 0, 0};
    centroid = m * (1.0 / length);
  } else {
    for (int c = 0; c < 3; ++c) {
      sums.e[c] = cell.radiance_solid_angle[c];
      sums.m[c] = cell.luminance_moment[c];
    }
    sums.y = cell.luminance;
    centroid = Load(cell.centroid);
  }
  if (!(sums.y > 0.0)) return {0, 0, 0};
  const double mean_cos = (q.n.x * sums.m[0] + q.n.y * sums.m[1] + q.n.z * sums.m[2]) / sums.y;
  if (!(mean_cos > 0.0)) return {0, 0, 0};
  const Vec3 wi = {Dot(q.s, centroid), Dot(q.t, centroid), Dot(q.n, centroid)};
  if (!(wi.z > 0.0)) return {0, 0, 0};
  const Rgb f = source_.Eval(wi, q.wo);
  ++q.evaluations;
  return {f[0] * sums.e[0] * mean_cos, f[1] * sums.e[1] * mean_cos, f[2] * sums.e[2] * mean_cos};
}

Rgb HierarchicalIntegrator::Refine(const Query& q, int level, int i, int j,
                                   const Rgb& estimate) const {
  const int child_level = level - 1;
  const int wd = map_.width(child_level), hd = map_.height(child_level);
  struct Child {
    int i, j;
    Rgb estimate;
    bool forced;
  };
  Child children[4];
  int count = 0;
  Rgb sum = {0, 0, 0};
  for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)
    for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) {
      const MapHierarchy::Cell& cell = map_.At(child_level, a, b);
      const Side side = SideOf(q.n, cell);
      if (side == Side::kBelow) continue;
      Child& c = children[count++];
      c.i = a;
      c.j = b;
      c.estimate = Estimate(q, child_level, a, b, side == Side::kStraddles);
      c.forced = child_level > mirror_level_ && ContainsMirror(q.mirror, cell);
      if (Luminance(c.estimate) > q.large_estimate) c.forced = true;
      for (int ch = 0; ch < 3; ++ch) sum[ch] += c.estimate[ch];
    }
  if (child_level == 0) return sum;
  const double difference = std::fabs(Luminance(sum) - Luminance(estimate));
  const bool split_all = difference > q.tolerance * SizeFactor(map_.At(level, i, j).solid_angle);
  Rgb total = {0, 0, 0};
  if (!split_all) {
    // Accepted: the midpoint-type rule's error falls as h², so the parent's error is about four
    // times the children's (Richardson): remove the children's share.
    for (int ch = 0; ch < 3; ++ch) total[ch] += (sum[ch] - estimate[ch]) / 3.0;
  }
  for (int k = 0; k < count; ++k) {
    const Child& c = children[k];
    const Rgb v =
        (split_all || c.forced) ? Refine(q, child_level, c.i, c.j, c.estimate) : c.estimate;
    for (int ch = 0; ch < 3; ++ch) total[ch] += v[ch];
  }
  return total;
}

Rgb HierarchicalIntegrator::Radiance(const Vec3& s, const Vec3& t, const Vec3& n, const Vec3& wo,
                                     double scale, bool top_only,
                                     std::uint64_t* evaluations) const {
  Query q;
  q.s = s;
  q.t = t;
  q.n = n;
  q.wo = wo;
  q.mirror = s * -wo.x + t * -wo.y + n * wo.z;
  const int top = map_.levels() - 1;
  const int w = map_.width(top), h = map_.height(top);
  struct Top {
    int i, j;
    Rgb estimate;
  };
  std::vector<Top> cells;
  cells.reserve(static_cast<std::size_t>(w) * h);
  Rgb sum = {0, 0, 0};
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const MapHierarchy::Cell& cell = map_.At(top, i, j);
      const Side side = SideOf(n, cell);
      if (side == Side::kBelow) continue;
      cells.push_back({i, j, Estimate(q, top, i, j, side == Side::kStraddles)});
      for (int ch = 0; ch < 3; ++ch) sum[ch] += cells.back().estimate[ch];
    }
  Rgb total = {0, 0, 0};
  if (top == 0 || top_only) {
    total = sum;
  } else {
    q.tolerance = settings_.tolerance * scale;
    q.large_estimate = settings_.largest_share * std::max(0.0, Luminance(sum));
    for (const Top& c : cells) {
      const Rgb v = Refine(q, top, c.i, c.j, c.estimate);
      for (int ch = 0; ch < 3; ++ch) total[ch] += v[ch];
    }
  }
  if (evaluations != nullptr) *evaluations += q.evaluations;
  return total;
}

}  // namespace brdf::preview::detail
