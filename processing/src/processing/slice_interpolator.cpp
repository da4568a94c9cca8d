#include "slice_interpolator.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <limits>
#include <string>

#include "brdf/core/error.h"

namespace brdf::processing::detail {
namespace {

// Lattice coordinates of float32 angles agree to ~1e-5°; 1e-3° separates distinct lattice
// lines of any realistic instrument (steps ≥ 0.05°, checked below).
constexpr double kAngleTolDeg = 1e-3;
constexpr double kMinStepDeg = 0.05;
constexpr int kRingSize = 3600;  // horizon table of the scattered method: 0.1° steps

std::string SliceName(const Slice& slice, std::size_t index) {
  return "slice " + std::to_string(index) + " (θin = " + NumberText(slice.theta_in_deg) + "°)";
}

// Distinct values (within kAngleTolDeg) of angles in [0°, range]: how many, the first and
// last cluster and the smallest distance between neighbouring clusters. A bitmap of half-
// tolerance bins makes this linear in the number of values (a sort of every sample's angle
// was a tenth of the whole resampling time).
struct Clusters {
  int count = 0;
  double first = 0, last = 0;
  double min_gap = std::numeric_limits<double>::infinity();
};

// `angle(point)` returns the angle to cluster, or a negative value to skip the point.
template <class AngleOf>
Clusters FindClusters(const std::vector<Point>& points, double range_deg, AngleOf angle) {
  constexpr double kBin = kAngleTolDeg / 2;
  const std::size_t n_bins = static_cast<std::size_t>(range_deg / kBin) + 2;
  std::vector<std::uint64_t> bits((n_bins + 63) / 64, 0);
  for (const Point& p : points) {
    const double v = angle(p);
    if (v < 0.0) continue;
    const auto b = std::min(static_cast<std::size_t>(v * (1.0 / kBin) + 0.5), n_bins - 1);
    bits[b >> 6] |= std::uint64_t{1} << (b & 63);
  }
  Clusters c;
  std::ptrdiff_t prev = -1000, start = -1;
  for (std::size_t w = 0; w < bits.size(); ++w) {
    for (std::uint64_t word = bits[w]; word != 0; word &= word - 1) {
      const auto b =
          static_cast<std::ptrdiff_t>(w * 64 + static_cast<std::size_t>(std::countr_zero(word)));
      if (b - prev > 2) {  // more than kAngleTolDeg after the previous value: a new cluster
        if (start >= 0)
          c.min_gap = std::min(c.min_gap, static_cast<double>(b - start) * kBin);
        else
          c.first = static_cast<double>(b) * kBin;
        start = b;
        ++c.count;
      }
      prev = b;
    }
  }
  c.last = static_cast<double>(start) * kBin;
  return c;
}

}  // namespace

void CheckSliceThetaIn(const Slice& slice, std::size_t slice_index) {
  if (!(slice.theta_in_deg >= 0.0 && slice.theta_in_deg < 90.0))
    throw InvalidArgument(SliceName(slice, slice_index) +
                          ": θin must be in [0°, 90°) for a reflection measurement");
  if (!std::isfinite(slice.phi_in_deg))
    throw InvalidArgument(SliceName(slice, slice_index) + ": φin is not a finite number");
}

namespace {

// The per-channel defect names of SampleDefect (static strings: messages quote them).
constexpr const char* kNotFinite[3] = {"red value not a finite number",
                                       "green value not a finite number",
                                       "blue value not a finite number"};
constexpr const char* kTooNegative[3] = {
    "red f_r negative beyond noise (below the slice's noise allowance)",
    "green f_r negative beyond noise (below the slice's noise allowance)",
    "blue f_r negative beyond noise (below the slice's noise allowance)"};
constexpr const char* kTooLarge[3] = {
    "red f_r·cosθout above 1e5 1/sr (more than a perfect mirror reflects)",
    "green f_r·cosθout above 1e5 1/sr (more than a perfect mirror reflects)",
    "blue f_r·cosθout above 1e5 1/sr (more than a perfect mirror reflects)"};

// cosθout of a sample as the upper bound uses it (docs/design.md §4): at least cos 89°, so a
// sample on the horizon is bounded too.
double BoundCos(const Sample& s) {
  return std::max(std::cos(DegToRad(std::fabs(static_cast<double>(s.theta_out_deg)))),
                  kMinBoundCos);
}

}  // namespace

// Both checks below read the bound v·cosθout > kMaxFrCosPerSr only for v above it: cosθout
// (BoundCos) is in (0, 1], so v·cosθout ≤ v exactly (rounding is monotone) and a value at
// most kMaxFrCosPerSr never exceeds the bound. The cosine, most of a sample's check, is then
// computed only for values above 10⁵ 1/sr; the outcome is the same for every sample.
double NegativeAllowance(const Slice& slice) {
  double peak = 0;
  for (const Sample& s : slice.samples) {
    if (s.flags & kFlagInvalid) continue;
    for (float v : s.rgb)
      if (std::isfinite(v) && (v <= kMaxFrCosPerSr || v * BoundCos(s) <= kMaxFrCosPerSr))
        peak = std::max(peak, static_cast<double>(v));
  }
  return std::max(kNegativeFloorPerSr, kNegativeFractionOfPeak * peak);
}

const char* SampleDefect(const Sample& s, std::optional<double> negative_allowance) {
  if (s.flags & kFlagInvalid) return nullptr;
  const double theta = s.theta_out_deg;
  if (!(theta >= -90.0 && theta <= 90.0)) return "θout outside [−90°, 90°]";
  if (!std::isfinite(s.phi_out_deg)) return "φout not a finite number";
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(s.rgb[c])) return kNotFinite[c];
  if (!negative_allowance) return nullptr;
  for (int c = 0; c < 3; ++c) {
    const double v = s.rgb[c];
    // σ widens the allowance only when it is a finite, non-negative number.
    const double sigma = s.sigma[c] >= 0.0f && std::isfinite(s.sigma[c]) ? s.sigma[c] : 0.0;
    if (v < -std::max(*negative_allowance, kNegativeSigmas * sigma)) return kTooNegative[c];
    if (v > kMaxFrCosPerSr && v * BoundCos(s) > kMaxFrCosPerSr) return kTooLarge[c];
  }
  return nullptr;
}

