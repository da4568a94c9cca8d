// The deterministic fast path for convex objects (Estimator::kHierarchical, preview.h): an
// adaptive quadrature over a hierarchy of the environment map. Private to brdf_preview.
//
// The map is piecewise constant over its pixels, so the integral of one pixel shading point is
//   Σ_cells ∫_cell L(ω) · f_r(ω, ω_o) · cosθ dω
// over any partition of the sphere into cells. The hierarchy stores, for every cell of every
// level (level 0 = the map's pixels, each level above merges 2 × 2 cells), the exact integrals
// E = ∫ L dω (RGB) and M = ∫ Y(ω) · ω dω (Y the luminance), from the pixels' exact solid angles
// and first moments. A cell's contribution is estimated as
//   f_r(ω̄, ω_o) ⊙ E · (n·M / E_Y),   ω̄ = M / |M| (the cell's luminance centroid),
// which integrates the cosine exactly (it is linear in ω) and f_r to second order in the cell's
// size. Cells are refined where the estimate of a cell and the sum of its children's differ by
// more than the tolerance, where they straddle the horizon of the normal (the clamped cosine
// has a kink there), and around the mirror direction (so that a lobe narrower than a coarse
// cell cannot fall between the points evaluated). Level 0 cells are the map pixels evaluated at
// their luminance centroid, the brute-force reference's rule.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/geometry.h"
#include "brdf/preview/preview.h"

namespace brdf::preview::detail {

class MapHierarchy {
 public:
  // One cache line, aligned to one, so that reading a cell costs one line.
  struct alignas(64) Cell {
    float radiance_solid_angle[3];  // E: ∫ L dω over the cell, RGB
    float luminance_moment[3];      // M: ∫ Y(ω) ω dω, map frame
    float centroid[3];              // M/|M| (the geometric centre for a black cell)
    float axis[3];                  // geometric centre direction (bounding cone axis)
    float sin_radius, cos_radius;   // bounding cone half-angle around `axis`
    float luminance;                // E_Y = ∫ Y dω
    float solid_angle;              // sr
  };

  // Levels are halved (rounding up) until the top level is at most `top_columns` wide. Built on
  // `jobs` threads (the cells do not depend on it). `map` must outlive the hierarchy (level 0 is
  // read from it).
  MapHierarchy(const EnvironmentMap& map, int top_columns, int jobs = 1);

  int levels() const { return static_cast<int>(width_.size()); }
  int width(int level) const { return width_[level]; }
  int height(int level) const { return height_[level]; }
  // Level 0 (the map's pixels, three quarters of all cells) is not stored: its cells are made
  // from the map's pixel and per-row and per-column terms when asked for, so the hierarchy costs
  // about 21 bytes per map pixel instead of 85 (docs/benchmarks/preview-memory.md).
  Cell At(int level, int i, int j) const {
    if (level == 0) return Pixel(i, j);
    return cells_[level][static_cast<std::size_t>(j) * width_[level] + i];
  }
  void Prefetch(int level, int i, int j) const {
    if (level == 0)
      __builtin_prefetch(map_->Pixel(i, j));
    else
      __builtin_prefetch(&cells_[level][static_cast<std::size_t>(j) * width_[level] + i]);
  }

