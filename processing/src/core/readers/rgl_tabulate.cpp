// RglBrdf::Tabulate: the tabulated form of an RGL file (rgl.h, RglTabulatedBrdf), and the
// quadrature approximation.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "brdf/core/error.h"
#include "brdf/core/parallel.h"
#include "brdf/core/rgl.h"
#include "readers/rgl_eval.h"
#include "readers/rgl_internal.h"

namespace brdf {

using detail::Cell;
using detail::Clamp01;
using detail::CoordinatesSingle;
using detail::Corners;
using detail::Interpolant2;
using detail::Locate;
using detail::PairCoordinates;
using detail::PhiToU;

// The tabulated form (rgl.h, RglTabulatedBrdf).
//
// Incidence: interval j of theta_i holds K_j slots (incidence samples) at weights m/K_j
// (m = 0 … K_j − 1) of the way from theta_i[j] to theta_i[j + 1]; the last node is the final
// slot. So the slots blend as RglBrdf's slices do and every node is a slot.
// u(θm) and u(φm − φi): VNDF cell k (between vertices k and k + 1) holds cells[k] table cells of
// equal width, starting at table vertex offset[k] (TableAxis), more where the warp is steep.
// Storage: vertex (x, y) of slot s holds R, G, B as 16-bit fractions of the slot's per-channel
// maximum `scale[4 s + ch]` (scale[4 s + 3] = 0), at texel ((s·ny + y)·nx + x), 6 bytes each: a
// lookup's two x-neighbours are 12 contiguous bytes, and a real file's table a few MB.
namespace {

// One axis of the table: the VNDF grid's `n` even vertices over [0, 1], cell k split into
// cells[k] equal table cells starting at table vertex offset[k].
struct TableAxis {
  int n = 0, vertices = 0;
  std::vector<double> offset, cells;

  // Table cells per VNDF cell from `rate` (how many RGB cells the warped coordinate crosses in
  // each VNDF cell), as RglTabulationSettings says.
  static TableAxis FromRates(const std::vector<double>& rate, double cells_per_rgb_cell,
                             int max_cells) {
    TableAxis a;
    a.n = static_cast<int>(rate.size()) + 1;
    double total = 0.0;
    for (const double r : rate) {
      const double wanted = std::ceil(r * cells_per_rgb_cell - 1e-9);
      const double c = std::clamp(wanted, 1.0, static_cast<double>(max_cells));
      a.offset.push_back(total);
      a.cells.push_back(c);
      total += c;
    }
    a.vertices = static_cast<int>(total) + 1;
    return a;
  }
  // The unit-square coordinate of every table vertex.
  std::vector<double> Positions() const {
    std::vector<double> u(static_cast<std::size_t>(vertices));
    for (std::size_t k = 0; k < cells.size(); ++k)
      for (int i = 0; i <= static_cast<int>(cells[k]); ++i)
        u[static_cast<std::size_t>(offset[k]) + i] =
            (static_cast<double>(k) + i / cells[k]) / static_cast<double>(n - 1);
    return u;
  }
  Cell Map(double u) const {
    const Cell c = Locate(u, n);
    const double t = offset[c.i] + cells[c.i] * c.f;
    const int i = std::min(static_cast<int>(t), vertices - 2);
    return {i, t - i};
  }
};

}  // namespace

struct RglTabulatedBrdf::Table {
  // Per incidence sample: θi (rad) and 1 / (distance to the next; 0 for the last). bin_slot[b]:
  // the last sample at or below slot_theta[0] + b / bins_per_rad.
  std::vector<double> slot_theta, slot_inv_step;
  std::vector<std::uint16_t> bin_slot;
  double bins_per_rad = 0.0;
  TableAxis ax, ay;  // along u(θm) and u(φm − φi)
  int slots = 1, nx = 0, ny = 0;
  std::vector<std::uint16_t> texels;
  std::vector<float> scale;
  Interpolant2 ndf;
  bool ndf_same_for_all_phi = false;  // then its first row alone is looked up
  double self_check_p99 = 0.0;
  bool jacobian = true;