CleanSlice CleanSliceSamples(const Slice& slice, std::size_t slice_index,
                             bool check_measured_values) {
  CleanSlice out;
  const std::optional<double> allowance =
      check_measured_values ? std::optional<double>(NegativeAllowance(slice)) : std::nullopt;
  out.points.reserve(slice.samples.size());
  for (std::size_t n = 0; n < slice.samples.size(); ++n) {
    const Sample& s = slice.samples[n];
    if (s.flags & kFlagInvalid) {
      ++out.invalid;
      continue;
    }
    const auto where = [&] {
      return SliceName(slice, slice_index) + ", sample " + std::to_string(n);
    };
    double theta = s.theta_out_deg;
    double phi = s.phi_out_deg;
    if (const char* defect = SampleDefect(s, allowance))
      throw InvalidArgument(where() + ": " + defect +
                            " (a sample without a usable value must be flagged invalid)");
    if (theta < 0) {  // in-plane goniometer convention: −θ is the opposite azimuth
      theta = -theta;
      phi += 180.0;
    }
    phi -= slice.phi_in_deg;
    if (!(phi >= 0.0 && phi < 360.0)) phi = WrapDeg360(phi);  // fmod only when needed
    Point p;
    p.theta_deg = theta;
    p.phi_deg = phi;
    p.value = {s.rgb[0], s.rgb[1], s.rgb[2]};
    out.max_theta_deg = std::max(out.max_theta_deg, theta);
    out.points.push_back(p);
  }
  if (out.points.empty())
    throw InvalidArgument(SliceName(slice, slice_index) + ": no valid sample (" +
                          std::to_string(slice.samples.size()) + " samples, " +
                          std::to_string(out.invalid) + " flagged invalid); cannot interpolate");
  return out;
}

