// Environment maps: validation, lookup, the procedural maps and files.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/preview/preview.h"
#include "preview_internal.h"

namespace brdf::preview {
namespace {

using detail::Length;

// Directions of the pixel centres, ω(θ_j, φ_i) with θ_j = (j + ½)·π/height and
// φ_i = (i + ½)·2π/width: sin/cos are taken once per row and once per column.
class PixelCentres {
 public:
  PixelCentres(int width, int height) {
    for (int j = 0; j < height; ++j) {
      const double theta = (j + 0.5) * kPi / height;
      sin_theta_.push_back(std::sin(theta));
      cos_theta_.push_back(std::cos(theta));
    }
    for (int i = 0; i < width; ++i) {
      const double phi = (i + 0.5) * 2.0 * kPi / width;
      sin_phi_.push_back(std::sin(phi));
      cos_phi_.push_back(std::cos(phi));
    }
  }
  // The same numbers as SphericalDirection(θ_j, φ_i).
  Vec3 At(int i, int j) const {
    return {sin_theta_[j] * cos_phi_[i], sin_theta_[j] * sin_phi_[i], cos_theta_[j]};
  }

 private:
  std::vector<double> sin_theta_, cos_theta_, sin_phi_, cos_phi_;
};

template <class F>
std::vector<float> Tabulate(int width, int height, F radiance) {
  const PixelCentres centres(width, height);
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const Rgb c = radiance(centres.At(i, j));
      float* p = &rgb[(static_cast<std::size_t>(j) * width + i) * 3];
      for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(c[k]);
    }
  return rgb;
}

double SmoothStep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// A soft box: a rectangle on the sphere centred on direction (θc, φc), `half_width_deg` across
// and `half_height_deg` up and down in the box's own tangent frame, edges softened over
// `soft_deg`.
class SoftBox {
 public:
  SoftBox(double theta_deg, double phi_deg, double half_width_deg, double half_height_deg,
          double soft_deg, Rgb radiance)
      : radiance_(radiance),
        across_(half_width_deg, soft_deg),
        upward_(half_height_deg, soft_deg),
        centre_(SphericalDirectionDeg(theta_deg, phi_deg)) {
    // Gnomonic coordinates on the plane tangent at the centre: right is horizontal, up towards
    // +z.
    right_ = detail::Cross(centre_, Vec3{0, 0, 1});
    right_ = right_ * (1.0 / Length(right_));
    up_ = detail::Cross(right_, centre_);
  }
  // The coverage of direction w, in [0, 1].
  double Coverage(const Vec3& w) const {
    const double cos_angle = Dot(w, centre_);
    if (cos_angle <= 0.0) return 0.0;
    const double x = across_.Inside(Dot(w, right_) / cos_angle);
    if (x == 0.0) return 0.0;
    return x * upward_.Inside(Dot(w, up_) / cos_angle);
  }
  const Rgb& radiance() const { return radiance_; }

