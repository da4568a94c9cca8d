#include "brdf/processing/beyond.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/models.h"
#include "fill_model_eval.h"

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

namespace brdf::processing {
namespace {

constexpr double kGrazingDeg = 89.5;  // the model is read here at and below the horizon
constexpr double kBlendDeg = 5.0;     // half width of the reciprocity/continuation seam
constexpr double kMaxRatio = 8.0;
// The ratio M(new)/M(old) is read with the fitted lobe widened to at least this (α ≥ 0.1 for
// ggx and ward, n ≤ 200 for lafortune): the ratio is meant to carry the smooth change with
// θin (Fresnel, shadowing, the 1/cos factors), and a lobe a degree wide, as the fit gives for
// sharp measured highlights, turns a sub-degree misplacement into a factor of 8.
constexpr double kMinRatioAlpha = 0.1, kMaxRatioExponent = 200.0;

FillModel Widened(FillModel m) {
  for (int c = 6; c < 9; ++c)
    m.material.values[c] = m.material.model == Model::kLafortune
                               ? std::min(m.material.values[c], kMaxRatioExponent)
                               : std::max(m.material.values[c], kMinRatioAlpha);
  return m;
}

std::uint64_t Bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// A new slice's blend weight at θout' = min(θout, 90°): 0 below θL − 5° (reciprocity alone), 1
// above θL + 5° (the continuation of the slice below alone), linear in between.
double BlendWeight(double to, double last) {
  return std::clamp((to - (last - kBlendDeg)) / (2 * kBlendDeg), 0.0, 1.0);
}

// Runs body(j) for every texel row j, on TBB's workers (within any enclosing arena's limit).
template <class Body>
void ForRows(const Body& body) {
  tbb::parallel_for(0, Lut::kHeight, [&](int j) { body(j); });
}

struct View {
  double theta_deg, phi_deg;
};

// The view (θout, φout) of texel (j, i) of the slice at θin (θout up to 180°).
View TexelView(double theta_in_deg, int j, int i) {
  const Vec3 w = SpecularFrame::FromThetaInDeg(theta_in_deg)
                     .FromSpecular(SphericalDirectionDeg(j * Lut::kTexelDeg, i * Lut::kTexelDeg));
  return {RadToDeg(ThetaOf(w)), RadToDeg(PhiOf(w))};
}

// A fill family at one geometry and shape: f = a·(1/π) + b·y + offset per channel, with a the
// diffuse reflectance and b the family's second linear parameter (f0, ρs, ks), each from the
// model's one definition (brdf/core/models.h).
struct Parts {
  double y = 0, offset = 0;
};

// The terms of models::Ggx, Ward and Lafortune at one geometry that do not depend on the shape
// (the cosines' squares and tangents, the Fresnel weight, the denominators), each computed with
// the operations the model does, so PartsOf below gives the doubles of the models themselves.
// A fit tries 30 shapes at the same points; these are computed once per point.
struct ShapeFreeTerms {
  double tan2_l = 0, tan2_v = 0, cos2_h = 0, fresnel_weight = 0, ggx_denom = 0;  // ggx
  double tan2_h = 0, sqrt_lv = 0;                                                // ward
  double v_dot_r = 0;                                                            // lafortune
};
double TanSquared(double cos_theta) {  // models::GgxG1's and Ward's tan²
  const double cos2 = cos_theta * cos_theta;
  return (1.0 - cos2) / cos2;
}
ShapeFreeTerms ShapeFreeTermsOf(Model family, const ShadingGeometry& g) {
  ShapeFreeTerms t;
  switch (family) {
    case Model::kWard:
      t.tan2_h = TanSquared(g.n_dot_h);
      t.sqrt_lv = std::sqrt(g.n_dot_l * g.n_dot_v);
      break;
    case Model::kLafortune:
      t.v_dot_r = g.v_dot_r;
      break;
    default:
      t.tan2_l = TanSquared(g.n_dot_l);
      t.tan2_v = TanSquared(g.n_dot_v);
      t.cos2_h = g.n_dot_h * g.n_dot_h;
      t.fresnel_weight = models::Pow5(1.0 - g.v_dot_h);
      t.ggx_denom = 4.0 * g.n_dot_l * g.n_dot_v;
      break;
  }
  return t;
}

// {models::Ward(g, 0, 1, shape), 0}, {models::Lafortune(g, 0, 1, shape), 0} and for ggx
// {Ggx(g, 0, 1, shape) − Ggx(g, 0, 0, shape), Ggx(g, 0, 0, shape)}, the two GGX evaluations
// sharing their shadowing and distribution; every operation as in brdf/core/models.h. g1_l is
// GGX's light-side masking models::GgxG1(n·l, shape²) (one per slice: the caller keeps it).
Parts PartsOf(Model family, const ShapeFreeTerms& t, double shape, double g1_l) {
  switch (family) {
    case Model::kWard: {
      const double a2 = shape * shape;
      return {0.0 * kInvPi + 1.0 * std::exp(-t.tan2_h / a2) / (4 * kPi * a2 * t.sqrt_lv), 0.0};
    }
    case Model::kLafortune: {
      const double lobe = t.v_dot_r > 0 ? std::pow(t.v_dot_r, shape) : 0.0;
      return {0.0 * kInvPi + 1.0 * (shape + 2.0) * (0.5 * kInvPi) * lobe, 0.0};
    }
    default: {
      const double a2 = shape * shape;
      const double shadowing = g1_l * (2.0 / (1.0 + std::sqrt(1.0 + a2 * t.tan2_v)));
      const double dd = t.cos2_h * (a2 - 1.0) + 1.0;
      const double d = a2 / (kPi * dd * dd);
      const double fresnel_0 = 0.0 + (1.0 - 0.0) * t.fresnel_weight;
      const double fresnel_1 = 1.0 + (1.0 - 1.0) * t.fresnel_weight;
      const double off = 0.0 * kInvPi + fresnel_0 * shadowing * d / t.ggx_denom;
      const double one = 0.0 * kInvPi + fresnel_1 * shadowing * d / t.ggx_denom;
      return {one - off, off};
    }
  }
}

ShadingGeometry GeometryAt(double theta_in_deg, double theta_out_deg, double phi_out_deg) {
  const Vec3 l = SphericalDirectionDeg(std::min(theta_in_deg, kGrazingDeg), 0.0);
  const Vec3 v = SphericalDirectionDeg(std::min(theta_out_deg, kGrazingDeg), phi_out_deg);
  return ShadingGeometry::Of(l, v);
}

struct FitPoint {
  ShadingGeometry g;
  std::array<double, 3> f;
};

// The three channels of a fit point as two pairs of doubles operated on lane by lane (GCC/Clang
// vector extension, one SSE2 register each on x86-64): channels 0 and 1, then channel 2 and an
// unused 0. Each lane does exactly the scalar operations, so a channel's sums are the doubles
// the scalar loop gave. (A four-lane type is split by the compiler through the stack, which
// made the accumulation wait on memory.)
using Pair = double __attribute__((vector_size(16)));
struct Lanes {
  Pair lo{}, hi{};
  double operator[](int c) const { return c < 2 ? lo[c] : hi[c - 2]; }
  double& operator[](int c) { return c < 2 ? lo[c] : hi[c - 2]; }
};
inline Lanes operator*(const Lanes& a, double x) { return {a.lo * x, a.hi * x}; }
inline Lanes operator*(const Lanes& a, const Lanes& b) { return {a.lo * b.lo, a.hi * b.hi}; }
inline Lanes operator-(const Lanes& a, double x) { return {a.lo - x, a.hi - x}; }
inline Lanes& operator+=(Lanes& a, const Lanes& b) {
  a.lo += b.lo, a.hi += b.hi;
  return a;
}

// What FitAtShape needs of the points besides the model's parts: each point's value f and
// relative weight w = 1/(f + ε)² per channel and w·(1/π), and the sums that do not involve the
// parts (Σ w/π² always, and Σ w·f/π and Σ w·f² for the families without an offset), each summed
// in the points' order as FitAtShape summed it.
struct FitData {
  std::vector<Lanes> f, w, wx;
  Lanes saa{}, sa{}, s{};
  bool offset_free = false;
};
FitData FitDataOf(const std::vector<FitPoint>& pts, const std::array<double, 3>& eps,
                  Model family) {
  FitData d;
  d.offset_free = family == Model::kWard || family == Model::kLafortune;
  d.f.resize(pts.size());
  d.w.resize(pts.size());
  d.wx.resize(pts.size());
  const double x = kInvPi;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const FitPoint& p = pts[k];
    Lanes f{}, w{};
    for (int c = 0; c < 3; ++c) {
      f[c] = p.f[c];
      w[c] = 1.0 / ((p.f[c] + eps[c]) * (p.f[c] + eps[c]));
    }
    const Lanes wx = w * x;
    d.f[k] = f, d.w[k] = w, d.wx[k] = wx;
    d.saa += wx * x;
    if (d.offset_free) {
      const Lanes y = f - 0.0;
      d.sa += wx * y, d.s += w * y * y;
    }
  }
  return d;
}

// Weighted least squares of kd, f0 ∈ [0, 1] for one channel: Σ w (kd/π + f0·a + b − f)².
struct Normal {
  double saa = 0, sab = 0, sbb = 0, sa = 0, sb = 0, s = 0;  // Σw·(x_k x_l), Σw·x_k·y, Σw·y²
};
double SolveBounded(const Normal& n, double* kd, double* f0) {
  // Unknowns x = (kd/π coefficient 1/π, f0 coefficient a); cost = xᵀAx − 2xᵀr + s.
  const auto cost = [&](double x, double y) {
    return n.saa * x * x + 2 * n.sab * x * y + n.sbb * y * y - 2 * (n.sa * x + n.sb * y) + n.s;
  };
  double best = HUGE_VAL;
  const auto consider = [&](double x, double y) {
    x = std::clamp(x, 0.0, 1.0);
    y = std::clamp(y, 0.0, 1.0);
    const double c = cost(x, y);
    if (c < best) best = c, *kd = x, *f0 = y;
  };
  const double det = n.saa * n.sbb - n.sab * n.sab;
  if (det > 1e-300)
    consider((n.sa * n.sbb - n.sb * n.sab) / det, (n.sb * n.saa - n.sa * n.sab) / det);
  for (double x : {0.0, 1.0}) consider(x, n.sbb > 0 ? (n.sb - n.sab * x) / n.sbb : 0.0);
  for (double y : {0.0, 1.0}) consider(n.saa > 0 ? (n.sa - n.sab * y) / n.saa : 0.0, y);
  return best;
}

struct Candidate {
  std::array<double, 3> a{}, b{};
  double shape = 0;
};

// PartsOf(family, point, shape) of every point: what a fit at one shape needs from the model,
// independent of the values fitted.
std::vector<Parts> PartsAtShape(Model family, const std::vector<ShapeFreeTerms>& terms,
                                double shape) {
  std::vector<Parts> parts(terms.size());
  // models::GgxG1(n·l) = 2/(1 + √(1 + α² tan²θl)) again only when tan²θl changes (its bits).
  const double a2 = shape * shape;
  std::uint64_t l_bits = 0;
  double g1_l = 0;
  for (std::size_t k = 0; k < terms.size(); ++k) {
    if (family == Model::kGgx) {
      const std::uint64_t bits = Bits(terms[k].tan2_l);
      if (k == 0 || bits != l_bits)
        g1_l = 2.0 / (1.0 + std::sqrt(1.0 + a2 * terms[k].tan2_l)), l_bits = bits;
    }
    parts[k] = PartsOf(family, terms[k], shape, g1_l);
  }
  return parts;
}

// The weighted normal equations Σ w (a/π + b·y + offset − f)² per channel at one shape, and
// their bounded solution.
double FitAtShape(const FitData& d, const std::vector<Parts>& parts, double shape, Candidate* out) {
  const std::size_t count = d.f.size();
  Lanes sab{}, sbb{}, sb{}, sa = d.sa, s = d.s;
  if (d.offset_free) {
    for (std::size_t k = 0; k < count; ++k) {
      const double qy = parts[k].y;
      const Lanes wq = d.w[k] * qy;
      const Lanes y = d.f[k] - 0.0;
      sab += d.wx[k] * qy, sbb += wq * qy, sb += wq * y;
    }
  } else {
    for (std::size_t k = 0; k < count; ++k) {
      const Parts& q = parts[k];
      const Lanes wq = d.w[k] * q.y;
      const Lanes y = d.f[k] - q.offset;
      sab += d.wx[k] * q.y, sbb += wq * q.y;
      sa += d.wx[k] * y, sb += wq * y, s += d.w[k] * y * y;
    }
  }
  std::array<Normal, 3> n{};
  for (int c = 0; c < 3; ++c) n[c] = {d.saa[c], sab[c], sbb[c], sa[c], sb[c], s[c]};
  double total = 0;
  for (int c = 0; c < 3; ++c) total += SolveBounded(n[c], &out->a[c], &out->b[c]);
  out->shape = shape;
  return total;
}

// A fill "model" of kHold is M ≡ 1; of kModel the fitted GGX.
std::array<double, 3> RatioOf(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  std::array<double, 3> r{};
  for (int c = 0; c < 3; ++c)
    r[c] = b[c] > 1e-30 ? std::clamp(a[c] / b[c], 1.0 / kMaxRatio, kMaxRatio) : 1.0;
  return r;
}

// The per-texel tables of a slice that depend on its θin alone, not on the measurement: every
// texel's view (TexelView) and shading geometry (GeometryAt at that view), and for the θout band
// GeometryAt(θin, θb, φout of the view). A batch of captures on one instrument's θin grid asks
// for the same few dozen tables once per capture and fill, and their trigonometry was about a
// third of a fill's instructions (docs/benchmarks/batch.md), so they are computed once per
// process and shared, read-only, by every fill on every thread. The tables are keyed by the
// exact bits of their inputs (and the view table they were computed from), so a table holds
// exactly the numbers the fill computed for itself before they were shared.
using Views = std::vector<View>;                  // index j·361 + i
using Geometries = std::vector<ShadingGeometry>;  // index j·361 + i
using ViewsPtr = std::shared_ptr<const Views>;
using GeometriesPtr = std::shared_ptr<const Geometries>;

// A process-wide map of read-only tables, thread-safe. Tables are computed outside the lock
// (they run on TBB's workers): when two threads compute the same table both get the same
// numbers, and the first one inserted is kept. Past `max_entries` the map starts over (tables
// in use stay alive through their shared pointers).
template <class Key, class Table>
class SharedMap {
 public:
  explicit SharedMap(std::size_t max_entries) : max_entries_(max_entries) {}
  template <class Make>
  std::shared_ptr<const Table> Get(const Key& key, const Make& make) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (const auto it = map_.find(key); it != map_.end()) return it->second;
    }
    std::shared_ptr<const Table> made = make();
    const std::lock_guard<std::mutex> lock(mutex_);
    if (const auto it = map_.find(key); it != map_.end()) return it->second;
    if (map_.size() >= max_entries_) map_.clear();
    return map_.emplace(key, std::move(made)).first->second;
  }

 private:
  std::size_t max_entries_;
  std::mutex mutex_;
  std::map<Key, std::shared_ptr<const Table>> map_;
};