ScatteredInterpolator::ScatteredInterpolator(const std::vector<Point>& points, int neighbours) {
  const std::size_t n = points.size();
  k_ = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(neighbours), n));
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  double max_theta = 0;
  std::vector<Vec3> dirs(n);
  for (std::size_t i = 0; i < n; ++i)
    dirs[i] = SphericalDirectionDeg(points[i].theta_deg, points[i].phi_deg);
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = points[i];
    const double c[3] = {dirs[i].x, dirs[i].y, dirs[i].z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c[a]);
      hi[a] = std::max(hi[a], c[a]);
    }
    max_theta = std::max(max_theta, DegToRad(p.theta_deg));
  }
  // Mean spacing of n samples spread over the cap they occupy; cells of 2.5 spacings hold the
  // k ≈ 16 nearest neighbours of a typical query within the first shell of 27 cells.
  const double cap = std::max(2.0 * kPi * (1.0 - std::cos(max_theta)), 1e-4);
  const double spacing = std::sqrt(cap / static_cast<double>(n));
  cell_ = std::clamp(2.5 * spacing, 1e-4, 2.0);
  const std::size_t max_cells = std::max<std::size_t>(4096, 4 * n);
  for (;;) {
    std::size_t total = 1;
    for (int a = 0; a < 3; ++a) {
      dims_[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / cell_)) + 1;
      total *= static_cast<std::size_t>(dims_[a]);
    }
    if (total <= max_cells) break;
    cell_ *= 1.5;
  }
  for (int a = 0; a < 3; ++a) origin_[a] = lo[a];
  const auto cell_of = [&](const Vec3& d) {
    const double c[3] = {d.x, d.y, d.z};
    int idx[3];
    for (int a = 0; a < 3; ++a)
      idx[a] =
          std::clamp(static_cast<int>(std::floor((c[a] - origin_[a]) / cell_)), 0, dims_[a] - 1);
    return (static_cast<std::size_t>(idx[2]) * dims_[1] + idx[1]) * dims_[0] + idx[0];
  };
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  cell_start_.assign(cells + 1, 0);
  std::vector<std::size_t> cell_index(n);
  for (std::size_t i = 0; i < n; ++i) {
    cell_index[i] = cell_of(dirs[i]);
    ++cell_start_[cell_index[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  pos_.resize(n);
  val_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t at = fill[cell_index[i]]++;
    pos_[at] = dirs[i];
    val_[at] = points[i].value;
  }
}

Rgb ScatteredInterpolator::At(const Vec3& q) const {
  // k nearest by squared chord distance, kept sorted (k ≤ 64: insertion is cheapest).
  constexpr int kMaxK = 64;
  double best_d2[kMaxK];
  std::uint32_t best_i[kMaxK];
  int count = 0;
  const double qc[3] = {q.x, q.y, q.z};
  int ci[3];
  for (int a = 0; a < 3; ++a)
    ci[a] = std::clamp(static_cast<int>(std::floor((qc[a] - origin_[a]) / cell_)), 0, dims_[a] - 1);
  const auto visit = [&](int x, int y, int z) {
    const std::size_t c = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
    for (std::uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) {
      const Vec3 d = pos_[i] - q;
      const double d2 = Dot(d, d);
      if (count == k_ && d2 >= best_d2[k_ - 1]) continue;
      int at = count < k_ ? count++ : k_ - 1;
      while (at > 0 && best_d2[at - 1] > d2) {
        best_d2[at] = best_d2[at - 1];
        best_i[at] = best_i[at - 1];
        --at;
      }
      best_d2[at] = d2;
      best_i[at] = i;
    }
  };
  const int max_r = std::max({dims_[0], dims_[1], dims_[2]});
  for (int r = 0; r <= max_r; ++r) {
    // Every cell of shell r is at least (r − 1) cells away from the query's (clamped) cell, and
    // clamping a query outside the grid onto it only shortens distances (projection on a box).
    if (count == k_ && r >= 1 && best_d2[k_ - 1] <= (r - 1) * cell_ * (r - 1) * cell_) break;
    const int z0 = std::max(ci[2] - r, 0), z1 = std::min(ci[2] + r, dims_[2] - 1);
    const int y0 = std::max(ci[1] - r, 0), y1 = std::min(ci[1] + r, dims_[1] - 1);
    const int x0 = std::max(ci[0] - r, 0), x1 = std::min(ci[0] + r, dims_[0] - 1);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) {
        if (std::abs(z - ci[2]) == r || std::abs(y - ci[1]) == r) {
          for (int x = x0; x <= x1; ++x) visit(x, y, z);
        } else {
          if (ci[0] - r >= 0) visit(ci[0] - r, y, z);
          if (r > 0 && ci[0] + r < dims_[0]) visit(ci[0] + r, y, z);
        }
      }
  }

  // Tangent basis at q.
  const Vec3 a = std::fabs(q.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0};
  const Vec3 e1 =
      Normalize(Vec3{q.y * a.z - q.z * a.y, q.z * a.x - q.x * a.z, q.x * a.y - q.y * a.x});
  const Vec3 e2{q.y * e1.z - q.z * e1.y, q.z * e1.x - q.x * e1.z, q.x * e1.y - q.y * e1.x};

  const double h = std::sqrt(best_d2[count - 1]);
  double m[6] = {0, 0, 0, 0, 0, 0};  // A00 A01 A02 A11 A12 A22
  double b[3][3] = {};               // [channel][row]
  Rgb lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  bool any_weight = false;
  for (int pass = 0; pass < 2 && !any_weight; ++pass) {
    for (int n = 0; n < count; ++n) {
      double w;
      if (pass == 0) {
        if (h <= 0) continue;
        const double s = std::sqrt(best_d2[n]) / h;
        if (s >= 1.0) continue;
        const double t = 1.0 - s;
        w = t * t * t * t * (4.0 * s + 1.0);  // Wendland C2: smooth, zero at the radius
      } else {
        w = 1.0;  // all neighbours at the same distance: plain mean
      }
      any_weight = true;
      const Vec3& p = pos_[best_i[n]];
      const double u = h > 0 ? Dot(p, e1) / h : 0.0, v = h > 0 ? Dot(p, e2) / h : 0.0;
      m[0] += w;
      m[1] += w * u;
      m[2] += w * v;
      m[3] += w * u * u;
      m[4] += w * u * v;
      m[5] += w * v * v;
      const Rgb& f = val_[best_i[n]];
      for (int c = 0; c < 3; ++c) {
        b[c][0] += w * f[c];
        b[c][1] += w * f[c] * u;
        b[c][2] += w * f[c] * v;
        lo[c] = std::min(lo[c], f[c]);
        hi[c] = std::max(hi[c], f[c]);
      }
    }
  }

  Rgb out;
  // Cholesky of the 3×3 normal matrix; a (near-)singular one means the neighbours do not span
  // the tangent plane (collinear, or one point), and the weighted mean is the honest answer.
  const double eps = 1e-7 * m[0];
  const double l00 = std::sqrt(m[0]);
  const double l10 = m[1] / l00, l20 = m[2] / l00;
  const double d1 = m[3] - l10 * l10;
  bool linear = d1 > eps;
  double l11 = 0, l21 = 0, l22 = 0;
  if (linear) {
    l11 = std::sqrt(d1);
    l21 = (m[4] - l20 * l10) / l11;
    const double d2 = m[5] - l20 * l20 - l21 * l21;
    linear = d2 > eps;
    if (linear) l22 = std::sqrt(d2);
  }
  for (int c = 0; c < 3; ++c) {
    double value;
    if (linear) {
      const double y0 = b[c][0] / l00;
      const double y1 = (b[c][1] - l10 * y0) / l11;
      const double y2 = (b[c][2] - l20 * y0 - l21 * y1) / l22;
      const double x2 = y2 / l22;
      const double x1 = (y1 - l21 * x2) / l11;
      value = (y0 - l10 * x1 - l20 * x2) / l00;
    } else {
      value = b[c][0] / m[0];
    }
    out[c] = std::clamp(value, lo[c], hi[c]);
  }
  return out;
}

