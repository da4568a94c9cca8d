// The map hierarchy and the adaptive quadrature of the convex-object fast path (hierarchical.h).
#include "hierarchical.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "preview_internal.h"

namespace brdf::preview::detail {
namespace {

void Store(float* out, const Vec3& v) {
  out[0] = static_cast<float>(v.x);
  out[1] = static_cast<float>(v.y);
  out[2] = static_cast<float>(v.z);
}
Vec3 Load(const float* v) { return {v[0], v[1], v[2]}; }

// The trigonometry of the map's pixel edges along one axis: edge k lies at angle
// k · range / pixels (θ: range π over the rows, φ: 2π over the columns). Every cell of every
// level has its edges among them (a cell of level ℓ spans 2^ℓ pixels, clipped at the map's
// edge), so sin/cos are taken once per edge instead of once per cell, corner and level.
struct EdgeTrig {
  std::vector<double> angle, sin, cos, sin_twice;  // sin_twice: sin(2·angle), θ edges only
  EdgeTrig(int pixels, double range, bool twice) {
    for (int k = 0; k <= pixels; ++k) {
      const double a = k * range / pixels;
      angle.push_back(a);
      sin.push_back(std::sin(a));
      cos.push_back(std::cos(a));
      if (twice) sin_twice.push_back(std::sin(2.0 * a));
    }
  }
};

// The per-row (θ) or per-column (φ) terms of the cells of one level: the edge indices and the
// direction of the centre angle.
struct CellAxis {
  int edge0, edge1;
  double sin_centre, cos_centre;
};
std::vector<CellAxis> Axis(const EdgeTrig& edges, int cells, int span) {
  const int pixels = static_cast<int>(edges.angle.size()) - 1;
  std::vector<CellAxis> axis(static_cast<std::size_t>(cells));
  for (int k = 0; k < cells; ++k) {
    CellAxis& a = axis[k];
    a.edge0 = std::min(k * span, pixels);
    a.edge1 = std::min((k + 1) * span, pixels);
    const double centre = 0.5 * (edges.angle[a.edge0] + edges.angle[a.edge1]);
    a.sin_centre = std::sin(centre);
    a.cos_centre = std::cos(centre);
  }
  return axis;
}

// The bounding cone of the cell between θ edges `row` and φ edges `column`: the distance from
// the centre direction grows monotonically along each edge (small circles of constant θ,
// meridians), so a corner is the farthest point (the smallest cosine); a small margin covers
// float rounding. The cone of a row's cells is the same in every column up to rounding, which
// leaves a few distinct cosines per row, so the sin/cos of the radius of the last few are kept
// in `cache` and reused when a cosine repeats exactly (the same numbers as computing them
// again).
class ConeCache {
 public:
  void Set(double min_dot, MapHierarchy::Cell* cell) {
    int k = 0;
    while (k < size_ && min_dot_[k] != min_dot) ++k;
    if (k == size_) {
      k = size_ < kEntries ? size_++ : next_;
      next_ = (k + 1) % kEntries;
      // acos falls monotonically, so the largest corner distance is the acos of the smallest
      // cosine.
      const double radius = std::min(0.5 * kPi, std::max(0.0, std::acos(min_dot)) * 1.01 + 1e-5);
      min_dot_[k] = min_dot;
      sin_radius_[k] = static_cast<float>(std::sin(radius));
      cos_radius_[k] = static_cast<float>(std::cos(radius));
    }
    cell->sin_radius = sin_radius_[k];
    cell->cos_radius = cos_radius_[k];
  }