class SharedTables {
 public:
  // TexelView(θin, j, i) of every texel.
  static ViewsPtr ViewsAt(double theta_in_deg) {
    static SharedMap<std::uint64_t, Views> views(kMaxSlices);
    return views.Get(Bits(theta_in_deg), [&] {
      auto v = std::make_shared<Views>(static_cast<std::size_t>(Lut::kHeight) * Lut::kWidth);
      ForRows([&](int j) {
        for (int i = 0; i < Lut::kWidth; ++i)
          (*v)[static_cast<std::size_t>(j) * Lut::kWidth + i] = TexelView(theta_in_deg, j, i);
      });
      return v;
    });
  }
  // GeometryAt(θin, view) of every texel of `views`.
  static GeometriesPtr GeometryAtViews(double theta_in_deg, const ViewsPtr& views) {
    static SharedMap<GeometryKey, Derived<ShadingGeometry>> geometry(kMaxSlices);
    return PerTexel(geometry, {Bits(theta_in_deg), 0, views.get()}, views, true,
                    [&](const View& v, ShadingGeometry& g) {
                      g = GeometryAt(theta_in_deg, v.theta_deg, v.phi_deg);
                    });
  }
  // GeometryAt(θin, θb, φout) at every texel of `views` whose θout is beyond θb (the others
  // are left default).
  static GeometriesPtr BandAtViews(double theta_in_deg, double theta_b_deg, const ViewsPtr& views) {
    static SharedMap<GeometryKey, Derived<ShadingGeometry>> band(kMaxSlices);
    return PerTexel(band, {Bits(theta_in_deg), Bits(theta_b_deg), views.get()}, views, true,
                    [&](const View& v, ShadingGeometry& g) {
                      if (v.theta_deg > theta_b_deg)
                        g = GeometryAt(theta_in_deg, theta_b_deg, v.phi_deg);
                    });
  }