std::optional<RegularGrid> DetectRegularGrid(const std::vector<Point>& points,
                                             std::vector<std::size_t>& holes) {
  holes.clear();
  if (points.size() < 8) return std::nullopt;
  double theta_max = 0, phi_min = 360.0;
  std::size_t off_pole = 0;
  for (const Point& p : points) {
    theta_max = std::max(theta_max, p.theta_deg);
    if (p.theta_deg > kAngleTolDeg) {
      phi_min = std::min(phi_min, p.phi_deg);
      ++off_pole;
    }
  }
  const Clusters rows = FindClusters(points, 90.0, [](const Point& p) { return p.theta_deg; });
  const double d_theta = rows.min_gap;
  if (!(d_theta >= kMinStepDeg) || off_pole == 0) return std::nullopt;
  const Clusters columns = FindClusters(points, 360.0, [](const Point& p) {
    return p.theta_deg > kAngleTolDeg ? p.phi_deg : -1.0;  // the pole has no azimuth
  });
  double d_phi_min = columns.min_gap;
  const double wrap_gap = columns.first + 360.0 - columns.last;
  if (wrap_gap > kAngleTolDeg) d_phi_min = std::min(d_phi_min, wrap_gap);
  if (!(d_phi_min >= kMinStepDeg)) return std::nullopt;
  const int n_phi = static_cast<int>(std::lround(360.0 / d_phi_min));
  const long n_theta_l = std::lround(theta_max / d_theta) + 1;
  if (n_phi < 4 || n_theta_l < 2) return std::nullopt;
  const auto n_theta = static_cast<int>(n_theta_l);
  // At least half of the non-pole nodes must be measured, which also bounds the allocation.
  const std::size_t nodes = static_cast<std::size_t>(n_theta - 1) * static_cast<std::size_t>(n_phi);
  if (nodes > 2 * off_pole) return std::nullopt;

  RegularGrid g;
  g.n_theta = n_theta;
  g.n_phi = n_phi;
  // Snap the steps to the lattice they describe (float32 angles carry ~1e-5° of noise); the
  // smallest φ is a lattice column (a sample near 360° is one near 0°, checked below).
  g.d_theta = theta_max / (n_theta - 1);
  g.d_phi = 360.0 / n_phi;
  g.phi0 = phi_min;
  g.inv_d_theta = 1.0 / g.d_theta;
  g.inv_d_phi = 1.0 / g.d_phi;
  const std::size_t total = static_cast<std::size_t>(n_theta) * static_cast<std::size_t>(n_phi);
  g.values.assign(total * 3, 0.0);
  std::vector<std::uint32_t> count(total, 0);
  Rgb pole_sum{};
  std::size_t pole_count = 0;
  for (const Point& p : points) {
    if (p.theta_deg <= kAngleTolDeg) {
      for (int c = 0; c < 3; ++c) pole_sum[c] += p.value[c];
      ++pole_count;
      continue;
    }
    // Both quotients are > −1 (θ > 0, φ ≥ φ0 − tolerance), so truncating x + 0.5 rounds.
    const auto j = static_cast<long>(p.theta_deg * g.inv_d_theta + 0.5);
    if (j < 1 || j >= n_theta || std::fabs(p.theta_deg - j * g.d_theta) > kAngleTolDeg)
      return std::nullopt;
    const double u = (p.phi_deg - g.phi0) * g.inv_d_phi;
    auto i = static_cast<long>(u + 0.5);
    if (std::fabs(p.phi_deg - g.phi0 - i * g.d_phi) > kAngleTolDeg) return std::nullopt;
    if (i >= n_phi) i -= n_phi;  // φ just below 360° is the column at φ0
    const std::size_t node = static_cast<std::size_t>(j) * n_phi + static_cast<std::size_t>(i);
    for (int c = 0; c < 3; ++c) g.values[node * 3 + c] += p.value[c];
    ++count[node];
  }
  for (std::size_t node = static_cast<std::size_t>(n_phi); node < total; ++node) {
    if (count[node] == 0) {
      holes.push_back(node);
    } else if (count[node] > 1) {  // repeated measurements of one direction: their mean
      for (int c = 0; c < 3; ++c) g.values[node * 3 + c] /= count[node];
    }
  }
  // The pole row: every φ names the same direction, so all pole samples are one value.
  if (pole_count > 0) {
    for (int i = 0; i < n_phi; ++i)
      for (int c = 0; c < 3; ++c)
        g.values[static_cast<std::size_t>(i) * 3 + c] = pole_sum[c] / pole_count;
  } else {
    for (int i = 0; i < n_phi; ++i) holes.push_back(static_cast<std::size_t>(i));
  }
  return g;
}

