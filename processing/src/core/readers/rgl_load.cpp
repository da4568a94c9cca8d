// RglBrdf::Load: an RGL `.bsdf` tensor file checked field by field and turned into the
// evaluator's tables (rgl_eval.h): normalised VNDF warps with their CDFs, the interleaved RGB.
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
#include "readers/text_util.h"

namespace brdf {

using detail::Interpolant2;

namespace {

// Table dimensions are stored as int; real files use at most a few hundred.
constexpr std::uint64_t kMaxDimension = 1u << 16;
// Largest magnitude accepted in any table (real files stay below 1e5). With it, every
// product the evaluator forms (rgb · ndf / 4σ, σ ≥ the smallest float) stays finite in double.
constexpr double kMaxMagnitude = 1e30;

std::string Quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string FieldPosition(const TensorField& f) {
  return BytePosition(f.header_offset) + " (header of field " + Quoted(f.name) + ")";
}

std::string IndexString(const std::vector<std::uint64_t>& shape, std::uint64_t flat) {
  std::vector<std::uint64_t> idx(shape.size());
  for (std::size_t d = shape.size(); d-- > 0;) {
    idx[d] = shape[d] == 0 ? 0 : flat % shape[d];
    flat = shape[d] == 0 ? 0 : flat / shape[d];
  }
  std::string s = "[";
  for (std::size_t d = 0; d < idx.size(); ++d) s += (d ? ", " : "") + std::to_string(idx[d]);
  return s + "]";
}

// Field checks shared by every field the evaluator reads.
class FieldChecker {
 public:
  explicit FieldChecker(const TensorFile& tf) : tf_(tf) {}

  const TensorField& Get(std::string_view name, TensorDtype dtype, std::size_t rank,
                         std::string_view meaning) const {
    const TensorField& f = tf_.Require(name);
    if (f.dtype != dtype || f.shape.size() != rank)
      throw FormatError(tf_.file(), FieldPosition(f),
                        "field " + Quoted(name) + " (" + std::string(meaning) + ") of " +
                            TensorDtypeName(dtype) + " with rank " + std::to_string(rank),
                        TensorDtypeName(f.dtype) + " with shape " + f.ShapeString());
    for (std::size_t d = 0; d < rank; ++d)
      if (f.shape[d] == 0 || f.shape[d] > kMaxDimension)
        throw FormatError(
            tf_.file(), FieldPosition(f),
            "field " + Quoted(name) + " dimensions between 1 and " + std::to_string(kMaxDimension),
            "shape " + f.ShapeString());
    return f;
  }

  void Shape(const TensorField& f, const std::vector<std::uint64_t>& expected,
             std::string_view meaning) const {
    if (f.shape != expected) {
      TensorField e;
      e.shape = expected;
      throw FormatError(tf_.file(), FieldPosition(f),
                        "field " + Quoted(f.name) + " of shape " + e.ShapeString() + " (" +
                            std::string(meaning) + ")",
                        "shape " + f.ShapeString());
    }
  }

  void AtLeast(const TensorField& f, std::size_t dim, std::uint64_t min,
               std::string_view meaning) const {
    if (f.shape[dim] < min)
      throw FormatError(tf_.file(), FieldPosition(f),
                        "field " + Quoted(f.name) + " dimension " + std::to_string(dim) +
                            " >= " + std::to_string(min) + " (" + std::string(meaning) + ")",
                        "shape " + f.ShapeString());
  }

  // Every element finite and satisfying `ok`; the first offender is named by byte and index.
  template <class Pred>
  std::vector<float> Values(const TensorField& f, Pred ok, std::string_view requirement) const {
    std::vector<float> v = tf_.Float32(f);
    for (std::size_t k = 0; k < v.size(); ++k) {
      const bool absurd = std::isfinite(v[k]) && std::abs(v[k]) > kMaxMagnitude;
      if (!std::isfinite(v[k]) || absurd || !ok(v[k]))
        throw FormatError(tf_.file(),
                          BytePosition(f.data_offset + 4 * k) + " (field " + Quoted(f.name) +
                              " element " + IndexString(f.shape, k) + ")",
                          absurd ? "a magnitude of at most 1e30" : std::string(requirement),
                          FormatValue(v[k]));
    }
    return v;
  }

  static std::string FormatValue(float v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    return buf;
  }

  const TensorFile& tf() const { return tf_; }