  // Where Fill's reciprocity reads the banded LUT (the measured slices with their band and the
  // inserted ones, θin list `banded`) for the new slice at θin `t` whose views are `views`:
  // Lut::TextureCoordinates(min(θout, θL), min(t, 90°), −φout) at every texel whose blend weight
  // is below 1 (the others are left 0). They depend on the θin lists and the views alone; the
  // trigonometry was most of a reciprocity read.
  using Coordinates = std::array<double, 3>;
  static std::shared_ptr<const std::vector<Coordinates>> ReciprocityAt(const Lut& banded, double t,
                                                                       double last,
                                                                       const ViewsPtr& views) {
    using Key = std::tuple<std::vector<std::uint64_t>, std::uint64_t, std::uint64_t, const Views*>;
    static SharedMap<Key, Derived<Coordinates>> coordinates(kMaxSlices);
    std::vector<std::uint64_t> list(banded.theta_in_deg.size());
    std::transform(banded.theta_in_deg.begin(), banded.theta_in_deg.end(), list.begin(), Bits);
    return PerTexel(coordinates, Key{std::move(list), Bits(t), Bits(last), views.get()}, views,
                    true, [&](const View& v, Coordinates& c) {
                      const double to = std::min(v.theta_deg, 90.0);
                      if (BlendWeight(to, last) < 1.0)
                        c = banded.TextureCoordinates(std::min(to, last), std::min(t, 90.0),
                                                      -v.phi_deg);
                    });
  }

  // cos θout of every texel of `views` (the albedo's weights, std::cos as Albedo computed it).
  static std::shared_ptr<const std::vector<double>> CosinesAt(const ViewsPtr& views) {
    static SharedMap<const Views*, Derived<double>> cosines(kMaxSlices);
    return PerTexel(cosines, views.get(), views, false,
                    [](const View& v, double& c) { c = std::cos(DegToRad(v.theta_deg)); });
  }

 private:
  // 1 MB of views and 3 MB of geometry per θin: a capture's fill uses 9 θin, an RGL file's
  // a few dozen.
  static constexpr std::size_t kMaxSlices = 64;
  using GeometryKey = std::tuple<std::uint64_t, std::uint64_t, const Views*>;
  // A table computed from a view table, one entry per texel. It keeps the view table alive, so
  // the address in its key cannot be taken by another view table while the entry exists.
  template <class T>
  struct Derived {
    Derived(ViewsPtr v, std::size_t n) : views(std::move(v)), table(n) {}
    ViewsPtr views;
    std::vector<T> table;
  };
  // The shared table of `key`, made by fill(view, entry) for every texel of `views` (by rows on
  // TBB's workers when `parallel`).
  template <class Key, class T, class Fill>
  static std::shared_ptr<const std::vector<T>> PerTexel(SharedMap<Key, Derived<T>>& map,
                                                        const Key& key, const ViewsPtr& views,
                                                        bool parallel, const Fill& fill) {
    const std::shared_ptr<const Derived<T>> d = map.Get(key, [&] {
      auto made = std::make_shared<Derived<T>>(views, views->size());
      const auto row = [&](int j) {
        for (int i = 0; i < Lut::kWidth; ++i) {
          const std::size_t n = static_cast<std::size_t>(j) * Lut::kWidth + i;
          fill((*views)[n], made->table[n]);
        }
      };
      if (parallel)
        ForRows(row);
      else
        for (int j = 0; j < Lut::kHeight; ++j) row(j);
      return made;
    });
    return {d, &d->table};
  }
};

// The fit points of FitFillModel are chosen by their views alone (θout ≤ θb), so a LUT's θin
// list and θb name them; the model's parts at a shape are then the same for every capture of
// the batch. The shape grid is fixed, so its parts are shared like the tables above (about
// 200 KB per shape for a capture; 18 shapes per family and point set).
using PointsKey = std::tuple<int, std::vector<std::uint64_t>, std::uint64_t, std::uint64_t>;
std::shared_ptr<const std::vector<Parts>> SharedPartsAtShape(
    Model family, const std::vector<double>& theta_in, double theta_b,
    const std::vector<ShapeFreeTerms>& terms, double shape) {
  static SharedMap<PointsKey, std::vector<Parts>> parts(128);
  std::vector<std::uint64_t> slices(theta_in.size());
  std::transform(theta_in.begin(), theta_in.end(), slices.begin(), Bits);
  return parts.Get({static_cast<int>(family), std::move(slices), Bits(theta_b), Bits(shape)}, [&] {
    return std::make_shared<const std::vector<Parts>>(PartsAtShape(family, terms, shape));
  });
}