SliceInterpolator::SliceInterpolator(const Slice& slice, std::size_t slice_index,
                                     const ResampleOptions& options) {
  CheckSliceThetaIn(slice, slice_index);
  CleanSlice clean = CleanSliceSamples(slice, slice_index, options.check_measured_values);
  report_.theta_in_deg = slice.theta_in_deg;
  report_.valid_samples = clean.points.size();
  report_.invalid_samples = clean.invalid;
  report_.max_theta_out_deg = clean.max_theta_deg;
  std::vector<std::size_t> holes;
  if (options.allow_regular_grid) grid_ = DetectRegularGrid(clean.points, holes);
  if (!grid_ || !holes.empty())
    scattered_ = std::make_unique<ScatteredInterpolator>(clean.points, options.neighbours);
  if (grid_) {
    report_.method = InterpolationMethod::kRegularGrid;
    report_.grid_step_theta_deg = grid_->d_theta;
    report_.grid_step_phi_deg = grid_->d_phi;
    bool pole_filled = false;
    Rgb pole{};
    for (std::size_t node : holes) {
      const int j = static_cast<int>(node / grid_->n_phi),
                i = static_cast<int>(node % grid_->n_phi);
      Rgb v;
      if (j == 0) {  // the pole is one direction: fill it once
        if (!pole_filled) pole = scattered_->At(Vec3{0, 0, 1});
        pole_filled = true;
        v = pole;
      } else {
        v = scattered_->At(
            SphericalDirectionDeg(j * grid_->d_theta, grid_->phi0 + i * grid_->d_phi));
        ++report_.filled_nodes;
      }
      for (int c = 0; c < 3; ++c) grid_->values[node * 3 + c] = v[c];
    }
    if (pole_filled) ++report_.filled_nodes;
    scattered_.reset();  // the filled lattice is the interpolant from here on
  } else {
    report_.method = InterpolationMethod::kScattered;
  }
}