 private:
  // One axis of the box: 1 − smoothstep(half − soft, half, |angle|) of the gnomonic coordinate
  // `tan_angle` = tan(angle). Outside the soft band the answer is exactly 1 or 0 whatever the
  // angle, so atan is only taken inside it; the band's limits on tan(angle) are widened by a
  // relative 1e-6, far more than atan's rounding, so that a direction is never classed on the
  // wrong side of them.
  struct Edge {
    double inner_deg, outer_deg, tan_inner, tan_outer;
    Edge(double half_deg, double soft_deg)
        : inner_deg(half_deg - soft_deg),
          outer_deg(half_deg),
          tan_inner(std::tan(DegToRad(half_deg - soft_deg)) * (1.0 - 1e-6)),
          tan_outer(std::tan(DegToRad(half_deg)) * (1.0 + 1e-6)) {}
    double Inside(double tan_angle) const {
      const double t = std::fabs(tan_angle);
      if (t >= tan_outer) return 0.0;
      if (t <= tan_inner) return 1.0;
      return 1.0 - SmoothStep(inner_deg, outer_deg, std::fabs(RadToDeg(std::atan(tan_angle))));
    }
  };
  Rgb radiance_;
  Edge across_, upward_;
  Vec3 centre_, right_{}, up_{};
};

void CheckSize(int width, int height) {
  if (width < 1 || height < 1 || width > 16384 || height > 8192)
    throw InvalidArgument("environment map: size must be between 1 × 1 and 16384 × 8192, got " +
                          std::to_string(width) + " × " + std::to_string(height));
}

}  // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<float> rgb, std::string name)
    : width_(width), height_(height), rgb_(std::move(rgb)), name_(std::move(name)) {
  CheckSize(width, height);
  if (rgb_.size() != static_cast<std::size_t>(width) * height * 3)
    throw InvalidArgument("environment map '" + name_ + "': " + std::to_string(width) + " × " +
                          std::to_string(height) + " pixels need " +
                          std::to_string(static_cast<std::size_t>(width) * height * 3) +
                          " floats, got " + std::to_string(rgb_.size()));
  for (std::size_t k = 0; k < rgb_.size(); ++k)
    if (!(rgb_[k] >= 0.0f) || !std::isfinite(rgb_[k])) {
      const std::size_t p = k / 3;
      throw InvalidArgument("environment map '" + name_ + "': pixel (" + std::to_string(p % width) +
                            ", " + std::to_string(p / width) +
                            "): expected a finite radiance ≥ 0, got " + std::to_string(rgb_[k]));
    }
}

Rgb EnvironmentMap::Radiance(const Vec3& w) const {
  int i = 0, j = 0;
  detail::MapPixelOf(*this, w, &i, &j);
  const float* p = Pixel(i, j);
  return {p[0], p[1], p[2]};
}

EnvironmentMap EnvironmentMap::Studio(int width, int height) {
  CheckSize(width, height);
  // The default camera looks from +x (φ = 0); +y is to its right. The key light is high on the
  // camera's right, the fill low on its left, the rim light behind the object.
  const SoftBox boxes[] = {
      {40.0, 35.0, 22.0, 16.0, 4.0, {4.0, 3.9, 3.7}},     // key
      {70.0, 295.0, 14.0, 20.0, 5.0, {0.9, 0.95, 1.05}},  // fill
      {55.0, 165.0, 9.0, 28.0, 3.0, {3.0, 3.0, 3.0}},     // rim
  };
  std::vector<float> rgb = Tabulate(width, height, [&](const Vec3& w) {
    // Gradient: 0.05 at and below the horizon, 0.25 at the zenith.
    const double g = 0.05 + 0.2 * std::max(0.0, w.z);
    Rgb c = {g, g, g * 1.05};
    for (const SoftBox& box : boxes) {
      const double k = box.Coverage(w);
      for (int ch = 0; ch < 3; ++ch) c[ch] = c[ch] * (1.0 - k) + box.radiance()[ch] * k;
    }
    return c;
  });
  return EnvironmentMap(width, height, std::move(rgb), "studio");
}