// The tables of the slices one ExtendBeyondMeasured call has asked for, by θin rounded to
// 10⁻⁶ degree (the first θin asked for within rounding gives the views; the geometry is of the
// θin that first needs it): shared by all its fills (the validations and the final one).
struct SliceGeometry {
  ViewsPtr view;
  GeometriesPtr g;  // GeometryAt(θin, view); looked up when a model needs it
};
using GeometryCache = std::map<long, SliceGeometry>;

// The texels of a validation fill's slices that its one read slice needs (ValidationNeeds), by
// slice key (θin·10⁶ rounded); a slice without an entry is computed whole.
using Mask = std::vector<std::uint8_t>;  // index j·361 + i, 1 = needed
struct Needs {
  std::map<long, Mask> texels;  // band and inserted slices: the texels to fill
  std::map<long, Mask> model;   // the model grid: the texels to evaluate it at
};
long SliceKey(double theta_in_deg) { return std::lround(theta_in_deg * 1e6); }
const Mask* MaskAt(const std::map<long, Mask>* masks, double theta_in_deg) {
  if (masks == nullptr) return nullptr;
  const auto it = masks->find(SliceKey(theta_in_deg));
  return it == masks->end() ? nullptr : &it->second;
}

// Every texel's view in the slice at one θin (the shared SliceGeometry's), and the model there
// (computed once per θin and model; at the needed texels alone when the fill has Needs).
struct SliceGrid {
  ViewsPtr views;
  std::vector<std::array<double, 3>> m;  // empty for M ≡ 1
  const Views& view() const { return *views; }
};

// M(new)/M(old) at texels; kHold's model is null (M ≡ 1).
struct Ratio {
  const FillModel* model = nullptr;
  // The grid of the slice at `theta_in_deg`, computed on first use. Not thread-safe: call it
  // outside the parallel loops, which then only read the grids.
  const SliceGrid& Prepare(double theta_in_deg) const {
    const long key = SliceKey(theta_in_deg);
    if (auto it = grids->find(key); it != grids->end()) return it->second;
    SliceGeometry& s = GeometryOf(theta_in_deg, key);
    SliceGrid g{s.view, {}};
    if (model) {
      if (!s.g) s.g = SharedTables::GeometryAtViews(theta_in_deg, s.view);
      const Geometries& at = *s.g;
      const Mask* only = MaskAt(needs ? &needs->model : nullptr, theta_in_deg);
      g.m.resize(at.size());
      ForRows([&](int j) {
        const std::size_t row = static_cast<std::size_t>(j) * Lut::kWidth;
        // FillModel::Eval at the cached geometry (the same numbers); texels never read are
        // left 0.
        detail::EvaluateFillModelAt(model->material, &at[row], Lut::kWidth, &g.m[row],
                                    [&](int i) { return only && !(*only)[row + i]; });
      });
    }
    return grids->emplace(key, std::move(g)).first->second;
  }
  SliceGeometry& GeometryOf(double theta_in_deg, long key) const {
    if (auto it = geometry->find(key); it != geometry->end()) return it->second;
    return geometry->emplace(key, SliceGeometry{SharedTables::ViewsAt(theta_in_deg), nullptr})
        .first->second;
  }
  std::array<double, 3> Between(const SliceGrid& now, const SliceGrid& old, std::size_t n) const {
    if (model == nullptr) return {1.0, 1.0, 1.0};
    return RatioOf(now.m[n], old.m[n]);
  }
  std::shared_ptr<GeometryCache> geometry = std::make_shared<GeometryCache>();
  // A validation fill's needed texels (null: every texel of every slice).
  std::shared_ptr<const Needs> needs;
  std::shared_ptr<std::map<long, SliceGrid>> grids = std::make_shared<std::map<long, SliceGrid>>();
};

// Slices every `step` degrees from 0 to the last measured one (which are kept as they are).
// A slice θ between measured slices θa < θb, weight t = (θ − θa)/(θb − θa), texel (θd, φd):
//   (1 − t)·f(θa)·M(θ)/M(θa) + t·f(θb)·M(θ)/M(θb)
// with M at each slice's own view of that texel: linear in θin at equal (θd, φd) for M ≡ 1,
// and following the model's change with θin otherwise.
// The result has room for `capacity_slices` slices (Fill appends its new slices).
Lut Densify(Lut measured, double step, const Ratio& ratio, std::size_t capacity_slices) {
  const double delta = measured.DeltaInDeg();
  const int per = static_cast<int>(std::lround(delta / step));
  if (per <= 1) return measured;
  Lut out;
  out.texels.reserve(capacity_slices * Lut::kHeight * Lut::kWidth * 3);
  out.Resize(static_cast<std::size_t>((measured.slices() - 1) * per + 1));
  for (int k = 0; k < out.slices(); ++k) {
    const double theta = k * step;
    out.theta_in_deg[k] = theta;
    const int a = k / per;
    if (k % per == 0) {
      std::copy_n(measured.Texel(a, 0, 0), static_cast<std::size_t>(Lut::kHeight) * Lut::kWidth * 3,
                  out.Texel(k, 0, 0));
      continue;
    }
    const int b = a + 1;
    const double t = static_cast<double>(k % per) / per;
    const double ta = measured.theta_in_deg[a], tb = measured.theta_in_deg[b];
    const SliceGrid& g = ratio.Prepare(theta);
    const SliceGrid& ga = ratio.Prepare(ta);
    const SliceGrid& gb = ratio.Prepare(tb);
    const Mask* only = MaskAt(ratio.needs ? &ratio.needs->texels : nullptr, theta);
    ForRows([&](int j) {
      for (int i = 0; i < Lut::kWidth; ++i) {
        const std::size_t n = static_cast<std::size_t>(j) * Lut::kWidth + i;
        if (only && !(*only)[n]) continue;  // never read (left 0)
        const auto ra = ratio.Between(g, ga, n);
        const auto rb = ratio.Between(g, gb, n);
        const float* fa = measured.Texel(a, j, i);
        const float* fb = measured.Texel(b, j, i);
        float* dst = out.Texel(k, j, i);
        for (int c = 0; c < 3; ++c)
          dst[c] = static_cast<float>((1.0 - t) * fa[c] * ra[c] + t * fb[c] * rb[c]);
      }
    });
  }
  return out;
}

// Directional albedo per channel of slice k (its upper-hemisphere texels, column 360 left out),
// and the part of it from texels for which `filled` is true.
template <class Filled>
void Albedo(const Lut& lut, int k, const SliceGrid& g, Filled filled, std::array<double, 3>* total,
            std::array<double, 3>* fill) {
  *total = {0, 0, 0};
  *fill = {0, 0, 0};
  const std::shared_ptr<const std::vector<double>> cosines = SharedTables::CosinesAt(g.views);
  for (int j = 0; j < Lut::kHeight; ++j) {
    // The texel's cell: θd ∈ [j − ½, j + ½]° (clipped at the poles), φd ∈ [i − ½, i + ½]°.
    const double dw = (std::cos(DegToRad(std::max(j - 0.5, 0.0))) -
                       std::cos(DegToRad(std::min(j + 0.5, 180.0)))) *
                      DegToRad(Lut::kTexelDeg);
    for (int i = 0; i < Lut::kWidth - 1; ++i) {
      const std::size_t n = static_cast<std::size_t>(j) * Lut::kWidth + i;
      const View v = g.view()[n];
      if (v.theta_deg >= 90.0) continue;
      const double w = dw * (*cosines)[n];
      const float* f = lut.Texel(k, j, i);
      const bool is_fill = filled(j, i, v);
      for (int c = 0; c < 3; ++c) {
        (*total)[c] += w * f[c];
        if (is_fill) (*fill)[c] += w * f[c];
      }
    }
  }
}