 private:
  Cell Pixel(int i, int j) const;
  struct Row {  // θ terms of a level-0 row (hierarchical.cpp)
    double band, sin_sq, sin_cos, sin_centre, cos_centre;
    float sin_radius, cos_radius;
  };
  struct Column {  // φ terms of a level-0 column
    double d_phi, d_sin, d_cos, sin_centre, cos_centre;
  };
  const EnvironmentMap* map_;
  std::vector<Row> rows_;
  std::vector<Column> columns_;
  std::vector<int> width_, height_;
  std::vector<std::unique_ptr<Cell[]>> cells_;
};

struct HierarchicalSettings {
  // A cell of solid angle Ω is split when the luminance of its estimate and of its children's
  // sum differ by more than tolerance · scale · (Ω/2π)^0.1 (scale: Radiance()).
  double tolerance = 0.002;
  // A cell whose estimate exceeds this fraction of the pixel's first (top-level) estimate is
  // split whatever its children say, so that no single cell carries a large share unchecked.
  double largest_share = 0.03;
  // A cell straddling the horizon is estimated from its descendants above the horizon, found
  // down to the level at least this many columns wide (about 2.8° cells; the map's pixels if it
  // is smaller), without BRDF evaluations.
  int horizon_columns = 128;
  // Cells whose bounding cone contains the mirror direction are split down to the level at
  // least this many columns wide (0.7°), so a lobe narrower than a coarse cell cannot fall
  // between the points evaluated.
  int mirror_columns = 512;
  // At most about this many f_r evaluations per shading point, whatever the values: once a
  // point has spent them, the cells not yet refined keep their estimate (with the children's
  // sum where they were compared). An intact capture (gold, simulated, 128²) spends about 700
  // per integrated point on average (docs/robustness.md, issue 20 finding 2); a source whose
  // values are noise, or whose image is black at the coarse level, would otherwise refine every
  // cell down to the map's pixels at every point (about 260 000 for a 1024 × 512 map).
  std::uint64_t max_evaluations = 16384;
};

// Outgoing radiance of one shading point by the adaptive quadrature. The frame (s, t, n) is the
// pixel's local frame expressed in the map's frame (preview_internal.h Frame, rotated by the
// map rotation); wo is the view direction in that local frame.
class HierarchicalIntegrator {
 public:
  HierarchicalIntegrator(const MapHierarchy& map, const BrdfSource& source,
                         HierarchicalSettings settings)
      : map_(map),
        source_(source),
        settings_(settings),
        horizon_level_(LevelOf(map, settings.horizon_columns)),
        mirror_level_(LevelOf(map, settings.mirror_columns)),
        size_factors_(SizeFactors(map)) {}

  // `scale`: the luminance the tolerance is relative to (the image's mean absolute luminance, so
  // that the error is bounded relative to it as the benchmark's RMS measures it; its sign is
  // ignored, so that negated values refine exactly as the intact ones). `top_only`: the
  // top level's estimate alone (no refinement), for finding that scale cheaply.
  // `evaluations` is incremented by the f_r evaluations made.
  Rgb Radiance(const Vec3& s, const Vec3& t, const Vec3& n, const Vec3& wo, double scale,
               bool top_only, std::uint64_t* evaluations) const;

 private:
  struct Query;
  struct CellSums {
    double e[3] = {0, 0, 0}, m[3] = {0, 0, 0}, y = 0;
  };
  // Appends to the query's leaf list the contributions (CellSums) of the part of cell
  // (level, i, j) above the horizon, in a fixed order, and notes where each straddling
  // descendant's own contributions lie in it, so that estimating that descendant later sums the
  // same numbers in the same order without walking its subtree again.
  void Clip(const Query& q, int level, int i, int j, int stop) const;
  // The CellSums of the part of straddling cell (level, i, j) above the horizon.
  CellSums ClippedSums(const Query& q, int level, int i, int j) const;
  Rgb Estimate(const Query& q, int level, int i, int j, bool straddles) const;
  Rgb Refine(const Query& q, int level, int i, int j, const Rgb& estimate) const;

  // The coarsest level at least `columns` wide (0 when the map itself is narrower).
  static int LevelOf(const MapHierarchy& map, int columns) {
    int level = 0;
    while (level + 1 < map.levels() && map.width(level + 1) >= columns) ++level;
    return level;
  }

  // The split threshold's factor for each cell's size ((Ω/2π)^0.1, hierarchical.cpp), per level
  // and row: [0] for the row's cells, [1] for its last one (narrower where the map's width is
  // not a multiple of the level's span). Taken once here: std::pow per refined cell was ~2.5 %
  // of a preview's time.
  using RowFactors = std::vector<std::array<double, 2>>;
  static std::vector<RowFactors> SizeFactors(const MapHierarchy& map);
  double SizeFactorOf(int level, int i, int j) const {
    return size_factors_[level][j][i + 1 == map_.width(level) ? 1 : 0];
  }

  const MapHierarchy& map_;
  const BrdfSource& source_;
  HierarchicalSettings settings_;
  int horizon_level_, mirror_level_;
  std::vector<RowFactors> size_factors_;
};

}  // namespace brdf::preview::detail
