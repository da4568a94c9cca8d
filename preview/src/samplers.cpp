// Importance sampling of the environment map and of BRDFs (preview.h). Every Sample() has a
// Pdf() that returns exactly the density of what it draws; tests/preview/preview_test.cpp
// checks each pair with a χ² test.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/preview/preview.h"
#include "distribution.h"
#include "preview_internal.h"

namespace brdf::preview {
namespace {

using detail::Distribution2D;

Vec3 SampleCosine(double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))};
}
double CosinePdf(const Vec3& w) { return w.z > 0.0 ? w.z * kInvPi : 0.0; }

// ---- GGX: visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals",
// JCGT 7(4)) mixed with cosine sampling for the diffuse term.
class GgxSampler final : public BrdfSampler {
 public:
  GgxSampler(double alpha, double specular_probability)
      : alpha_(std::max(alpha, 1e-4)), specular_probability_(specular_probability) {}

  bool Sample(const Vec3& wo, double u1, double u2, double u3, Vec3* wi,
              double* pdf) const override {
    if (!(wo.z > 0.0)) return false;
    if (u3 < specular_probability_) {
      const Vec3 h = SampleVisibleNormal(wo, u1, u2);
      const double d = 2.0 * Dot(wo, h);
      *wi = h * d - wo;
    } else {
      *wi = SampleCosine(u1, u2);
    }
    if (!(wi->z > 0.0)) return false;
    *pdf = Pdf(wo, *wi);
    return *pdf > 0.0;
  }

  double Pdf(const Vec3& wo, const Vec3& wi) const override {
    if (!(wo.z > 0.0) || !(wi.z > 0.0)) return 0.0;
    const Vec3 h = Normalize(wo + wi);
    // D_wo(h) = G1(wo)·max(0, wo·h)·D(h)/wo.z; reflecting about h has Jacobian 1/(4 wo·h).
    const double specular =
        models::GgxG1(wo.z, alpha_ * alpha_) * models::GgxD(h.z, alpha_ * alpha_) / (4.0 * wo.z);
    return specular_probability_ * specular + (1.0 - specular_probability_) * CosinePdf(wi);
  }

  std::string Kind() const override { return "ggx-vndf"; }

 private:
  Vec3 SampleVisibleNormal(const Vec3& wo, double u1, double u2) const {
    const Vec3 vh = Normalize(Vec3{alpha_ * wo.x, alpha_ * wo.y, wo.z});
    const double len2 = vh.x * vh.x + vh.y * vh.y;
    const Vec3 t1 =
        len2 > 0.0 ? Vec3{-vh.y, vh.x, 0.0} * (1.0 / std::sqrt(len2)) : Vec3{1.0, 0.0, 0.0};
    const Vec3 t2 = detail::Cross(vh, t1);
    const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
    const double p1 = r * std::cos(phi);
    double p2 = r * std::sin(phi);
    const double s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
    const Vec3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2));
    return Normalize(Vec3{alpha_ * nh.x, alpha_ * nh.y, std::max(1e-12, nh.z)});
  }

  double alpha_;
  double specular_probability_;
};

// ---- Tabulated: for any source. For a set of viewer polar angles θ_k (the slices), a 2D
// table over the light direction in the specular frame of the viewer direction,
// ω_d = S(θ_o)·R_z(−φ_o)·ω_i (geometry.h), which puts the mirror of ω_o at the pole: the lobe
// of glossy materials stays near θd = 0 at every θ_o. Cells are uniform in u = √(θd/π) and in
// φd, so they are small near the mirror direction (the first ring is 0.04° across) and about
// 2.8° wide at θd = 45°. Each cell's weight is the source's luminance f_r·cosθ_i at the cell's
// centre times its solid angle; inside a cell directions are drawn uniformly in solid angle, so
// the density is the cell's probability over its solid angle. Between slices, the slice is
// chosen at random with the linear interpolation weights (a mixture, so the density is the
// same mixture). A fraction kDefensive of the draws is cosine-distributed so that every
// direction where f_r > 0 has positive density, whatever the table missed.
class TabulatedSampler final : public BrdfSampler {
 public:
  static constexpr int kSlices = 23;  // θ_o = 0°, 4°, …, 88°
  static constexpr double kSliceStepDeg = 4.0;
  static constexpr int kThetaCells = 64;
  static constexpr int kPhiCells = 64;
  static constexpr double kDefensive = 0.1;