EnvironmentMap EnvironmentMap::Sky(double sun_theta_deg, double sun_phi_deg, int width,
                                   int height) {
  CheckSize(width, height);
  if (!(sun_theta_deg >= 0.0 && sun_theta_deg < 90.0) || !std::isfinite(sun_phi_deg))
    throw InvalidArgument("sky: the sun's polar angle must be in [0, 90) degrees, got " +
                          NumberText(sun_theta_deg));
  const Vec3 sun = SphericalDirectionDeg(sun_theta_deg, sun_phi_deg);
  const double sun_theta = DegToRad(sun_theta_deg);
  // CIE standard clear sky (ISO 15469 type 12): gradation φ(θ) = 1 − exp(−0.32 / cosθ),
  // indicatrix f(γ) = 1 + 10 (exp(−3γ) − exp(−3π/2)) + 0.45 cos²γ; relative to the zenith.
  auto gradation = [](double cos_theta) { return 1.0 - std::exp(-0.32 / cos_theta); };
  auto indicatrix = [](double gamma) {
    return 1.0 + 10.0 * (std::exp(-3.0 * gamma) - std::exp(-1.5 * kPi)) +
           0.45 * std::cos(gamma) * std::cos(gamma);
  };
  const double zenith_norm = indicatrix(sun_theta) * gradation(1.0);
  const Rgb sky_tint = {0.55, 0.72, 1.0};
  // The gradation depends on the row alone (w.z = cosθ of the row's centre), so it is taken
  // once per row.
  const PixelCentres centres(width, height);
  std::vector<double> row_gradation(static_cast<std::size_t>(height));
  for (int j = 0; j < height; ++j)
    row_gradation[j] = gradation(std::max(centres.At(0, j).z, 0.02));  // keeps the horizon finite
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3, 0.0f);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const Vec3 w = centres.At(i, j);
      if (w.z <= 0.0) continue;
      const double gamma = std::acos(std::clamp(Dot(w, sun), -1.0, 1.0));
      const double l = indicatrix(gamma) * row_gradation[j] / zenith_norm;
      float* p = &rgb[(static_cast<std::size_t>(j) * width + i) * 3];
      for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(l * sky_tint[k]);
    }
  // The sun: irradiance kSunIrradiance on a surface facing it, spread over the pixels whose
  // centres lie within max(0.265°, one pixel) of the sun's direction, so even a coarse map
  // carries exactly that irradiance.
  constexpr double kSunIrradiance = 8.0;
  const Rgb sun_tint = {1.0, 0.95, 0.85};
  const double pixel_rad = std::max(2.0 * kPi / width, kPi / height);
  const double radius = std::max(DegToRad(0.265), 0.75 * pixel_rad);
  std::vector<std::size_t> disc;
  double disc_solid_angle = 0.0;
  const double cos_radius = std::cos(radius);
  for (int j = 0; j < height; ++j) {
    const double cos0 = std::cos(j * kPi / height), cos1 = std::cos((j + 1) * kPi / height);
    const double pixel_solid_angle = (cos0 - cos1) * 2.0 * kPi / width;
    for (int i = 0; i < width; ++i)
      if (const double cos_sun = Dot(centres.At(i, j), sun); cos_sun >= cos_radius) {
        disc.push_back(static_cast<std::size_t>(j) * width + i);
        disc_solid_angle += pixel_solid_angle * cos_sun;
      }
  }
  if (disc.empty()) {  // the disc fell between centres: take the sun's own pixel
    const Vec3 w = sun;
    const int i = std::min(width - 1, static_cast<int>(PhiOf(w) / (2.0 * kPi) * width));
    const int j = std::min(height - 1, static_cast<int>(ThetaOf(w) / kPi * height));
    disc.push_back(static_cast<std::size_t>(j) * width + i);
    const double cos0 = std::cos(j * kPi / height), cos1 = std::cos((j + 1) * kPi / height);
    disc_solid_angle = (cos0 - cos1) * 2.0 * kPi / width;
  }
  for (std::size_t p : disc)
    for (int c = 0; c < 3; ++c)
      rgb[p * 3 + c] += static_cast<float>(kSunIrradiance * sun_tint[c] / disc_solid_angle);
  // Ground of albedo 0.2 lit by the sky and the sun: L = 0.2 · E_horizontal / π.
  Rgb e_horizontal = {0, 0, 0};
  for (int j = 0; j < height / 2 + 1 && j < height; ++j) {
    const double cos0 = std::cos(j * kPi / height), cos1 = std::cos((j + 1) * kPi / height);
    const double pixel_solid_angle = (cos0 - cos1) * 2.0 * kPi / width;
    const double cos_theta = std::cos((j + 0.5) * kPi / height);
    if (cos_theta <= 0.0) continue;
    for (int i = 0; i < width; ++i)
      for (int c = 0; c < 3; ++c)
        e_horizontal[c] +=
            rgb[(static_cast<std::size_t>(j) * width + i) * 3 + c] * cos_theta * pixel_solid_angle;
  }
  for (int j = 0; j < height; ++j) {
    if (std::cos((j + 0.5) * kPi / height) > 0.0) continue;
    for (int i = 0; i < width; ++i)
      for (int c = 0; c < 3; ++c)
        rgb[(static_cast<std::size_t>(j) * width + i) * 3 + c] =
            static_cast<float>(0.2 * e_horizontal[c] * kInvPi);
  }
  return EnvironmentMap(width, height, std::move(rgb), "sky");
}