 private:
  static constexpr int kEntries = 8;
  double min_dot_[kEntries];
  float sin_radius_[kEntries], cos_radius_[kEntries];
  int size_ = 0, next_ = 0;
};
void SetCone(const EdgeTrig& theta, const EdgeTrig& phi, const CellAxis& row,
             const CellAxis& column, ConeCache* cache, MapHierarchy::Cell* cell) {
  const Vec3 axis = {row.sin_centre * column.cos_centre, row.sin_centre * column.sin_centre,
                     row.cos_centre};
  double min_dot = 1.0;
  for (int t : {row.edge0, row.edge1})
    for (int p : {column.edge0, column.edge1}) {
      const Vec3 corner = {theta.sin[t] * phi.cos[p], theta.sin[t] * phi.sin[p], theta.cos[t]};
      min_dot = std::min(min_dot, std::clamp(Dot(axis, corner), -1.0, 1.0));
    }
  Store(cell->axis, axis);
  cache->Set(min_dot, cell);
}

// Rows are independent at every level, so they are built `jobs` at a time.
constexpr std::size_t kRowsPerChunk = 4;

}  // namespace

MapHierarchy::Cell MapHierarchy::Pixel(int i, int j) const {
  const float* px = map_->Pixel(i, j);
  const Row& row = rows_[j];
  const Column& column = columns_[i];
  const double solid_angle = row.band * column.d_phi;
  const double y = Luminance({px[0], px[1], px[2]});
  const Vec3 m =
      Vec3{row.sin_sq * column.d_sin, row.sin_sq * column.d_cos, row.sin_cos * column.d_phi} * y;
  Cell cell;
  for (int c = 0; c < 3; ++c)
    cell.radiance_solid_angle[c] = static_cast<float>(px[c] * solid_angle);
  Store(cell.luminance_moment, m);
  cell.luminance = static_cast<float>(y * solid_angle);
  cell.solid_angle = static_cast<float>(solid_angle);
  const Vec3 axis = {row.sin_centre * column.cos_centre, row.sin_centre * column.sin_centre,
                     row.cos_centre};
  Store(cell.axis, axis);
  cell.sin_radius = row.sin_radius;
  cell.cos_radius = row.cos_radius;
  const double length = Length(m);
  Store(cell.centroid, length > 0.0 ? m * (1.0 / length) : Load(cell.axis));
  return cell;
}

MapHierarchy::MapHierarchy(const EnvironmentMap& map, int top_columns, int jobs) : map_(&map) {
  const int w0 = map.width(), h0 = map.height();
  width_.push_back(w0);
  height_.push_back(h0);
  while (width_.back() > top_columns && height_.back() > 1) {
    width_.push_back((width_.back() + 1) / 2);
    height_.push_back((height_.back() + 1) / 2);
  }
  cells_.resize(width_.size());
  const EdgeTrig theta(h0, kPi, true), phi(w0, 2.0 * kPi, false);
  // Level 0: the map's pixels, in double while summing. The moment ∫ ω dω of the patch
  // θ ∈ [t0, t1], φ ∈ [p0, p1] (dω = sinθ dθ dφ) is a θ factor times a φ factor per component:
  //   (S · (sin p1 − sin p0), S · (cos p0 − cos p1), C · (p1 − p0)),
  //   S = ∫ sin²θ dθ = (t1 − t0)/2 − (sin 2t1 − sin 2t0)/4,
  //   C = ∫ sinθ cosθ dθ = (sin²t1 − sin²t0)/2.
  struct Sums {
    double e[3];
    Vec3 m;
    double y, solid_angle;
  };
  std::vector<double> sin_sq(h0), sin_cos(h0), band(h0);
  for (int j = 0; j < h0; ++j) {
    sin_sq[j] = 0.5 * (theta.angle[j + 1] - theta.angle[j]) -
                0.25 * (theta.sin_twice[j + 1] - theta.sin_twice[j]);
    sin_cos[j] = 0.5 * (theta.sin[j + 1] * theta.sin[j + 1] - theta.sin[j] * theta.sin[j]);
    band[j] = theta.cos[j] - theta.cos[j + 1];
  }
  std::vector<double> d_phi(w0), d_sin(w0), d_cos(w0);
  for (int i = 0; i < w0; ++i) {
    d_phi[i] = phi.angle[i + 1] - phi.angle[i];
    d_sin[i] = phi.sin[i + 1] - phi.sin[i];
    d_cos[i] = phi.cos[i] - phi.cos[i + 1];
  }
  // The pixels' sums are a few products each, so they are made where they are needed (for the
  // level-0 cells and again for level 1's) rather than kept: a stored copy would be as large as
  // the level-0 cells twice over.
  auto pixel_sums = [&](int i, int j) {
    const float* px = map.Pixel(i, j);
    Sums s;
    s.solid_angle = band[j] * d_phi[i];
    for (int c = 0; c < 3; ++c) s.e[c] = px[c] * s.solid_angle;
    const double y = Luminance({px[0], px[1], px[2]});
    s.y = y * s.solid_angle;
    s.m = Vec3{sin_sq[j] * d_sin[i], sin_sq[j] * d_cos[i], sin_cos[j] * d_phi[i]} * y;
    return s;
  };
  // The sums of the level below the one being built (from level 2 on; level 1 reads pixels).
  std::unique_ptr<Sums[]> below, sums;
  for (int level = 0; level < levels(); ++level) {
    const int w = width_[level], h = height_[level];
    const std::size_t count = static_cast<std::size_t>(w) * h;
    if (level > 0) {
      // Left uninitialised here and written by the threads, so that the pages are first
      // touched (and cleared by the kernel) in parallel.
      sums = std::make_unique_for_overwrite<Sums[]>(count);
      const int wd = width_[level - 1], hd = height_[level - 1];
      ParallelChunks(static_cast<std::size_t>(h), kRowsPerChunk, jobs, nullptr,
                     [&](std::size_t b0, std::size_t e0) {
                       for (int j = static_cast<int>(b0); j < static_cast<int>(e0); ++j)
                         for (int i = 0; i < w; ++i) {
                           Sums& s = sums[static_cast<std::size_t>(j) * w + i];
                           s = {{0, 0, 0}, {0, 0, 0}, 0, 0};
                           for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)
                             for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) {
                               const Sums d = level == 1
                                                  ? pixel_sums(a, b)
                                                  : below[static_cast<std::size_t>(b) * wd + a];
                               for (int c = 0; c < 3; ++c) s.e[c] += d.e[c];
                               s.m = s.m + d.m;
                               s.y += d.y;
                               s.solid_angle += d.solid_angle;
                             }
                         }
                     });
    }
    // Cell (i, j) of this level covers map pixels [i·2^level, (i+1)·2^level) clipped.
    const int span = 1 << level;
    const std::vector<CellAxis> rows = Axis(theta, h, span), columns = Axis(phi, w, span);
    if (level == 0) {
      // Not stored (At): the per-row and per-column terms its cells are made of. The bounding
      // cone of a row's cells is the same in every column up to rounding, far inside the cone's
      // margin (ConeCache), so it is taken once per row, from column 0.
      for (int j = 0; j < h; ++j) {
        ConeCache cache;
        Cell probe;
        SetCone(theta, phi, rows[j], columns[0], &cache, &probe);
        rows_.push_back({band[j], sin_sq[j], sin_cos[j], rows[j].sin_centre, rows[j].cos_centre,
                         probe.sin_radius, probe.cos_radius});
      }
      for (int i = 0; i < w; ++i)
        columns_.push_back(
            {d_phi[i], d_sin[i], d_cos[i], columns[i].sin_centre, columns[i].cos_centre});
      continue;
    }
    cells_[level] = std::make_unique_for_overwrite<Cell[]>(count);
    Cell* cells = cells_[level].get();
    ParallelChunks(static_cast<std::size_t>(h), kRowsPerChunk, jobs, nullptr,
                   [&](std::size_t b, std::size_t e) {
                     for (std::size_t j = b; j < e; ++j) {
                       ConeCache cache;
                       for (int i = 0; i < w; ++i) {
                         const Sums s = sums[j * w + i];
                         Cell& cell = cells[j * w + i];
                         for (int c = 0; c < 3; ++c)
                           cell.radiance_solid_angle[c] = static_cast<float>(s.e[c]);
                         Store(cell.luminance_moment, s.m);
                         cell.luminance = static_cast<float>(s.y);
                         cell.solid_angle = static_cast<float>(s.solid_angle);
                         SetCone(theta, phi, rows[j], columns[i], &cache, &cell);
                         const double length = Length(s.m);
                         Store(cell.centroid,
                               length > 0.0 ? s.m * (1.0 / length) : Load(cell.axis));
                       }
                     }
                   });
    below = std::move(sums);
  }
}