// Scales the filled texels of slice k so that its albedo is at most 1 per channel.
template <class Filled>
void LimitAlbedo(Lut* lut, int k, const SliceGrid& g, Filled filled, BeyondReport* report) {
  std::array<double, 3> total, fill;
  Albedo(*lut, k, g, filled, &total, &fill);
  for (int c = 0; c < 3; ++c) {
    double albedo = total[c];
    if (total[c] > 1.0 && fill[c] > 0) {
      const double s = std::max(0.0, (1.0 - (total[c] - fill[c])) / fill[c]);
      for (int j = 0; j < Lut::kHeight; ++j)
        for (int i = 0; i < Lut::kWidth; ++i)
          if (filled(j, i, g.view()[static_cast<std::size_t>(j) * Lut::kWidth + i]))
            lut->Texel(k, j, i)[c] *= s;
      albedo = total[c] - fill[c] + fill[c] * s;
      ++report->albedo_scaled_channels;
    }
    report->max_albedo = std::max(report->max_albedo, albedo);
  }
}

// The fill of `measured` by `ratio` (no validation, no method choice).
Lut Fill(const Lut& measured_in, double theta_b, double max_theta_in, double step,
         const Ratio& ratio, BeyondReport* report) {
  const int k_meas = measured_in.slices();
  const double last = measured_in.theta_in_deg.back();
  // Room for every slice of the result (a bound: the step of steps 2 and 3 below), so that
  // appending the new slices copies nothing else.
  const double step_out = step > 0 && std::lround(measured_in.DeltaInDeg() / step) > 1
                              ? step
                              : measured_in.DeltaInDeg();
  const std::size_t capacity = static_cast<std::size_t>(std::max(
      k_meas * std::max(1L, step > 0 ? std::lround(measured_in.DeltaInDeg() / step) : 1L),
      step_out > 0 ? static_cast<long>(std::floor(max_theta_in / step_out + 1e-9)) + 1 : 0L));
  Lut out;
  out.theta_in_deg = measured_in.theta_in_deg;
  out.texels.reserve(capacity * Lut::kHeight * Lut::kWidth * 3);
  out.texels = measured_in.texels;
  // 1. The θout band of the measured slices.
  for (int k = 0; k < k_meas; ++k) {
    const double t = measured_in.theta_in_deg[k];
    if (ratio.model == nullptr) break;  // M ≡ 1: the band stays as it is
    const SliceGrid& g = ratio.Prepare(t);
    const GeometriesPtr band = SharedTables::BandAtViews(t, theta_b, g.views);
    const Material& model = ratio.model->material;
    const Mask* only = MaskAt(ratio.needs ? &ratio.needs->texels : nullptr, t);
    ForRows([&](int j) {
      const std::size_t row = static_cast<std::size_t>(j) * Lut::kWidth;
      const auto skip = [&](int i) {
        const View& v = g.view()[row + i];
        // Not in the band, or neither read nor in the slice's albedo (θout < 90°), which
        // scales the band below.
        return v.theta_deg <= theta_b || (only && !(*only)[row + i] && v.theta_deg >= 90.0);
      };
      // FillModel::Eval(t, θb, φout) at the shared geometry (the same numbers).
      std::array<std::array<double, 3>, Lut::kWidth> at_band;
      detail::EvaluateFillModelAt(model, &(*band)[row], Lut::kWidth, at_band.data(), skip);
      for (int i = 0; i < Lut::kWidth; ++i) {
        if (skip(i)) continue;
        const std::size_t n = row + static_cast<std::size_t>(i);
        const auto r = RatioOf(g.m[n], at_band[static_cast<std::size_t>(i)]);
        float* f = out.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) f[c] = static_cast<float>(f[c] * r[c]);
      }
    });
    LimitAlbedo(
        &out, k, g, [&](int, int, const View& v) { return v.theta_deg > theta_b; }, report);
  }
  // 2. Slices between the measured ones, when the step is finer.
  if (step > 0) {
    out = Densify(std::move(out), step, ratio, capacity);
    for (double t : out.theta_in_deg)
      if (std::none_of(measured_in.theta_in_deg.begin(), measured_in.theta_in_deg.end(),
                       [&](double m) { return std::fabs(m - t) < 1e-6; }))
        report->inserted_theta_in_deg.push_back(t);
  }
  const int k_meas_step = out.slices();
  const double delta = out.DeltaInDeg();
  // 3. New slices beyond the last measured one, made in `added` (slice q is slice
  // k_meas_step + q of the result) while `out` is the banded LUT (the measured slices with their
  // band, and the inserted ones) that reciprocity reads; appended to it at the end.
  const Lut& banded = out;
  const int k_total = static_cast<int>(std::floor(max_theta_in / delta + 1e-9)) + 1;
  Lut added;
  added.Resize(static_cast<std::size_t>(std::max(0, k_total - k_meas_step)));
  for (int k = k_meas_step; k < k_total; ++k) {
    const double t = k * delta;
    const int q = k - k_meas_step;
    added.theta_in_deg[static_cast<std::size_t>(q)] = t;
    const SliceGrid& g = ratio.Prepare(t);
    const SliceGrid& g_below = ratio.Prepare(t - delta);
    const Mask* only = MaskAt(ratio.needs ? &ratio.needs->texels : nullptr, t);
    const auto reciprocity = SharedTables::ReciprocityAt(banded, t, last, g.views);
    ForRows([&](int j) {
      for (int i = 0; i < Lut::kWidth; ++i) {
        const std::size_t n = static_cast<std::size_t>(j) * Lut::kWidth + i;
        if (only && !(*only)[n]) continue;  // never read (left 0)
        const View v = g.view()[n];
        const double to = std::min(v.theta_deg, 90.0);
        const double w = BlendWeight(to, last);
        std::array<double, 3> value{};
        if (w < 1.0) {
          // banded.SampleTexture(min(θout, θL), min(t, 90°), −φout) at the shared coordinates.
          const auto& at = (*reciprocity)[n];
          const auto f = banded.SampleTrilinear(at[0], at[1], at[2]);
          for (int c = 0; c < 3; ++c) value[c] = (1.0 - w) * f[c];
        }
        if (w > 0.0) {
          const auto r = ratio.Between(g, g_below, n);
          const float* f = q == 0 ? out.Texel(k - 1, j, i) : added.Texel(q - 1, j, i);
          for (int c = 0; c < 3; ++c) value[c] += w * f[c] * r[c];
        }
        float* dst = added.Texel(q, j, i);
        for (int c = 0; c < 3; ++c) dst[c] = static_cast<float>(value[c]);
      }
    });
    // Column 360 repeats column 0 (docs/design.md §5).
    for (int j = 0; j < Lut::kHeight; ++j)
      std::copy_n(added.Texel(q, j, 0), 3, added.Texel(q, j, Lut::kWidth - 1));
    LimitAlbedo(
        &added, q, g, [](int, int, const View&) { return true; }, report);
    report->extrapolated_theta_in_deg.push_back(t);
  }
  out.theta_in_deg.insert(out.theta_in_deg.end(), added.theta_in_deg.begin(),
                          added.theta_in_deg.end());
  out.texels.insert(out.texels.end(), added.texels.begin(), added.texels.end());
  return out;
}