 private:
  const TensorFile& tf_;
};

std::vector<double> StrictlyIncreasing(const FieldChecker& ck, const TensorField& f,
                                       std::string_view unit) {
  const std::vector<float> v = ck.Values(
      f, [](float) { return true; }, "finite " + std::string(unit));
  for (std::size_t k = 1; k < v.size(); ++k)
    if (!(v[k] > v[k - 1]))
      throw FormatError(
          ck.tf().file(),
          BytePosition(f.data_offset + 4 * k) + " (field " + Quoted(f.name) + " element " +
              std::to_string(k) + ")",
          "values increasing strictly (previous " + FieldChecker::FormatValue(v[k - 1]) + ")",
          FieldChecker::FormatValue(v[k]));
  return {v.begin(), v.end()};
}

}  // namespace

RglBrdf RglBrdf::Load(const std::string& path) {
  return FromTensorFile(TensorFile::Read(path), std::filesystem::path(path).filename().string());
}

RglBrdf RglBrdf::FromTensorFile(const TensorFile& tf, std::string name) {
  const FieldChecker ck(tf);
  auto t = std::make_unique<Tables>();
  RglInfo& info = t->info;

  if (const TensorField* d = tf.Find("description")) {
    if (d->dtype != TensorDtype::kUInt8 || d->shape.size() != 1)
      throw FormatError(tf.file(), FieldPosition(*d),
                        "field 'description' of uint8 with rank 1 (UTF-8 text)",
                        TensorDtypeName(d->dtype) + " with shape " + d->ShapeString());
    const auto bytes = tf.Data(*d);
    info.description.assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (!detail::IsValidUtf8(info.description))
      throw FormatError(tf.file(), BytePosition(d->data_offset) + " (field 'description')",
                        "UTF-8 text", "invalid UTF-8 bytes");
  }

  const TensorField& phi_f = ck.Get("phi_i", TensorDtype::kFloat32, 1, "incidence azimuths, rad");
  const TensorField& theta_f =
      ck.Get("theta_i", TensorDtype::kFloat32, 1, "incidence elevations, rad");
  t->phi_i = StrictlyIncreasing(ck, phi_f, "azimuths in radians");
  t->theta_i = StrictlyIncreasing(ck, theta_f, "elevations in radians");
  const std::uint64_t np = t->phi_i.size(), nt = t->theta_i.size();
  for (auto [grid, inv] :
       {std::pair{&t->phi_i, &t->phi_i_inv_step}, std::pair{&t->theta_i, &t->theta_i_inv_step}})
    for (std::size_t k = 0; k + 1 < grid->size(); ++k)
      inv->push_back(1.0 / ((*grid)[k + 1] - (*grid)[k]));
  info.phi_i_rad = t->phi_i;
  info.theta_i_rad = t->theta_i;
  info.isotropic = np <= 2;
  if (!info.isotropic) {
    // The reference loader evaluates anisotropic files only when phi_i spans the full
    // circle; files reduced by symmetry (a half or a quarter) need mirroring it does not do.
    const double span = t->phi_i.back() - t->phi_i.front();
    const double reduction = std::rint(2.0 * kPi / span);
    if (reduction != 1.0)
      throw FormatError(tf.file(), FieldPosition(phi_f),
                        "phi_i covering the full circle (symmetry reduction 1)",
                        "a span of " + std::to_string(span) + " rad (reduction " +
                            std::to_string(reduction) + ")",
                        "reduced anisotropic files are not supported");
  }

  const TensorField& jac_f = ck.Get("jacobian", TensorDtype::kUInt8, 1, "flag");
  ck.Shape(jac_f, {1}, "one flag byte");
  info.jacobian = tf.Data(jac_f)[0] != 0;

  auto interpolant = [&](std::string_view field, std::string_view meaning, auto pred,
                         std::string_view requirement) {
    const TensorField& f = ck.Get(field, TensorDtype::kFloat32, 2, meaning);
    ck.AtLeast(f, 0, 2, "vertices along u(phi)");
    ck.AtLeast(f, 1, 2, "vertices along u(theta)");
    Interpolant2 out;
    out.ny = static_cast<int>(f.shape[0]);
    out.nx = static_cast<int>(f.shape[1]);
    out.v = ck.Values(f, pred, requirement);
    return out;
  };
  t->ndf = interpolant(
      "ndf", "microfacet normal distribution", [](float v) { return v >= 0; },
      "a finite NDF value >= 0");
  t->sigma = interpolant(
      "sigma", "projected microfacet area", [](float v) { return v > 0; },
      "a finite projected area > 0 (it divides)");

  const TensorField& vndf_f = ck.Get("vndf", TensorDtype::kFloat32, 4, "visible normal density");
  ck.Shape(vndf_f, {np, nt, vndf_f.shape[2], vndf_f.shape[3]},
           "[phi_i, theta_i, u(phi), u(theta)]");
  ck.AtLeast(vndf_f, 2, 2, "vertices along u(phi)");
  ck.AtLeast(vndf_f, 3, 2, "vertices along u(theta)");
  t->vy = static_cast<int>(vndf_f.shape[2]);
  t->vx = static_cast<int>(vndf_f.shape[3]);
  const std::vector<float> density = ck.Values(
      vndf_f, [](float x) { return x >= 0; }, "a finite density >= 0");

  const TensorField& rgb_f = ck.Get("rgb", TensorDtype::kFloat32, 5, "reflectance");
  ck.Shape(rgb_f, {np, nt, 3, rgb_f.shape[3], rgb_f.shape[4]},
           "[phi_i, theta_i, 3 channels, y, x]");
  ck.AtLeast(rgb_f, 3, 2, "vertices along y");
  ck.AtLeast(rgb_f, 4, 2, "vertices along x");
  t->ry = static_cast<int>(rgb_f.shape[3]);
  t->rx = static_cast<int>(rgb_f.shape[4]);
  const std::vector<float> planar = ck.Values(
      rgb_f, [](float) { return true; }, "a finite value");
  info.rgb_res = t->rx;
  info.rgb_values = planar.size();
  for (const float v : planar) info.negative_rgb_values += v < 0 ? 1 : 0;

  if (const TensorField* lum = tf.Find("luminance")) {
    // Only used for importance sampling, which we do not do; checked because the reference
    // loader requires it to match the RGB table.
    if (lum->dtype != TensorDtype::kFloat32 ||
        lum->shape != std::vector<std::uint64_t>{np, nt, rgb_f.shape[3], rgb_f.shape[4]})
      throw FormatError(tf.file(), FieldPosition(*lum),
                        "field 'luminance' of float32 with shape [phi_i, theta_i, y, x] = [" +
                            std::to_string(np) + ", " + std::to_string(nt) + ", " +
                            std::to_string(rgb_f.shape[3]) + ", " + std::to_string(rgb_f.shape[4]) +
                            "]",
                        TensorDtypeName(lum->dtype) + " with shape " + lum->ShapeString());
  }

  // Interleave the channels: [slice][c][y][x] -> [slice][y][x][c].
  const std::size_t slices = np * nt;
  const std::size_t plane = static_cast<std::size_t>(t->rx) * t->ry;
  t->rgb.resize(planar.size());
  for (std::size_t s = 0; s < slices; ++s)
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < plane; ++i)
        t->rgb[(s * plane + i) * 3 + c] = planar[(s * 3 + c) * plane + i];