  Rgb EvalCosine(const Vec3& wi, const Vec3& wo, bool divide_by_cos) const {
    PairCoordinates p;
    if (!CoordinatesSingle(wi, wo, p)) return {0.0, 0.0, 0.0};
    // The incidence sample at or below θi: from the bin of θi, then at most a step or two up
    // (bins are no wider than the closest two samples, so usually none).
    const double theta = p.theta_i_rad;
    const double bin_position = (theta - slot_theta[0]) * bins_per_rad;
    const int bin =
        std::clamp(static_cast<int>(bin_position), 0, static_cast<int>(bin_slot.size()) - 1);
    int s0 = bin_slot[static_cast<std::size_t>(bin)];
    while (s0 + 2 < slots && theta >= slot_theta[static_cast<std::size_t>(s0) + 1]) ++s0;
    const int s1 = std::min(s0 + 1, slots - 1);
    const double ft = Clamp01((theta - slot_theta[static_cast<std::size_t>(s0)]) *
                              slot_inv_step[static_cast<std::size_t>(s0)]);
    const Cell cx = ax.Map(p.um_x), cy = ay.Map(p.um_y);
    const double fx = cx.f;
    const std::size_t row = 3 * static_cast<std::size_t>(nx);
    const std::size_t at =
        row * static_cast<std::size_t>(cy.i) + 3 * static_cast<std::size_t>(cx.i);
    const std::uint16_t* t0 = texels.data() + row * ny * static_cast<std::size_t>(s0) + at;
    const std::uint16_t* t1 = texels.data() + row * ny * static_cast<std::size_t>(s1) + at;
    const float w00 = static_cast<float>((1 - fx) * (1 - cy.f)),
                w10 = static_cast<float>(fx * (1 - cy.f)),
                w01 = static_cast<float>((1 - fx) * cy.f), w11 = static_cast<float>(fx * cy.f);
    Rgb f;
#if defined(__SSE2__)
    // Three 16-bit channels per vertex: one 8-byte load each (its fourth lane, the next
    // vertex's R or the tail pad, is multiplied by the scale's 0), widened to float.
    const __m128i zero = _mm_setzero_si128();
    auto texel = [&](const std::uint16_t* q) {
      return _mm_cvtepi32_ps(
          _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q)), zero));
    };
    auto corners = [&](const std::uint16_t* q, int slot, double weight) {
      __m128 a = _mm_mul_ps(texel(q), _mm_set1_ps(w00));
      a = _mm_add_ps(a, _mm_mul_ps(texel(q + 3), _mm_set1_ps(w10)));
      a = _mm_add_ps(a, _mm_mul_ps(texel(q + row), _mm_set1_ps(w01)));
      a = _mm_add_ps(a, _mm_mul_ps(texel(q + row + 3), _mm_set1_ps(w11)));
      return _mm_mul_ps(a, _mm_mul_ps(_mm_loadu_ps(scale.data() + 4 * slot),
                                      _mm_set1_ps(static_cast<float>(weight))));
    };
    alignas(16) float out[4];
    _mm_store_ps(out, _mm_add_ps(corners(t0, s0, 1 - ft), corners(t1, s1, ft)));
    for (int ch = 0; ch < 3; ++ch) f[ch] = out[ch];
#else
    for (int ch = 0; ch < 3; ++ch) {
      auto corners = [&](const std::uint16_t* q, int slot) {
        return (w00 * q[ch] + w10 * q[3 + ch] + w01 * q[row + ch] + w11 * q[row + 3 + ch]) *
               static_cast<double>(scale[4 * slot + ch]);
      };
      f[ch] = (1 - ft) * corners(t0, s0) + ft * corners(t1, s1);
    }