// The tap indices [lo, hi] along one axis that SampleTrilinear can read at coordinate x (the
// texel coordinate before its floor), widened by 10⁻⁶ of a texel against rounding.
std::pair<int, int> TapRange(double x, int n) {
  const int lo = static_cast<int>(std::floor(x - 1e-6));
  const int hi = static_cast<int>(std::floor(x + 1e-6)) + 1;
  return {std::clamp(lo, 0, n - 1), std::clamp(hi, 0, n - 1)};
}

// What a validation fill (Fill of the slices `head` up to `max_theta_in`, of which Validate reads
// the last slice alone) needs of its slices, from the last one back. A new slice needs its
// albedo's texels (θout < 90°: its albedo limit scales the slice by their sum; the last one's
// include those Validate reads) and those the next new slice continues (blend weight w > 0),
// and its model where it continues the slice below and where the next one continues it. The
// banded LUT (the measured slices with their band and the inserted ones) is read by the new
// slices' reciprocity (Lut::SampleTexture where w < 1) at that sample's trilinear taps, and its
// last slice also where the first new slice continues it; an inserted slice is computed from
// its two measured neighbours at the same texel, so they need its texels too; and a measured
// slice's band is also computed above the horizon, which its albedo limit sums. The needs
// depend on the θin lists, θb and the steps alone, so they are computed once per process and
// shared like the tables above.
using NeedsKey =
    std::tuple<std::vector<std::uint64_t>, std::uint64_t, std::uint64_t, std::uint64_t>;
std::shared_ptr<const Needs> ValidationNeeds(const std::vector<double>& head, double theta_b,
                                             double max_theta_in, double step) {
  static SharedMap<NeedsKey, Needs> shared(16);
  std::vector<std::uint64_t> bits(head.size());
  std::transform(head.begin(), head.end(), bits.begin(), Bits);
  return shared.Get({std::move(bits), Bits(theta_b), Bits(max_theta_in), Bits(step)}, [&] {
    // The banded LUT's θin as Fill makes them (Densify when the step is finer).
    const double delta = head[1] - head[0];
    const int per = step > 0 ? static_cast<int>(std::lround(delta / step)) : 1;
    Lut banded;                    // θin alone: for SliceCoordinate
    std::vector<int> measured_of;  // the head slice of each banded slice, −1 when inserted
    if (per > 1) {
      for (int k = 0; k <= (static_cast<int>(head.size()) - 1) * per; ++k) {
        banded.theta_in_deg.push_back(k * step);
        measured_of.push_back(k % per == 0 ? k / per : -1);
      }
    } else {
      banded.theta_in_deg = head;
      for (int k = 0; k < static_cast<int>(head.size()); ++k) measured_of.push_back(k);
    }
    const int k_meas_step = banded.slices();
    const double delta_b = banded.DeltaInDeg();
    const double last = head.back();
    const int k_total = static_cast<int>(std::floor(max_theta_in / delta_b + 1e-9)) + 1;
    const std::size_t texels = static_cast<std::size_t>(Lut::kHeight) * Lut::kWidth;
    const int n_new = k_total - k_meas_step;
    auto needs = std::make_shared<Needs>();
    if (n_new <= 0) return std::shared_ptr<const Needs>(std::move(needs));
    // Fill's blend weight w of a new slice's texel is above 0 where θout > θL − 5° and below 1
    // where θout < θL + 5° (both with a margin).
    const auto continues = [&](const View& v) {
      return std::min(v.theta_deg, 90.0) > last - kBlendDeg - 1e-6;
    };
    const auto reads_banded = [&](const View& v) {
      return std::min(v.theta_deg, 90.0) < last + kBlendDeg + 1e-6;
    };
    // The new slices, last first: each needs its albedo's texels (θout < 90°; the last one's
    // include those Validate reads) and those the next new slice continues; its model grid is
    // read where it continues the slice below and where the next one continues it.
    std::vector<ViewsPtr> views_new(static_cast<std::size_t>(n_new));
    for (int q = 0; q < n_new; ++q)
      views_new[static_cast<std::size_t>(q)] = SharedTables::ViewsAt((k_meas_step + q) * delta_b);
    std::vector<Mask> need(static_cast<std::size_t>(n_new));
    Mask continued(texels, 0);  // of the slice q: the texels slice q + 1 continues
    for (int q = n_new - 1; q >= 0; --q) {
      const Views& views = *views_new[static_cast<std::size_t>(q)];
      Mask m(texels, 0), model = continued, below(texels, 0);
      for (std::size_t n = 0; n < texels; ++n) {
        m[n] = views[n].theta_deg < 90.0 + 1e-6 || continued[n];
        if (m[n] && continues(views[n])) below[n] = 1, model[n] = 1;
      }
      const double t = (k_meas_step + q) * delta_b;
      needs->texels.emplace(SliceKey(t), m);
      needs->model.emplace(SliceKey(t), std::move(model));
      need[static_cast<std::size_t>(q)] = std::move(m);
      continued = std::move(below);
    }
    // Now `continued` is of the last banded slice. The banded LUT's reads: their taps.
    std::vector<Mask> taps(static_cast<std::size_t>(k_meas_step), Mask(texels, 0));
    taps.back() = continued;
    for (int q = 0; q < n_new; ++q) {
      const double t = (k_meas_step + q) * delta_b;
      const Views& views = *views_new[static_cast<std::size_t>(q)];
      for (std::size_t n = 0; n < texels; ++n) {
        const View v = views[n];
        if (!need[static_cast<std::size_t>(q)][n] || !reads_banded(v)) continue;
        const double ti = std::min(std::min(v.theta_deg, 90.0), last);
        const Vec3 w_d = SpecularFrame::FromThetaInDeg(ti).ToSpecular(
            SphericalDirectionDeg(std::min(t, 90.0), -v.phi_deg));
        const auto [k0, k1] = TapRange(banded.SliceCoordinate(ti), k_meas_step);
        const auto [j0, j1] = TapRange(RadToDeg(ThetaOf(w_d)) / Lut::kTexelDeg, Lut::kHeight);
        const auto [i0, i1] = TapRange(RadToDeg(PhiOf(w_d)) / Lut::kTexelDeg, Lut::kWidth);
        for (int kk = k0; kk <= k1; ++kk)
          for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i)
              taps[static_cast<std::size_t>(kk)][static_cast<std::size_t>(j) * Lut::kWidth + i] = 1;
      }
    }
    for (int k = 0; k < k_meas_step; ++k) {
      Mask m = taps[static_cast<std::size_t>(k)];
      if (measured_of[k] < 0) {
        needs->texels.emplace(SliceKey(banded.theta_in_deg[k]), m);
        needs->model.emplace(SliceKey(banded.theta_in_deg[k]), std::move(m));
        continue;
      }
      // The inserted slices on either side read this one at their own taps.
      for (int q = std::max(0, k - per + 1); q < std::min(k_meas_step, k + per); ++q)
        if (measured_of[q] < 0)
          for (std::size_t n = 0; n < texels; ++n) m[n] |= taps[static_cast<std::size_t>(q)][n];
      const double theta = head[static_cast<std::size_t>(measured_of[k])];
      Mask model = m;
      const ViewsPtr views = SharedTables::ViewsAt(theta);
      for (std::size_t n = 0; n < texels; ++n)
        if ((*views)[n].theta_deg > theta_b - 1e-6 && (*views)[n].theta_deg < 90.0 + 1e-6)
          model[n] = 1;
      needs->texels.emplace(SliceKey(theta), std::move(m));
      needs->model.emplace(SliceKey(theta), std::move(model));
    }
    return std::shared_ptr<const Needs>(std::move(needs));
  });
}