namespace {

// Where the leaf contributions of the straddling cells Clip() has walked lie in the query's
// leaf list: an open-addressed table from (level, i, j) to [begin, end), cleared per query by a
// generation count. A cell that does not fit (the table is kept under half full) is walked
// again when it is estimated, which gives the same numbers.
class ClipRanges {
 public:
  void Clear() {
    used_ = 0;
    if (++generation_ == 0) {  // wrapped: forget every stamp
      for (Slot& s : slots_) s.generation = 0;
      generation_ = 1;
    }
  }
  static std::uint64_t Key(int level, int i, int j) {
    return (static_cast<std::uint64_t>(level) << 48) | (static_cast<std::uint64_t>(j) << 24) |
           static_cast<std::uint64_t>(i);
  }
  bool Find(std::uint64_t key, std::size_t* begin, std::size_t* end) const {
    for (std::size_t k = Hash(key);; k = (k + 1) & (kSlots - 1)) {
      const Slot& s = slots_[k];
      if (s.generation != generation_) return false;
      if (s.key == key) {
        *begin = s.begin;
        *end = s.end;
        return true;
      }
    }
  }
  void Insert(std::uint64_t key, std::size_t begin, std::size_t end) {
    if (used_ >= kSlots / 2) return;
    std::size_t k = Hash(key);
    while (slots_[k].generation == generation_) k = (k + 1) & (kSlots - 1);
    slots_[k] = {key, generation_, static_cast<std::uint32_t>(begin),
                 static_cast<std::uint32_t>(end)};
    ++used_;
  }