EnvironmentMap EnvironmentMap::Furnace(Rgb radiance, int width, int height) {
  CheckSize(width, height);
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  for (std::size_t p = 0; p < rgb.size(); p += 3)
    for (int c = 0; c < 3; ++c) rgb[p + c] = static_cast<float>(radiance[c]);
  return EnvironmentMap(width, height, std::move(rgb), "furnace");
}

EnvironmentMap EnvironmentMap::AxisCoded(int width, int height) {
  CheckSize(width, height);
  std::vector<float> rgb = Tabulate(width, height, [](const Vec3& w) {
    const double px = std::max(0.0, w.x), py = std::max(0.0, w.y), pz = std::max(0.0, w.z);
    const double nx = std::max(0.0, -w.x), ny = std::max(0.0, -w.y), nz = std::max(0.0, -w.z);
    return Rgb{px + 0.5 * (ny + nz), py + 0.5 * (nx + nz), pz + 0.5 * (nx + ny)};
  });
  return EnvironmentMap(width, height, std::move(rgb), "axes");
}

EnvironmentMap EnvironmentMap::Load(const std::string& path) {
  detail::RgbImage image = detail::ReadEnvironmentImage(path);
  if (image.width != 2 * image.height)
    throw FormatError(path, "image size", "an equirectangular map (width = 2 × height)",
                      std::to_string(image.width) + " × " + std::to_string(image.height));
  // Texels with a NaN, an infinity or a negative value in any channel carry no usable light:
  // they are taken as black, counted by kind and reported in one line; a map made of nothing
  // else lights nothing and is refused rather than rendered black.
  std::size_t nan = 0, positive_inf = 0, negative_inf = 0, negative = 0, bad = 0;
  const std::size_t texels = image.rgb.size() / 3;
  for (std::size_t t = 0; t < texels; ++t) {
    float* px = &image.rgb[3 * t];
    // Counted by the first unusable channel's kind.
    bool usable = true;
    for (int c = 0; c < 3 && usable; ++c) {
      const float v = px[c];
      usable = false;
      if (std::isnan(v))
        ++nan;
      else if (v == std::numeric_limits<float>::infinity())
        ++positive_inf;
      else if (v == -std::numeric_limits<float>::infinity())
        ++negative_inf;
      else if (v < 0.0f)
        ++negative;
      else
        usable = true;
    }
    if (usable) continue;
    ++bad;
    px[0] = px[1] = px[2] = 0.0f;
  }
  std::string kinds;
  auto kind = [&](std::size_t n, const char* what) {
    if (n == 0) return;
    kinds += (kinds.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  kind(nan, "NaN");
  kind(positive_inf, "+Inf (a half-float value beyond 65504 overflows to +Inf)");
  kind(negative_inf, "-Inf");
  kind(negative, "negative");
  const std::string of = std::to_string(bad) + " of " + std::to_string(texels) + " texels";
  if (bad == texels)
    throw FormatError(path, "pixel data", "texels with a finite radiance >= 0",
                      "none: all " + std::to_string(texels) +
                          " hold NaN, infinite or negative values (" + kinds + ")");
  EnvironmentMap map(image.width, image.height, std::move(image.rgb),
                     std::filesystem::path(path).filename().string());
  if (bad > 0)
    map.load_warning_ = path + ": warning: " + of +
                        " hold NaN, infinite or negative values and are taken as black (" + kinds +
                        ")";
  return map;
}

EnvironmentMap EnvironmentMap::FromName(const std::string& name_or_path) {
  if (name_or_path == "studio") return Studio();
  if (name_or_path == "sky") return Sky();
  if (name_or_path == "furnace") return Furnace();
  if (name_or_path == "axes") return AxisCoded();
  std::error_code ec;
  if (!std::filesystem::exists(name_or_path, ec))
    throw InvalidArgument("environment '" + name_or_path +
                          "': expected studio, sky, furnace, axes or an existing .exr/.hdr file");
  return Load(name_or_path);
}

}  // namespace brdf::preview