  TabulatedSampler(const BrdfSource& source, int jobs) : tables_(kSlices) {
    ParallelChunks(kSlices, 1, jobs, nullptr, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) tables_[k] = BuildSlice(source, static_cast<int>(k));
    });
  }

  bool Sample(const Vec3& wo, double u1, double u2, double u3, Vec3* wi,
              double* pdf) const override {
    if (!(wo.z > 0.0)) return false;
    if (u3 < kDefensive) {
      *wi = SampleCosine(u1, u2);
    } else {
      const Slices s = SlicesOf(wo);
      const double u = (u3 - kDefensive) / (1.0 - kDefensive);
      const Distribution2D& table = tables_[u < s.weight0 ? s.k0 : s.k1];
      if (table.total() <= 0.0) {
        *wi = SampleCosine(u1, u2);
      } else {
        std::size_t row = 0, column = 0;
        double a = 0, b = 0;
        table.SampleCell(u1, u2, &row, &column, &a, &b);
        const double cos0 = std::cos(ThetaEdge(row)), cos1 = std::cos(ThetaEdge(row + 1));
        const double cos_d = cos0 + (cos1 - cos0) * a;
        const double sin_d = std::sqrt(std::max(0.0, 1.0 - cos_d * cos_d));
        const double phi_d = 2.0 * kPi * (column + b) / kPhiCells;
        const Vec3 wd = {sin_d * std::cos(phi_d), sin_d * std::sin(phi_d), cos_d};
        *wi = FromSpecular(wo, wd);
      }
    }
    if (!(wi->z > 0.0)) return false;
    *pdf = Pdf(wo, *wi);
    return *pdf > 0.0;
  }

  double Pdf(const Vec3& wo, const Vec3& wi) const override {
    if (!(wo.z > 0.0) || !(wi.z > 0.0)) return 0.0;
    const Slices s = SlicesOf(wo);
    const Vec3 wd = ToSpecular(wo, wi);
    const double theta_d = ThetaOf(wd);
    const int row =
        std::min(kThetaCells - 1, static_cast<int>(std::sqrt(theta_d / kPi) * kThetaCells));
    const int column =
        std::min(kPhiCells - 1, static_cast<int>(PhiOf(wd) / (2.0 * kPi) * kPhiCells));
    const double cell_solid_angle =
        (std::cos(ThetaEdge(row)) - std::cos(ThetaEdge(row + 1))) * 2.0 * kPi / kPhiCells;
    auto table_pdf = [&](int k) {
      const Distribution2D& table = tables_[k];
      if (table.total() <= 0.0) return CosinePdf(wi);
      return table.CellProbability(row, column) / cell_solid_angle;
    };
    double tabulated = s.weight0 * table_pdf(s.k0);
    if (s.weight0 < 1.0) tabulated += (1.0 - s.weight0) * table_pdf(s.k1);
    return kDefensive * CosinePdf(wi) + (1.0 - kDefensive) * tabulated;
  }

  std::string Kind() const override { return "tabulated"; }

 private:
  struct Slices {
    int k0, k1;
    double weight0;  // probability of k0
  };
  static Slices SlicesOf(const Vec3& wo) {
    const double x = RadToDeg(ThetaOf(wo)) / kSliceStepDeg;
    const int k0 = std::clamp(static_cast<int>(std::floor(x)), 0, kSlices - 1);
    const int k1 = std::min(k0 + 1, kSlices - 1);
    const double t = std::clamp(x - k0, 0.0, 1.0);
    return {k0, k1, k1 == k0 ? 1.0 : 1.0 - t};
  }
  static double ThetaEdge(std::size_t row) {
    const double u = static_cast<double>(row) / kThetaCells;
    return kPi * u * u;
  }
  // ω_d = S(θ_o)·R_z(−φ_o)·ω_i and its inverse (both maps are orthogonal).
  static Vec3 ToSpecular(const Vec3& wo, const Vec3& wi) {
    const double phi = PhiOf(wo);
    const Vec3 canonical = detail::RotateZ(wi, std::cos(phi), -std::sin(phi));
    return SpecularFrame::FromThetaInRad(ThetaOf(wo)).Apply(canonical);
  }
  static Vec3 FromSpecular(const Vec3& wo, const Vec3& wd) {
    const double phi = PhiOf(wo);
    const Vec3 canonical = SpecularFrame::FromThetaInRad(ThetaOf(wo)).Apply(wd);
    return detail::RotateZ(canonical, std::cos(phi), std::sin(phi));
  }

  static Distribution2D BuildSlice(const BrdfSource& source, int k) {
    const double theta_o = DegToRad(k * kSliceStepDeg);
    const Vec3 wo = {std::sin(theta_o), 0.0, std::cos(theta_o)};
    const SpecularFrame frame = SpecularFrame::FromThetaInRad(theta_o);
    std::vector<double> weights(static_cast<std::size_t>(kThetaCells) * kPhiCells, 0.0);
    for (int row = 0; row < kThetaCells; ++row) {
      const double cos0 = std::cos(ThetaEdge(row)), cos1 = std::cos(ThetaEdge(row + 1));
      const double cos_d = 0.5 * (cos0 + cos1);
      const double sin_d = std::sqrt(std::max(0.0, 1.0 - cos_d * cos_d));
      const double solid_angle = (cos0 - cos1) * 2.0 * kPi / kPhiCells;
      for (int column = 0; column < kPhiCells; ++column) {
        const double phi_d = 2.0 * kPi * (column + 0.5) / kPhiCells;
        const Vec3 wi = frame.Apply({sin_d * std::cos(phi_d), sin_d * std::sin(phi_d), cos_d});
        if (!(wi.z > 0.0)) continue;
        const Rgb f = source.Eval(wi, wo);
        const double value = std::max(0.0, detail::Luminance(f)) * wi.z * solid_angle;
        if (std::isfinite(value))
          weights[static_cast<std::size_t>(row) * kPhiCells + column] = value;
      }
    }
    return Distribution2D(weights, kThetaCells, kPhiCells);
  }

  std::vector<Distribution2D> tables_;
};

}  // namespace