LeaveLastSliceOut Validate(const Lut& measured, double theta_b, const Lut& filled) {
  LeaveLastSliceOut v;
  const int k = measured.slices() - 1;
  v.theta_in_deg = measured.theta_in_deg[k];
  const int kf = static_cast<int>(
      std::find_if(filled.theta_in_deg.begin(), filled.theta_in_deg.end(),
                   [&](double t) { return std::fabs(t - v.theta_in_deg) < 1e-6; }) -
      filled.theta_in_deg.begin());
  std::vector<double> got, want;
  const ViewsPtr views = SharedTables::ViewsAt(v.theta_in_deg);
  for (int j = 0; j < Lut::kHeight; ++j)
    for (int i = 0; i < Lut::kWidth - 1; ++i) {
      if ((*views)[static_cast<std::size_t>(j) * Lut::kWidth + i].theta_deg > theta_b) continue;
      const float* a = filled.Texel(kf, j, i);
      const float* b = measured.Texel(k, j, i);
      got.push_back(double(a[0]) + a[1] + a[2]);
      want.push_back(double(b[0]) + b[1] + b[2]);
    }
  const double floor = 1e-3 * *std::max_element(want.begin(), want.end());
  std::vector<double> e(got.size());
  for (std::size_t n = 0; n < e.size(); ++n)
    e[n] = std::fabs(got[n] - want[n]) / std::max(want[n], floor);
  v.texels = e.size();
  const auto at = [&](double q) {
    std::vector<double> s = e;
    const std::size_t n =
        std::min(s.size() - 1, static_cast<std::size_t>(q * (s.size() - 1) + 0.5));
    std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(n), s.end());
    return s[n];
  };
  v.median = at(0.5);
  v.p90 = at(0.9);
  return v;
}

// Which validation is better: the lower p90 relative error, then the lower median (the tail is
// where glossy peaks and grazing growth sit, which a median over mostly diffuse texels misses).
std::pair<double, double> Key(const LeaveLastSliceOut& v) { return {v.p90, v.median}; }

bool Uniform(const Lut& lut) {
  const double delta = lut.DeltaInDeg();
  if (lut.slices() < 2 || !(delta > 0) || std::fabs(lut.theta_in_deg[0]) > 1e-9) return false;
  for (int k = 0; k < lut.slices(); ++k)
    if (std::fabs(lut.theta_in_deg[k] - k * delta) > 1e-6) return false;
  return true;
}

}  // namespace

std::string_view BeyondMethodName(BeyondMethod method) {
  switch (method) {
    case BeyondMethod::kClamp:
      return "clamp";
    case BeyondMethod::kHold:
      return "hold";
    case BeyondMethod::kModel:
      return "model";
    case BeyondMethod::kAuto:
      return "auto";
  }
  return "clamp";
}

BeyondMethod ParseBeyondMethod(std::string_view text) {
  for (BeyondMethod m :
       {BeyondMethod::kClamp, BeyondMethod::kHold, BeyondMethod::kModel, BeyondMethod::kAuto})
    if (text == BeyondMethodName(m)) return m;
  throw InvalidArgument("--beyond: expected clamp, hold, model or auto, got '" + std::string(text) +
                        "'");
}

void BeyondOptions::Validate() const {
  if (!(max_theta_in_deg > 0.0 && max_theta_in_deg <= 90.0))
    throw InvalidArgument("beyond: the largest extrapolated θin must be in (0°, 90°], got " +
                          std::to_string(max_theta_in_deg));
  if (subdivisions < 1 || subdivisions > 20)
    throw InvalidArgument("beyond: subdivisions of the measured θin step must be in [1, 20], got " +
                          std::to_string(subdivisions));
}

std::array<double, 3> FillModel::Eval(double theta_in_deg, double theta_out_deg,
                                      double phi_out_deg) const {
  const ShadingGeometry g = GeometryAt(theta_in_deg, theta_out_deg, phi_out_deg);
  const Rgb f = models::EvaluateRgb(material.model, g, material.values.data());
  return {f[0], f[1], f[2]};
}

std::string BeyondReportJson(const BeyondReport& r) {
  using nlohmann::ordered_json;
  ordered_json j;
  j["method"] = std::string(BeyondMethodName(r.used));
  j["requested"] = std::string(BeyondMethodName(r.requested));
  j["measured_theta_in"] = r.measured_theta_in_deg;
  j["extrapolated_theta_in"] = r.extrapolated_theta_in_deg;
  j["inserted_theta_in"] = r.inserted_theta_in_deg;
  j["subdivisions"] = r.subdivisions;
  const auto loo = [](const std::optional<LeaveLastSliceOut>& v) {
    if (!v) return ordered_json(nullptr);
    return ordered_json{{"theta_in", v->theta_in_deg},
                        {"median_relative_error", v->median},
                        {"p90_relative_error", v->p90},
                        {"texels", v->texels}};
  };
  j["leave_last_slice_out"] = loo(r.validation);
  j["leave_last_slice_out_hold"] = loo(r.validation_hold);
  j["leave_last_slice_out_model"] = loo(r.validation_model);
  if (r.model) {
    j["model"] = ordered_json::parse(MaterialToJson(r.model->material));
    j["model"]["median_relative_error"] = r.model->median_relative_error;
  } else {
    j["model"] = nullptr;
  }
  j["max_albedo"] = r.max_albedo;
  return j.dump();
}