  // Normalise each VNDF slice and tabulate its CDFs (running sums in double).
  const std::size_t vx = t->vx, vy = t->vy, slice_size = vx * vy;
  t->warp.assign(2 * density.size(), 0.0);
  t->rows.assign(2 * slices * vy, 0.0);
  std::vector<double> row_cum(slice_size), marg_cum(vy);
  for (std::size_t s = 0; s < slices; ++s) {
    const float* d = density.data() + s * slice_size;
    for (std::size_t y = 0; y < vy; ++y) {
      double sum = 0.0;
      row_cum[y * vx] = 0.0;
      for (std::size_t x = 0; x + 1 < vx; ++x) {
        sum += 0.5 * (static_cast<double>(d[y * vx + x]) + d[y * vx + x + 1]);
        row_cum[y * vx + x + 1] = sum;
      }
    }
    double sum = 0.0;
    marg_cum[0] = 0.0;
    for (std::size_t y = 0; y + 1 < vy; ++y) {
      sum += 0.5 * (row_cum[y * vx + vx - 1] + row_cum[(y + 1) * vx + vx - 1]);
      marg_cum[y + 1] = sum;
    }
    if (!(sum > 0.0) || !std::isfinite(sum))
      throw FormatError(
          tf.file(),
          BytePosition(vndf_f.data_offset + 4 * s * slice_size) + " (field 'vndf' slice " +
              IndexString({np, nt}, static_cast<std::uint64_t>(s)) + ")",
          "a visible normal density with positive total mass", "total " + std::to_string(sum));
    const double norm = 1.0 / sum;
    double* w = t->warp.data() + 2 * s * slice_size;
    for (std::size_t i = 0; i < slice_size; ++i) {
      w[2 * i] = d[i] * norm;
      w[2 * i + 1] = row_cum[i] * norm;
    }
    double* r = t->rows.data() + 2 * s * vy;
    for (std::size_t y = 0; y < vy; ++y) {
      r[2 * y] = row_cum[y * vx + vx - 1] * norm;
      r[2 * y + 1] = marg_cum[y] * norm;
    }
  }
  bool sigma_same_for_all_phi = true;
  for (int y = 1; y < t->sigma.ny; ++y)
    for (int x = 0; x < t->sigma.nx; ++x)
      sigma_same_for_all_phi &=
          t->sigma.v[static_cast<std::size_t>(y) * t->sigma.nx + x] == t->sigma.v[x];
  t->relative_phi_only = info.isotropic && np == 1 && sigma_same_for_all_phi;
  info.vndf_theta_res = t->vx;
  info.vndf_phi_res = t->vy;
  return RglBrdf(std::move(t), std::move(name));
}

}  // namespace brdf