 private:
  static constexpr std::size_t kSlots = 1024;
  static std::size_t Hash(std::uint64_t key) {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ull) >> 54);  // 10 bits
  }
  struct Slot {
    std::uint64_t key = 0;
    std::uint32_t generation = 0, begin = 0, end = 0;
  };
  std::array<Slot, kSlots> slots_{};
  std::uint32_t generation_ = 0;
  std::size_t used_ = 0;
};

}  // namespace

struct HierarchicalIntegrator::Query {
  Vec3 s, t, n, wo, mirror;
  double tolerance = 0.0;       // allowed |ΔY| of a cell of 2π sr (scaled by SizeFactor)
  double large_estimate = 0.0;  // cells estimated above this are always split
  mutable std::uint64_t evaluations = 0;  // counted for the benchmark figures
  // Clip()'s record (per thread, reused across queries).
  std::vector<CellSums>* leaves = nullptr;
  ClipRanges* ranges = nullptr;
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
double SizeFactor(double solid_angle_sr) { return std::pow(solid_angle_sr / (2.0 * kPi), 0.1); }

bool ContainsMirror(const Vec3& r, const MapHierarchy::Cell& cell) {
  return r.x * cell.axis[0] + r.y * cell.axis[1] + r.z * cell.axis[2] >= cell.cos_radius;
}

}  // namespace

// The part of a cell above the horizon: the sums of its descendants that lie above it, down to
// `level` `stop` (straddling cells there are taken whole; their signed n·M is nearly exact).
void HierarchicalIntegrator::Clip(const Query& q, int level, int i, int j, int stop) const {
  const MapHierarchy::Cell& cell = map_.At(level, i, j);
  const Side side = SideOf(q.n, cell);
  if (side == Side::kBelow) return;
  CellSums leaf;
  if (side == Side::kAbove) {
    for (int c = 0; c < 3; ++c) {
      leaf.e[c] = cell.radiance_solid_angle[c];
      leaf.m[c] = cell.luminance_moment[c];
    }
    leaf.y = cell.luminance;
    q.leaves->push_back(leaf);
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
    for (int c = 0; c < 3; ++c) leaf.e[c] = cell.radiance_solid_angle[c] * above;
    leaf.m[0] = m_above.x;
    leaf.m[1] = m_above.y;
    leaf.m[2] = m_above.z;
    leaf.y = cell.luminance * above;
    q.leaves->push_back(leaf);
    return;
  }
  const std::size_t begin = q.leaves->size();
  const int wd = map_.width(level - 1), hd = map_.height(level - 1);
  for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)  // as in Refine()
    for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) map_.Prefetch(level - 1, a, b);
  for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)
    for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) Clip(q, level - 1, a, b, stop);
  q.ranges->Insert(ClipRanges::Key(level, i, j), begin, q.leaves->size());
}