FillModel FitFillModel(const Lut& lut, double theta_b, Model family) {
  if (lut.slices() == 0 || lut.texels.empty())
    throw InvalidArgument("FitFillModel: the LUT has no slices");
  std::vector<FitPoint> pts;
  std::array<double, 3> mean{};
  for (int k = 0; k < lut.slices(); ++k) {
    const double t = lut.theta_in_deg[k];
    const ViewsPtr views = SharedTables::ViewsAt(t);
    const GeometriesPtr geometry = SharedTables::GeometryAtViews(t, views);
    for (int j = 0; j < Lut::kHeight; ++j) {
      // Every texel row near the peak (every third column), every fourth row and column
      // elsewhere.
      const bool near = j <= 20;
      if (!near && j % 4 != 0) continue;
      for (int i = 0; i < Lut::kWidth - 1; i += near ? 3 : 4) {
        const std::size_t n = static_cast<std::size_t>(j) * Lut::kWidth + i;
        if ((*views)[n].theta_deg > theta_b) continue;
        FitPoint p;
        p.g = (*geometry)[n];
        const float* f = lut.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) p.f[c] = f[c], mean[c] += f[c];
        pts.push_back(p);
      }
    }
  }
  std::array<double, 3> eps{};
  const double all = (mean[0] + mean[1] + mean[2]) / (3.0 * std::max<std::size_t>(pts.size(), 1));
  for (int c = 0; c < 3; ++c) eps[c] = 0.02 * all + 1e-6;
  const FitData data = FitDataOf(pts, eps, family);
  std::vector<ShapeFreeTerms> terms(pts.size());
  for (std::size_t k = 0; k < pts.size(); ++k) terms[k] = ShapeFreeTermsOf(family, pts[k].g);
  // The grid's shapes and the golden section's first two (set by the best grid shape alone) are
  // shared; the later ones depend on the values fitted and are computed here.
  const auto fit_at = [&](double shape, Candidate* out, bool shared = true) {
    if (!shared) return FitAtShape(data, PartsAtShape(family, terms, shape), shape, out);
    return FitAtShape(data, *SharedPartsAtShape(family, lut.theta_in_deg, theta_b, terms, shape),
                      shape, out);
  };
  const bool lafortune = family == Model::kLafortune;
  const double lo = std::log(lafortune ? 1.0 : 0.005), hi = std::log(lafortune ? 20000.0 : 1.5);
  Candidate best, trial;
  double best_cost = HUGE_VAL;
  const int n_grid = 16;
  int best_n = 0;
  for (int n = 0; n < n_grid; ++n) {
    const double c = fit_at(std::exp(lo + (hi - lo) * n / (n_grid - 1)), &trial);
    if (c < best_cost) best_cost = c, best = trial, best_n = n;
  }
  // Golden section in log(shape) between the grid neighbours.
  double a = lo + (hi - lo) * std::max(0, best_n - 1) / (n_grid - 1);
  double b = lo + (hi - lo) * std::min(n_grid - 1, best_n + 1) / (n_grid - 1);
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  Candidate m1, m2;
  double f1 = fit_at(std::exp(x1), &m1);
  double f2 = fit_at(std::exp(x2), &m2);
  for (int it = 0; it < 12; ++it) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, m2 = m1;
      x1 = b - g * (b - a);
      f1 = fit_at(std::exp(x1), &m1, false);
    } else {
      a = x1, x1 = x2, f1 = f2, m1 = m2;
      x2 = a + g * (b - a);
      f2 = fit_at(std::exp(x2), &m2, false);
    }
  }
  if (f1 < best_cost) best = m1, best_cost = f1;
  if (f2 < best_cost) best = m2, best_cost = f2;
  FillModel out;
  out.material =
      Material::Make(family,
                     {Rgb{best.a[0], best.a[1], best.a[2]}, Rgb{best.b[0], best.b[1], best.b[2]},
                      Rgb{best.shape, best.shape, best.shape}},
                     "blind-spot fill");
  std::vector<double> rel;
  rel.reserve(pts.size() * 3);
  for (const FitPoint& p : pts) {
    // models::EvaluateRgb(family, p.g, …), its shape terms once for the three channels.
    const std::array<double, 3> m = detail::EvaluateFillModel(out.material, p.g);
    for (int c = 0; c < 3; ++c) rel.push_back(std::fabs(m[c] - p.f[c]) / std::max(p.f[c], 1e-3));
  }
  if (!rel.empty()) {
    std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(rel.size() / 2),
                     rel.end());
    out.median_relative_error = rel[rel.size() / 2];
  }
  out.texels = pts.size();
  return out;
}

Lut ExtendBeyondMeasured(const Lut& measured, double theta_b, const BeyondOptions& options,
                         BeyondReport* report) {
  options.Validate();
  BeyondReport local;
  BeyondReport& r = report ? *report : local;
  r = BeyondReport{};
  r.requested = options.method;
  r.measured_theta_in_deg = measured.theta_in_deg;
  const double last = measured.theta_in_deg.empty() ? 0.0 : measured.theta_in_deg.back();
  const double step = measured.DeltaInDeg() / options.subdivisions;
  if (options.method == BeyondMethod::kClamp || !Uniform(measured) ||
      !(options.max_theta_in_deg >= last + step - 1e-9))
    return measured;
  r.subdivisions = options.subdivisions;
  const double fill_step = options.subdivisions > 1 ? step : 0.0;

  // Validation: the fill from all slices but the last, read at the last one.
  const bool validate = measured.slices() >= 3;
  Lut head;
  if (validate) {
    head.theta_in_deg.assign(measured.theta_in_deg.begin(), measured.theta_in_deg.end() - 1);
    head.texels.assign(
        measured.texels.begin(),
        measured.texels.begin() +
            static_cast<std::ptrdiff_t>(head.theta_in_deg.size() * Lut::kHeight * Lut::kWidth * 3));
  }
  // One table of slices for every fill below (the ratios differ only in their model).
  const auto geometry = std::make_shared<GeometryCache>();
  const auto ratio_of = [&](const FillModel* model) {
    Ratio ratio;
    ratio.model = model;
    ratio.geometry = geometry;
    return ratio;
  };
  // What the validations' fills need (they are read at the left-out slice alone).
  const std::shared_ptr<const Needs> needs =
      validate ? ValidationNeeds(head.theta_in_deg, theta_b, last, fill_step) : nullptr;
  const auto validate_with = [&](Ratio ratio) {
    ratio.needs = needs;
    BeyondReport scratch;
    const Lut f = Fill(head, theta_b, last, fill_step, ratio, &scratch);
    return Validate(measured, theta_b, f);
  };
  BeyondMethod use = options.method;
  if (validate && (use == BeyondMethod::kHold || use == BeyondMethod::kAuto))
    r.validation_hold = validate_with(ratio_of(nullptr));
  // kModel: the family whose fill predicts the left-out slice best (GGX without validation).
  Model family = Model::kGgx;
  if (validate && (use == BeyondMethod::kModel || use == BeyondMethod::kAuto)) {
    for (Model m : {Model::kGgx, Model::kWard, Model::kLafortune}) {
      const FillModel head_model = Widened(FitFillModel(head, theta_b, m));
      const LeaveLastSliceOut v = validate_with(ratio_of(&head_model));
      if (!r.validation_model || Key(v) < Key(*r.validation_model)) {
        r.validation_model = v;
        family = m;
      }
    }
  }
  if (use == BeyondMethod::kAuto) {
    use = BeyondMethod::kModel;
    if (r.validation_hold && r.validation_model &&
        Key(*r.validation_hold) < Key(*r.validation_model))
      use = BeyondMethod::kHold;
  }
  r.used = use;
  r.validation = use == BeyondMethod::kModel ? r.validation_model : r.validation_hold;
  if (use == BeyondMethod::kModel) {
    r.model = FitFillModel(measured, theta_b, family);
    const FillModel ratio_model = Widened(*r.model);
    return Fill(measured, theta_b, options.max_theta_in_deg, fill_step, ratio_of(&ratio_model), &r);
  }
  return Fill(measured, theta_b, options.max_theta_in_deg, fill_step, ratio_of(nullptr), &r);
}

}  // namespace brdf::processing