void SliceInterpolator::PrepareHorizon(double theta_b_deg) {
  theta_b_deg_ = theta_b_deg;
  horizon_mean_ = {0, 0, 0};
  if (grid_) {
    // f(θb, φ) is piecewise linear between the lattice columns: its circular mean is the mean
    // of the column values.
    for (int i = 0; i < grid_->n_phi; ++i) {
      const Rgb v = grid_->At(theta_b_deg, grid_->phi0 + i * grid_->d_phi);
      for (int c = 0; c < 3; ++c) horizon_mean_[c] += v[c] / grid_->n_phi;
    }
    return;
  }
  ring_.resize(kRingSize);
  for (int n = 0; n < kRingSize; ++n) {
    const double phi = n * (360.0 / kRingSize);
    const Rgb v = scattered_->At(SphericalDirectionDeg(theta_b_deg, phi));
    ring_[static_cast<std::size_t>(n)] = v;
    for (int c = 0; c < 3; ++c) horizon_mean_[c] += v[c] / kRingSize;
  }
}

Rgb SliceInterpolator::RingAt(double phi_deg) const {
  double u = phi_deg * (kRingSize / 360.0);
  u -= std::floor(u / kRingSize) * kRingSize;
  int i0 = static_cast<int>(u);
  if (i0 >= kRingSize) i0 = 0;
  const double t = u - i0;
  const int i1 = i0 + 1 == kRingSize ? 0 : i0 + 1;
  const Rgb& a = ring_[static_cast<std::size_t>(i0)];
  const Rgb& b = ring_[static_cast<std::size_t>(i1)];
  return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

}  // namespace brdf::processing::detail