HierarchicalIntegrator::CellSums HierarchicalIntegrator::ClippedSums(const Query& q, int level,
                                                                     int i, int j) const {
  std::size_t begin = 0, end = 0;
  if (level <= horizon_level_ || !q.ranges->Find(ClipRanges::Key(level, i, j), &begin, &end)) {
    begin = q.leaves->size();
    Clip(q, level, i, j, horizon_level_);
    end = q.leaves->size();
  }
  // Summed from zero in the order Clip() visits the leaves, as a walk of the subtree would.
  CellSums sums;
  for (std::size_t k = begin; k < end; ++k) {
    const CellSums& leaf = (*q.leaves)[k];
    for (int c = 0; c < 3; ++c) {
      sums.e[c] += leaf.e[c];
      sums.m[c] += leaf.m[c];
    }
    sums.y += leaf.y;
  }
  return sums;
}

Rgb HierarchicalIntegrator::Estimate(const Query& q, int level, int i, int j,
                                     bool straddles) const {
  const MapHierarchy::Cell& cell = map_.At(level, i, j);
  if (!(cell.luminance > 0.0f)) return {0, 0, 0};
  CellSums sums;
  Vec3 centroid;
  if (straddles) {
    sums = ClippedSums(q, level, i, j);
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

std::vector<HierarchicalIntegrator::RowFactors> HierarchicalIntegrator::SizeFactors(
    const MapHierarchy& map) {
  std::vector<RowFactors> factors(static_cast<std::size_t>(map.levels()));
  for (int level = 0; level < map.levels(); ++level) {
    const int w = map.width(level);
    for (int j = 0; j < map.height(level); ++j)
      factors[level].push_back({SizeFactor(map.At(level, 0, j).solid_angle),
                                SizeFactor(map.At(level, w - 1, j).solid_angle)});
  }
  return factors;
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
  // The children lie in two map rows far apart; asking for all four lines first overlaps their
  // cache misses with each other and with the first child's BRDF evaluation.
  for (int b = 2 * j; b < std::min(2 * j + 2, hd); ++b)
    for (int a = 2 * i; a < std::min(2 * i + 2, wd); ++a) map_.Prefetch(child_level, a, b);
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
      if (std::fabs(Luminance(c.estimate)) > q.large_estimate) c.forced = true;
      for (int ch = 0; ch < 3; ++ch) sum[ch] += c.estimate[ch];
    }
  if (child_level == 0) return sum;
  // Out of evaluations (HierarchicalSettings::max_evaluations): accepted as it stands.
  if (q.evaluations >= settings_.max_evaluations) {
    for (int ch = 0; ch < 3; ++ch) sum[ch] += (sum[ch] - estimate[ch]) / 3.0;
    return sum;
  }
  const double difference = std::fabs(Luminance(sum) - Luminance(estimate));
  const bool split_all = difference > q.tolerance * SizeFactorOf(level, i, j);
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
  // Clip()'s record, kept per thread so that a query allocates nothing once it has grown.
  thread_local std::vector<CellSums> leaves;
  thread_local ClipRanges ranges;
  leaves.clear();
  ranges.Clear();
  Query q;
  q.leaves = &leaves;
  q.ranges = &ranges;
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
  thread_local std::vector<Top> cells;  // per thread, as Clip()'s record
  cells.clear();
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
    // The magnitudes, not the signed values: a negative (or NaN) threshold would split every
    // cell down to the map's pixels.
    q.tolerance = settings_.tolerance * std::fabs(scale);
    q.large_estimate = settings_.largest_share * std::fabs(Luminance(sum));
    for (const Top& c : cells) {
      const Rgb v = Refine(q, top, c.i, c.j, c.estimate);
      for (int ch = 0; ch < 3; ++ch) total[ch] += v[ch];
    }
  }
  if (evaluations != nullptr) *evaluations += q.evaluations;
  return total;
}

}  // namespace brdf::preview::detail