#endif
    // The slot scales hold 1 / 4σ; what is left of rgl.h's step 3 is ndf(u_m) [/ cosθo].
    double factor = 1.0;
    if (jacobian) {
      if (ndf_same_for_all_phi) {
        const Cell cn = Locate(p.um_x, ndf.nx);
        factor = (1 - cn.f) * ndf.v[cn.i] + cn.f * ndf.v[cn.i + 1];
      } else {
        factor = ndf.Eval(p.um_x, p.um_y);
      }
    }
    if (divide_by_cos) factor /= wo.z;
    for (double& v : f) v *= factor;
    return f;
  }
};

RglTabulatedBrdf::RglTabulatedBrdf(std::unique_ptr<Table> table, std::string name)
    : table_(std::move(table)), name_(std::move(name)) {}
RglTabulatedBrdf::RglTabulatedBrdf(RglTabulatedBrdf&&) noexcept = default;
RglTabulatedBrdf& RglTabulatedBrdf::operator=(RglTabulatedBrdf&&) noexcept = default;
RglTabulatedBrdf::~RglTabulatedBrdf() = default;

Rgb RglTabulatedBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  return table_->EvalCosine(wi, wo, true);
}
Rgb RglTabulatedBrdf::EvalCosine(const Vec3& wi, const Vec3& wo) const {
  return table_->EvalCosine(wi, wo, false);
}
std::size_t RglTabulatedBrdf::table_bytes() const {
  return table_->texels.size() * sizeof(std::uint16_t) + table_->scale.size() * sizeof(float);
}
int RglTabulatedBrdf::incidence_samples() const { return table_->slots; }
int RglTabulatedBrdf::vertices_theta() const { return table_->nx; }
int RglTabulatedBrdf::vertices_phi() const { return table_->ny; }
double RglTabulatedBrdf::self_check_p99_error() const { return table_->self_check_p99; }

namespace {

// RglTabulatedBrdf::self_check_p99_error: the table against the exact evaluator at fixed
// pseudo-random pairs (SplitMix64, so every build checks the same pairs).
double SelfCheckP99(const RglBrdf& exact, const RglTabulatedBrdf& table) {
  std::uint64_t state = 0x5eed5eed12345678ull;
  auto next = [&] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  constexpr int kPairs = 16384;
  std::vector<std::array<double, 6>> values;  // exact, tabulated per channel
  values.reserve(kPairs);
  std::array<double, 3> peak{0, 0, 0};
  for (int k = 0; k < kPairs; ++k) {
    const double theta_i = std::acos(std::sqrt(1.0 - next())), phi_i = 2 * kPi * next();
    const Vec3 wi = SphericalDirection(theta_i, phi_i);
    Vec3 wo;
    if (k % 2 == 0) {
      wo = SphericalDirection(std::acos(std::sqrt(1.0 - next())), 2 * kPi * next());
    } else {  // within ±4° (uniform) of the mirror direction in θ and φ
      const double spread = 4.0 * kPi / 180.0;
      const double theta_o = std::abs(theta_i + spread * (2 * next() - 1));
      wo = SphericalDirection(std::min(theta_o, 0.5 * kPi - 1e-3),
                              phi_i + kPi + spread * (2 * next() - 1));
    }
    const Rgb a = exact.EvalCosine(wi, wo), b = table.EvalCosine(wi, wo);
    values.push_back({a[0], a[1], a[2], b[0], b[1], b[2]});
    for (int ch = 0; ch < 3; ++ch) peak[ch] = std::max(peak[ch], a[ch]);
  }
  std::vector<double> rel;
  for (const auto& v : values)
    for (int ch = 0; ch < 3; ++ch)
      if (v[ch] > 0.0 && v[ch] >= 0.01 * peak[ch])
        rel.push_back(std::abs(v[3 + ch] - v[ch]) / v[ch]);
  if (rel.empty()) return 0.0;
  const std::size_t at = rel.size() * 99 / 100;
  std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(at), rel.end());
  return rel[at];
}

}  // namespace