std::shared_ptr<const BrdfSampler> MakeBrdfSampler(const BrdfSource& source, int jobs) {
  if (const auto* analytic = dynamic_cast<const AnalyticBrdf*>(&source);
      analytic != nullptr && analytic->material().model == Model::kGgx) {
    const Material& m = analytic->material();
    const Rgb a = m.Parameter("alpha"), f0 = m.Parameter("f0"), kd = m.Parameter("kd");
    const double alpha = (a[0] + a[1] + a[2]) / 3.0;
    const double specular = std::max(1e-3, (f0[0] + f0[1] + f0[2]) / 3.0);
    const double diffuse = std::max(0.0, (kd[0] + kd[1] + kd[2]) / 3.0);
    const double p = std::clamp(specular / (specular + diffuse), 0.1, 0.95);
    return std::make_shared<GgxSampler>(alpha, p);
  }
  return std::make_shared<TabulatedSampler>(source, ResolveJobs(jobs));
}

// ---- Environment map: a piecewise-constant density over the map's pixels in (u, v) =
// (φ/2π, θ/π), pixel weight max(R, G, B)·sinθ at the pixel centre, uniform in (θ, φ) inside a
// pixel. A direction's density per unit solid angle is p(u, v) / (2π² sinθ): the sinθ Jacobian
// of the equirectangular parameterisation (dω = sinθ dθ dφ = 2π² sinθ du dv).
struct EnvironmentSampler::Impl {
  int width = 0, height = 0;
  Distribution2D table;
};

EnvironmentSampler::EnvironmentSampler(const EnvironmentMap& map)
    : impl_(std::make_unique<Impl>()) {
  impl_->width = map.width();
  impl_->height = map.height();
  std::vector<double> weights(static_cast<std::size_t>(map.width()) * map.height());
  for (int j = 0; j < map.height(); ++j) {
    const double sin_theta = std::sin((j + 0.5) * kPi / map.height());
    for (int i = 0; i < map.width(); ++i) {
      const float* p = map.Pixel(i, j);
      weights[static_cast<std::size_t>(j) * map.width() + i] =
          std::max({p[0], p[1], p[2]}) * sin_theta;
    }
  }
  impl_->table = Distribution2D(weights, map.height(), map.width());
}
EnvironmentSampler::~EnvironmentSampler() = default;
EnvironmentSampler::EnvironmentSampler(EnvironmentSampler&&) noexcept = default;

bool EnvironmentSampler::Sample(double u1, double u2, Vec3* w, double* pdf) const {
  if (impl_->table.total() <= 0.0) return false;
  std::size_t row = 0, column = 0;
  double a = 0, b = 0;
  impl_->table.SampleCell(u1, u2, &row, &column, &a, &b);
  const double theta = (row + a) * kPi / impl_->height;
  const double phi = (column + b) * 2.0 * kPi / impl_->width;
  const double sin_theta = std::sin(theta);
  if (!(sin_theta > 0.0)) return false;
  *w = SphericalDirection(theta, phi);
  const double density_uv =
      impl_->table.CellProbability(row, column) * static_cast<double>(impl_->width) * impl_->height;
  *pdf = density_uv / (2.0 * kPi * kPi * sin_theta);
  return true;
}

double EnvironmentSampler::Pdf(const Vec3& w) const {
  if (impl_->table.total() <= 0.0) return 0.0;
  const double theta = ThetaOf(w);
  const double sin_theta = std::sin(theta);
  if (!(sin_theta > 0.0)) return 0.0;
  const int i = std::min(impl_->width - 1, static_cast<int>(PhiOf(w) / (2.0 * kPi) * impl_->width));
  const int j = std::min(impl_->height - 1, static_cast<int>(theta / kPi * impl_->height));
  const double density_uv =
      impl_->table.CellProbability(j, i) * static_cast<double>(impl_->width) * impl_->height;
  return density_uv / (2.0 * kPi * kPi * sin_theta);
}

}  // namespace brdf::preview