std::unique_ptr<RglTabulatedBrdf> RglBrdf::Tabulate(const RglTabulationSettings& settings) const {
  const RglTabulationSettings& o = settings;
  if (!(o.incidence_tolerance > 0.0) || !(o.cells_per_rgb_cell > 0.0) ||
      !std::isfinite(o.incidence_tolerance + o.cells_per_rgb_cell) ||
      o.max_samples_per_interval < 1 || o.max_samples_per_interval > 64 ||
      o.max_cells_per_vndf_cell < 1 || o.max_cells_per_vndf_cell > 64)
    throw InvalidArgument(
        "RGL tabulation: the incidence tolerance and cells per RGB cell must be finite and > 0, "
        "the largest samples per interval and cells per VNDF cell between 1 and 64");
  const Tables& e = *tables_;
  if (!e.relative_phi_only) return nullptr;
  auto t = std::make_unique<RglTabulatedBrdf::Table>();
  t->ndf = e.ndf;
  t->ndf_same_for_all_phi = true;
  for (int y = 1; y < e.ndf.ny; ++y)
    for (int x = 0; x < e.ndf.nx; ++x)
      t->ndf_same_for_all_phi &= e.ndf.v[static_cast<std::size_t>(y) * e.ndf.nx + x] == e.ndf.v[x];
  t->jacobian = e.info.jacobian;
  // Table cells per VNDF cell. Along u(θm): X, the conditional CDF the RGB table is indexed
  // by, changes by density / row total per VNDF cell (the warp tables are normalised over the
  // index domain). Along u(φm): Y, the marginal CDF, changes by the row total, and X at a
  // given u(θm) by the difference of the two rows' conditional CDFs (large between rows of
  // little mass, e.g. half vectors facing away from a grazing ωi; this term costs 8–40 % more
  // table and takes the preview of cc_ibiza_sunset from 0.61 to 0.57 % RMS). Each rate is the
  // largest over slices (and rows or columns), in RGB cells.
  const std::size_t vx = e.vx, vy = e.vy, slices = e.theta_i.size();
  std::vector<double> rate_x(vx - 1, 0.0), rate_y(vy - 1, 0.0);
  for (std::size_t sl = 0; sl < slices; ++sl)
    for (std::size_t y = 0; y < vy; ++y) {
      const double total = e.rows[2 * (sl * vy + y)];
      if (y + 1 < vy)
        rate_y[y] =
            std::max(rate_y[y], std::max(total, e.rows[2 * (sl * vy + y + 1)]) * (e.ry - 1));
      if (!(total > 0.0)) continue;
      for (std::size_t k = 0; k + 1 < vx; ++k) {
        const double* d = e.warp.data() + 2 * ((sl * vy + y) * vx + k);
        rate_x[k] = std::max(rate_x[k], std::max(d[0], d[2]) / total * (e.rx - 1));
      }
      const double next = y + 1 < vy ? e.rows[2 * (sl * vy + y + 1)] : 0.0;
      if (!(next > 0.0)) continue;
      for (std::size_t k = 0; k < vx; ++k) {
        const double* d = e.warp.data() + 2 * ((sl * vy + y) * vx + k);
        const double change = std::abs(d[2 * vx + 1] / next - d[1] / total);
        rate_y[y] = std::max(rate_y[y], change * (e.rx - 1));
      }
    }
  // Within the memory budget at the most incidence samples the refinement below can make:
  // fewer cells per RGB cell until it fits (files with finer RGB tables, e.g. cg_sunflower's
  // 64 × 64, would otherwise take 25 MB).
  const std::size_t most_slots =
      (slices - 1) * static_cast<std::size_t>(o.max_samples_per_interval) + 1;
  for (double cells = o.cells_per_rgb_cell;; cells *= 0.8) {
    t->ax = TableAxis::FromRates(rate_x, cells, o.max_cells_per_vndf_cell);
    t->ay = TableAxis::FromRates(rate_y, cells, o.max_cells_per_vndf_cell);
    const std::size_t bytes = 6 * most_slots * static_cast<std::size_t>(t->ax.vertices) *
                              static_cast<std::size_t>(t->ay.vertices);
    if (bytes <= o.max_table_bytes || (t->ax.vertices == e.vx && t->ay.vertices == e.vy)) break;
  }
  t->nx = t->ax.vertices;
  t->ny = t->ay.vertices;
  const std::size_t nx = t->nx, ny = t->ny, plane = nx * ny;
  const std::vector<double> ux = t->ax.Positions(), uy = t->ay.Positions();
  // Weights of the incidence test: f_r·cosθo at a vertex is g · ndf / 4σ and the vertex stands
  // for a solid angle of half vectors ∝ sinθm · u(θm) (θm = u² π/2), so an error in g there
  // counts with ndf² · sinθm · u in the RMS of f over directions.
  std::vector<double> weight(plane);
  for (std::size_t y = 0; y < ny; ++y)
    for (std::size_t x = 0; x < nx; ++x) {
      const double n = e.info.jacobian ? e.ndf.Eval(ux[x], uy[y]) : 1.0;
      weight[y * nx + x] = n * n * std::sin(ux[x] * ux[x] * 0.5 * kPi) * ux[x];
    }
  // g at weight w of interval j (RGB per vertex, double).
  auto sample = [&](int j, double w) {
    Corners c;
    const bool single = slices == 1;
    c.n = single ? 1 : 2;
    c.slice = {static_cast<std::size_t>(j), static_cast<std::size_t>(single ? j : j + 1), 0, 0};
    c.w = {1.0 - w, w, 0.0, 0.0};
    std::vector<double> g(3 * plane);
    for (std::size_t y = 0; y < ny; ++y)
      for (std::size_t x = 0; x < nx; ++x) {
        double sx, sy;
        e.InvertWarp(ux[x], uy[y], c, sx, sy);
        const Rgb v = e.InterpolateRgb(sx, sy, c);
        for (int ch = 0; ch < 3; ++ch) g[3 * (y * nx + x) + ch] = v[ch];
      }
    return g;
  };
  // Incidence samples per interval: doubled until linear interpolation between the samples
  // predicts every new midpoint within incidence_tolerance (weighted RMS relative to the
  // midpoint's own weighted RMS). Intervals are independent: built on `jobs` threads, each
  // holding its slots from w = 0 to w = 1 (the shared nodes are computed twice).
  const int intervals = static_cast<int>(slices) - 1;
  std::vector<std::vector<std::vector<double>>> runs(std::max(1, intervals));
  auto build_interval = [&](int j) {
    std::vector<std::vector<double>> run = {sample(j, 0.0)};
    if (intervals == 0) {
      runs[0] = std::move(run);
      return;
    }
    run.push_back(sample(j, 1.0));  // run[m] at w = m / k_samples
    int k_samples = 1;
    while (k_samples < o.max_samples_per_interval) {
      std::vector<std::vector<double>> refined;
      double err = 0.0, norm = 0.0;
      for (int m = 0; m < k_samples; ++m) {
        std::vector<double> mid = sample(j, (m + 0.5) / k_samples);
        for (std::size_t v = 0; v < plane; ++v)
          for (int ch = 0; ch < 3; ++ch) {
            const std::size_t i = 3 * v + static_cast<std::size_t>(ch);
            const double d = mid[i] - 0.5 * (run[m][i] + run[m + 1][i]);
            err += weight[v] * d * d;
            norm += weight[v] * mid[i] * mid[i];
          }
        refined.push_back(std::move(run[m]));
        refined.push_back(std::move(mid));
      }
      refined.push_back(std::move(run[k_samples]));
      run = std::move(refined);
      k_samples *= 2;
      if (!(err > o.incidence_tolerance * o.incidence_tolerance * norm)) break;
    }
    runs[j] = std::move(run);
  };
  ParallelChunks(runs.size(), 1, ResolveJobs(o.jobs), nullptr,
                 [&](std::size_t begin, std::size_t end) {
                   for (std::size_t j = begin; j < end; ++j) build_interval(static_cast<int>(j));
                 });
  // Slots in order, each interval's w = 1 end dropped in favour of the next one's w = 0 (the
  // same node; the last node kept).
  std::vector<const std::vector<double>*> slot_values;
  std::vector<double> slot_theta;
  for (int j = 0; j < static_cast<int>(runs.size()); ++j) {
    const int k_samples = std::max(1, static_cast<int>(runs[j].size()) - 1);
    const bool last = j + 1 == static_cast<int>(runs.size());
    for (std::size_t m = 0; m < runs[j].size(); ++m) {
      if (intervals > 0 && m + 1 == runs[j].size() && !last) break;
      slot_values.push_back(&runs[j][m]);
      slot_theta.push_back(intervals == 0 ? e.theta_i[0]
                                          : e.theta_i[j] + (e.theta_i[j + 1] - e.theta_i[j]) *
                                                               static_cast<double>(m) / k_samples);
    }
  }
  t->slots = static_cast<int>(slot_values.size());
  t->slot_theta = slot_theta;
  t->slot_inv_step.assign(slot_theta.size(), 0.0);
  double closest = kPi;
  for (std::size_t k = 0; k + 1 < slot_theta.size(); ++k) {
    t->slot_inv_step[k] = 1.0 / (slot_theta[k + 1] - slot_theta[k]);
    closest = std::min(closest, slot_theta[k + 1] - slot_theta[k]);
  }
  const double span = slot_theta.back() - slot_theta.front();
  const std::size_t bins =
      std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(span / closest)) + 1, 1, 1u << 14);
  t->bins_per_rad = span > 0.0 ? static_cast<double>(bins) / span : 0.0;
  t->bin_slot.resize(bins);
  for (std::size_t b = 0, k = 0; b < bins; ++b) {
    const double start = slot_theta.front() + static_cast<double>(b) / t->bins_per_rad;
    while (k + 1 < slot_theta.size() && slot_theta[k + 1] <= start) ++k;
    t->bin_slot[b] = static_cast<std::uint16_t>(
        std::min<std::size_t>(k, slot_theta.size() > 1 ? slot_theta.size() - 2 : 0));
  }
  // 16-bit fractions of each slot's per-channel maximum (values are ≥ 0: RglBrdf clips). With
  // the jacobian, the slot's 1 / (4σ(θi)) is folded into its scale: σ is smooth in θi (the
  // projected area of the microsurface), so interpolating g / 4σ between slots instead of g
  // and σ separately changes f by far less than the tabulation of g itself.
  t->texels.assign(3 * plane * slot_values.size() + 1, 0);  // + the last load's fourth lane
  t->scale.assign(4 * slot_values.size(), 0.0f);
  for (std::size_t sl = 0; sl < slot_values.size(); ++sl) {
    const std::vector<double>& g = *slot_values[sl];
    const double factor =
        e.info.jacobian
            ? 1.0 / (4.0 * e.sigma.Eval(std::sqrt(slot_theta[sl] * (2.0 / kPi)), PhiToU(0.0)))
            : 1.0;
    for (int ch = 0; ch < 3; ++ch) {
      double peak = 0.0;
      for (std::size_t v = 0; v < plane; ++v) peak = std::max(peak, g[3 * v + ch]);
      const double step = peak > 0.0 ? peak / 65535.0 : 1.0;
      t->scale[4 * sl + ch] = static_cast<float>(step * factor);
      for (std::size_t v = 0; v < plane; ++v)
        t->texels[3 * (sl * plane + v) + ch] =
            static_cast<std::uint16_t>(std::min(65535.0, std::rint(g[3 * v + ch] / step)));
    }
  }
  RglTabulatedBrdf::Table* raw = t.get();
  std::unique_ptr<RglTabulatedBrdf> out(new RglTabulatedBrdf(std::move(t), name_ + " (tabulated)"));
  raw->self_check_p99 = SelfCheckP99(*this, *out);
  return out;
}

std::unique_ptr<BrdfSource> RglBrdf::QuadratureApproximation() const {
  std::unique_ptr<RglTabulatedBrdf> table = Tabulate(RglTabulationSettings{});
  if (table == nullptr || table->self_check_p99_error() > kRglApproximationMaxP99Error)
    return nullptr;
  return table;
}

}  // namespace brdf
