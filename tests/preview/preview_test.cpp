// Physics of the environment-lit preview (brdf/preview/preview.h). Every expected value comes
// from outside the renderer: closed forms (furnace, linear-gradient irradiance, mirror
// geometry), NumPy quadrature of the docs/design.md §9 formulas (tests/python/preview_oracle.py),
// or another estimator whose error bars are known.
#include "brdf/preview/preview.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include "test_support.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/lut_brdf.h"
#include "brdf/core/rgl.h"
#include "brdf/exporter/exr.h"
#include "brdf/processing/measurement_brdf.h"
#include "brdf/processing/resample.h"
#include "brdf/sources/open.h"
#include "processing/synthetic_capture.h"

namespace brdf::preview {
namespace {

namespace fs = std::filesystem;
using test::MakeMaterial;

std::string DataDir() { return brdf::test::DataDir(); }

// Runs the NumPy oracle and returns its numbers.
std::vector<double> Oracle(const std::string& args) {
  const std::string cmd =
      std::string(BRDF_PYTHON3) + " " BRDF_SOURCE_DIR "/tests/python/preview_oracle.py " + args;
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  EXPECT_NE(pipe, nullptr) << cmd;
  if (pipe == nullptr) return {};
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  EXPECT_EQ(::pclose(pipe), 0) << cmd;
  std::istringstream in(out);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

// The sphere's normal at pixel (x, y) for the default camera (on +x, +y to the right, +z up,
// orthographic, the unit sphere spanning `fill` of the height), from preview.h's definition.
bool SphereNormal(int x, int y, int width, int height, double fill, Vec3* n) {
  const double aspect = static_cast<double>(width) / height;
  const double s = ((x + 0.5) / width * 2.0 - 1.0) * aspect / fill;
  const double t = (1.0 - (y + 0.5) / height * 2.0) / fill;
  const double r2 = s * s + t * t;
  if (r2 >= 1.0) return false;
  *n = {std::sqrt(1.0 - r2), s, t};
  return true;
}

PreviewOptions SmallOptions(int size, Estimator estimator = Estimator::kMis, int spp = 64) {
  PreviewOptions o;
  o.width = o.height = size;
  o.estimator = estimator;
  o.samples_per_pixel = spp;
  o.jobs = 2;
  return o;
}

double Lum(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

TEST(PreviewFurnace, WhiteLambertianRendersTheMapRadianceAtEveryLitPixel) {
  const AnalyticBrdf white(MakeMaterial(Model::kLambert, {1, 1, 1}, {}, {}));
  const EnvironmentMap furnace = EnvironmentMap::Furnace({1, 1, 1});
  // Map-only sampling converges too (PreviewEstimators) but needs far more samples for 1 % at
  // every single pixel; the default estimator and the quadrature are checked here.
  for (Estimator e : {Estimator::kMis, Estimator::kQuadrature}) {
    const PreviewImage image = RenderPreview(white, furnace, SmallOptions(40, e, 1024));
    int lit = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        if (!image.object[y * image.width + x]) continue;
        ++lit;
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(image.Pixel(x, y)[c], 1.0, 0.01)
              << "estimator " << static_cast<int>(e) << " pixel " << x << "," << y;
      }
    EXPECT_GT(lit, 900);
  }
}

TEST(PreviewFurnace, LambertianOfRhoGivesRhoTimesL) {
  const Rgb rho = {0.2, 0.5, 0.8}, radiance = {1.5, 1.0, 0.5};
  const AnalyticBrdf lambert(MakeMaterial(Model::kLambert, rho, {}, {}));
  const PreviewImage image = RenderPreview(lambert, EnvironmentMap::Furnace(radiance),
                                           SmallOptions(32, Estimator::kMis, 1024));
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.object[y * image.width + x]) {
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(image.Pixel(x, y)[c], rho[c] * radiance[c], 0.01 * rho[c] * radiance[c]);
      }
}

// Furnace value of each pixel against the NumPy directional albedo at its θ_o.
void ExpectFurnaceMatchesAlbedo(const Material& m, const std::string& model_name) {
  const int size = 48;
  const PreviewOptions o = SmallOptions(size, Estimator::kMis, 1024);
  const PreviewImage image = RenderPreview(AnalyticBrdf(m), EnvironmentMap::Furnace(), o);
  std::string thetas;
  for (int t = 0; t <= 86; ++t) thetas += " " + std::to_string(t);
  std::vector<std::vector<double>> albedo(3);
  for (int c = 0; c < 3; ++c) {
    albedo[c] = Oracle("albedo " + model_name + " " + std::to_string(m.Parameter(0)[c]) + " " +
                       std::to_string(m.Parameter(1)[c]) + " " + std::to_string(m.Parameter(2)[c]) +
                       thetas);
    ASSERT_EQ(albedo[c].size(), 87u);
  }
  double squares = 0, total = 0;
  int n = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      Vec3 normal;
      if (!SphereNormal(x, y, size, size, o.camera.fill, &normal)) continue;
      const double theta_o = RadToDeg(std::acos(normal.x));
      if (theta_o > 85.0) continue;  // the rim, where one pixel spans many degrees
      ASSERT_TRUE(image.object[y * size + x]);
      const int k = static_cast<int>(theta_o);
      const double t = theta_o - k;
      for (int c = 0; c < 3; ++c) {
        const double expected = albedo[c][k] * (1 - t) + albedo[c][k + 1] * t;
        const double got = image.Pixel(x, y)[c];
        EXPECT_NEAR(got, expected, 0.03 * expected) << model_name << " θo " << theta_o << " ch "
                                                    << c << " got " << got << " want " << expected;
        squares += (got - expected) * (got - expected);
        total += expected;
        ++n;
      }
    }
  EXPECT_LT(std::sqrt(squares / n) / (total / n), 0.01) << model_name;
}

TEST(PreviewFurnace, GgxEqualsItsDirectionalAlbedo) {
  ExpectFurnaceMatchesAlbedo(
      MakeMaterial(Model::kGgx, {0.1, 0.3, 0.0}, {0.9, 0.5, 0.04}, {0.3, 0.15, 0.5}), "ggx");
}

TEST(PreviewFurnace, LafortuneEqualsItsDirectionalAlbedo) {  // the tabulated sampler
  ExpectFurnaceMatchesAlbedo(
      MakeMaterial(Model::kLafortune, {0.1, 0.2, 0.3}, {0.6, 0.5, 0.4}, {20, 60, 8}), "lafortune");
}

TEST(PreviewFurnace, WardEqualsItsDirectionalAlbedo) {
  ExpectFurnaceMatchesAlbedo(
      MakeMaterial(Model::kWard, {0.3, 0.2, 0.1}, {0.1, 0.2, 0.05}, {0.2, 0.1, 0.3}), "ward");
}

// L(ω) = a + b·cosθ: a Lambertian of albedo ρ with normal n reflects
// ρ/π·(aπ + b·(2π/3)·n.z) = ρ·(a + 2b·n.z/3), since ∫_{H(n)} ω (ω·n) dω = (2π/3)·n.
TEST(PreviewIrradiance, LambertianUnderLinearGradientMatchesTheClosedForm) {
  const double a = 1.0, b = 0.8, rho = 0.7;
  const int width = 512, height = 256;
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  for (int j = 0; j < height; ++j) {
    // The row's mean of cosθ over its solid angle, so the pixelised map has the same integral
    // against any function linear in cosθ.
    const double c0 = std::cos(j * kPi / height), c1 = std::cos((j + 1) * kPi / height);
    const float value = static_cast<float>(a + b * 0.5 * (c0 + c1));
    for (int i = 0; i < width; ++i)
      for (int c = 0; c < 3; ++c) rgb[(static_cast<std::size_t>(j) * width + i) * 3 + c] = value;
  }
  const EnvironmentMap map(width, height, std::move(rgb), "gradient");
  const AnalyticBrdf lambert(MakeMaterial(Model::kLambert, {rho, rho, rho}, {}, {}));
  const int size = 40;
  PreviewOptions o = SmallOptions(size, Estimator::kMis, 512);
  o.camera.theta_deg = 60.0;  // from above, so the normals' z varies over [−0.5, 1]
  const PreviewImage image = RenderPreview(lambert, map, o);
  // The camera at (θ = 60°, φ = 0) sees along c = (sin60°, 0, cos60°), with image up
  // (−cos60°, 0, sin60°): a view-space normal (n.x towards the camera, n.z up) has world
  // z = n.x·cos60° + n.z·sin60°.
  const double c60 = 0.5, s60 = std::sqrt(0.75);
  int checked = 0;
  double squares = 0, total = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      Vec3 n;
      if (!SphereNormal(x, y, size, size, o.camera.fill, &n) || n.x < 0.1) continue;
      const double nz = n.x * c60 + n.z * s60;
      const double expected = rho * (a + 2.0 * b * nz / 3.0);
      EXPECT_NEAR(image.Pixel(x, y)[1], expected, 0.02 * expected) << x << "," << y;
      squares += (image.Pixel(x, y)[1] - expected) * (image.Pixel(x, y)[1] - expected);
      total += expected;
      ++checked;
    }
  EXPECT_GT(checked, 800);
  EXPECT_LT(std::sqrt(squares / checked) / (total / checked), 0.005);
}

// Mean object luminance and its standard error from the renderer's variance estimate.
struct Mean {
  double value, error;
};
Mean ObjectMean(const PreviewImage& image) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < image.object.size(); ++p)
    if (image.object[p]) {
      sum += Lum(&image.rgb[3 * p]);
      ++n;
    }
  const double mean = sum / n;
  return {mean, image.relative_rms_estimate * mean / std::sqrt(static_cast<double>(n))};
}

void ExpectEstimatorsAgree(const BrdfSource& source, const EnvironmentMap& map, int spp) {
  const int size = 32;
  PreviewOptions o = SmallOptions(size, Estimator::kQuadrature);
  o.quadrature_subdivisions = 2;
  const PreviewImage reference = RenderPreview(source, map, o);
  std::map<int, Mean> means;
  for (Estimator e : {Estimator::kMis, Estimator::kEnvironment, Estimator::kBrdf}) {
    o.estimator = e;
    o.samples_per_pixel = spp;
    const PreviewImage image = RenderPreview(source, map, o);
    const Mean m = ObjectMean(image);
    means[static_cast<int>(e)] = m;
    ASSERT_GT(m.error, 0.0);
    // Pixel by pixel: the RMS difference to the quadrature is the estimator's own noise.
    const ImageDifference d = CompareImages(image, reference);
    EXPECT_LT(d.relative_rms, 2.0 * image.relative_rms_estimate + 0.01)
        << source.Name() << " estimator " << static_cast<int>(e);
  }
  const Mean q = ObjectMean(reference);
  for (const auto& [e, m] : means) {
    EXPECT_NEAR(m.value, q.value, 4.0 * m.error + 0.003 * q.value)
        << source.Name() << " estimator " << e << " vs quadrature";
    for (const auto& [e2, m2] : means)
      EXPECT_NEAR(m.value, m2.value, 4.0 * std::hypot(m.error, m2.error))
          << source.Name() << " estimators " << e << " and " << e2;
  }
  // MIS is never much worse than the better single strategy.
  const double mis = means[static_cast<int>(Estimator::kMis)].error;
  const double best = std::min(means[static_cast<int>(Estimator::kEnvironment)].error,
                               means[static_cast<int>(Estimator::kBrdf)].error);
  EXPECT_LT(mis, 1.5 * best) << source.Name();
}

TEST(PreviewEstimators, EnvironmentBrdfAndMisAgreeWithinErrorBars) {
  const EnvironmentMap studio = EnvironmentMap::Studio(128, 64);
  ExpectEstimatorsAgree(AnalyticBrdf(MakeMaterial(Model::kGgx, {0.2, 0.1, 0.05}, {0.8, 0.8, 0.8},
                                                  {0.25, 0.25, 0.25})),
                        studio, 64);
  ExpectEstimatorsAgree(AnalyticBrdf(test::LafortuneN20()), studio, 64);
}

// The renderer's error bars against the scatter they describe: two renders that differ only in
// the seed (each pixel's random shift of its Kronecker sequence) are independent estimates, so
// √(mean over the object of (L₁ − L₂)² / 2) / mean L is the relative RMS error the images
// actually have. The renderer's own estimate (PreviewImage::relative_rms_estimate) is the
// spread of its passes as if they were independent; successive points of a Kronecker sequence
// are not (they stratify), so the estimate is conservative: 1.4–1.7 × the scatter here. It
// must never understate the error (≥ 0.9 × the scatter, which ~800 pixels know to about 5 %)
// and stay an error bar of the right size (≤ 2.5 ×).
TEST(PreviewEstimators, ErrorBarsMatchTheScatterOfTwoSeeds) {
  const EnvironmentMap studio = EnvironmentMap::Studio(128, 64);
  const AnalyticBrdf ggx(
      MakeMaterial(Model::kGgx, {0.2, 0.1, 0.05}, {0.8, 0.8, 0.8}, {0.25, 0.25, 0.25}));
  for (Estimator e : {Estimator::kMis, Estimator::kBrdf}) {
    SCOPED_TRACE(static_cast<int>(e));
    PreviewOptions o = SmallOptions(32, e, 32);
    o.seed = 1;
    const PreviewImage a = RenderPreview(ggx, studio, o);
    o.seed = 2;
    const PreviewImage b = RenderPreview(ggx, studio, o);
    double squares = 0, sum = 0;
    std::size_t n = 0;
    for (std::size_t p = 0; p < a.object.size(); ++p)
      if (a.object[p] && b.object[p]) {
        const double la = Lum(&a.rgb[3 * p]), lb = Lum(&b.rgb[3 * p]);
        squares += (la - lb) * (la - lb);
        sum += 0.5 * (la + lb);
        ++n;
      }
    ASSERT_GT(n, 500u);
    const double scatter = std::sqrt(squares / (2.0 * n)) / (sum / n);
    const double estimate = 0.5 * (a.relative_rms_estimate + b.relative_rms_estimate);
    ASSERT_GT(scatter, 0);
    EXPECT_GT(estimate / scatter, 0.9) << "estimate " << estimate << ", scatter " << scatter;
    EXPECT_LT(estimate / scatter, 2.5) << "estimate " << estimate << ", scatter " << scatter;
    RecordProperty("estimate_over_scatter_" + std::to_string(static_cast<int>(e)),
                   std::to_string(estimate / scatter));
  }
}

TEST(PreviewEstimators, RglFileAgreesWithItsOwnDirectQuadrature) {
  const std::string path = DataDir() + "/rgl/cc_ibiza_sunset_rgb.bsdf";
  ASSERT_TRUE(fs::exists(path)) << "set BRDF_DATA_DIR to the shared brdf-data folder (" << path
                                << " is missing)";
  const RglBrdf rgl = RglBrdf::Load(path);
  ExpectEstimatorsAgree(rgl, EnvironmentMap::Studio(96, 48), 48);
}

// A sharp GGX lit by one small bright patch: the highlight sits where the normal is the half
// vector of the patch and the camera (+x). Returns the angle between them, degrees.
double HighlightErrorDeg(Estimator estimator, double patch_theta, double patch_phi) {
  const int width = 720, height = 360;
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3, 0.0f);
  const Vec3 patch = SphericalDirectionDeg(patch_theta, patch_phi);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const Vec3 w = SphericalDirection((j + 0.5) * kPi / height, (i + 0.5) * 2 * kPi / width);
      if (Dot(w, patch) > std::cos(DegToRad(1.0)))
        for (int c = 0; c < 3; ++c) rgb[(static_cast<std::size_t>(j) * width + i) * 3 + c] = 100;
    }
  const EnvironmentMap map(width, height, std::move(rgb), "patch");
  const AnalyticBrdf ggx(MakeMaterial(Model::kGgx, {0, 0, 0}, {1, 1, 1}, {0.03, 0.03, 0.03}));
  const int size = 200;
  PreviewOptions o = SmallOptions(size, estimator, 16);
  o.show_background = false;
  const PreviewImage image = RenderPreview(ggx, map, o);
  int best_x = 0, best_y = 0;
  double best = -1;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (Lum(image.Pixel(x, y)) > best) {
        best = Lum(image.Pixel(x, y));
        best_x = x;
        best_y = y;
      }
  Vec3 n;
  EXPECT_TRUE(SphereNormal(best_x, best_y, size, size, o.camera.fill, &n));
  const Vec3 half = Normalize(patch + Vec3{1, 0, 0});
  return RadToDeg(std::acos(std::min(1.0, Dot(n, half))));
}

TEST(PreviewHighlight, SharpGgxHighlightSitsWhereMirrorReflectionPredicts) {
  for (const auto& [patch_theta, patch_phi] :
       std::vector<std::pair<double, double>>{{60, 20}, {90, 300}, {35, 0}})
    EXPECT_LT(HighlightErrorDeg(Estimator::kMis, patch_theta, patch_phi), 1.5)
        << "patch at " << patch_theta << "," << patch_phi;
}

// A white Lambertian under the axis-coded map: each normal's colour against NumPy's integral of
// the continuous map, and the background straight behind the sphere is −x (cyan).
// `spp` MIS passes, each probe within `tolerance` (relative) + 0.003 of the oracle.
void ExpectAxisCodedOrientation(const EnvironmentMap& axes, int spp = 1024,
                                double tolerance = 0.02) {
  SCOPED_TRACE(axes.name());
  const AnalyticBrdf white(MakeMaterial(Model::kLambert, {1, 1, 1}, {}, {}));
  const int size = 61;
  PreviewOptions o = SmallOptions(size, Estimator::kMis, spp);
  o.camera.fill = 0.5;
  const PreviewImage image = RenderPreview(white, axes, o);
  struct Probe {
    int x, y;
    const char* what;
  };
  const int c = size / 2, r = static_cast<int>(0.45 * size * o.camera.fill);
  for (const Probe& p :
       {Probe{c, c, "centre (+x)"}, Probe{c + r, c, "right (+y)"}, Probe{c - r, c, "left (−y)"},
        Probe{c, c - r, "top (+z)"}, Probe{c, c + r, "bottom (−z)"}}) {
    Vec3 n;
    ASSERT_TRUE(SphereNormal(p.x, p.y, size, size, o.camera.fill, &n));
    const std::vector<double> expected = Oracle("axes " + std::to_string(n.x) + " " +
                                                std::to_string(n.y) + " " + std::to_string(n.z));
    ASSERT_EQ(expected.size(), 3u);
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(image.Pixel(p.x, p.y)[ch], expected[ch], tolerance * expected[ch] + 0.003)
          << p.what << " channel " << ch << " got " << image.Pixel(p.x, p.y)[ch] << " want "
          << expected[ch];
  }
  // Background: straight behind the sphere is −x: G = B = 0.5, R = 0 (cyan) at the image
  // centre row near the left and right edges (−x rotated slightly towards ∓y).
  const float* behind = image.Pixel(2, c);
  EXPECT_LT(behind[0], 0.1);
  EXPECT_GT(behind[1], 0.4);
  EXPECT_GT(behind[2], 0.4);
}

TEST(PreviewOrientation, AxisCodedMapAppearsWhereTheDocumentedFrameSaysItIs) {
  ExpectAxisCodedOrientation(EnvironmentMap::AxisCoded(512, 256));
}

// Maps read from files keep the documented orientation: the axis-coded map written by NumPy as
// an OpenEXR file (OpenImageIO) and as a run-length encoded Radiance .hdr (bytes written by the
// oracle), read by EnvironmentMap::Load. Every pixel centre's direction reads the colour the
// formula gives there (the .hdr's 8-bit mantissas: within 1/128 of the largest channel), and
// the sphere under the EXR shows the axes where the in-memory map does. A map mirrored in
// either direction swaps +y/−y or +z/−z: green for magenta, blue for yellow.
TEST(PreviewOrientation, MapsReadFromExrAndHdrFilesKeepTheDocumentedOrientation) {
  const brdf::test::ScopedTempDir tmp("preview-axes");
  const int w = 256, h = 128;
  const std::string cmd = std::string(BRDF_PYTHON3) +
                          " " BRDF_SOURCE_DIR "/tests/python/preview_oracle.py write-axes '" +
                          tmp.path().string() + "' " + std::to_string(w) + " " + std::to_string(h);
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (const char* name : {"axes.exr", "axes.hdr"}) {
    SCOPED_TRACE(name);
    const EnvironmentMap map = EnvironmentMap::Load((tmp / name).string());
    ASSERT_EQ(map.width(), w);
    ASSERT_EQ(map.height(), h);
    for (int j = 0; j < h; j += 3)
      for (int i = 0; i < w; i += 5) {
        const double theta = (j + 0.5) / h * kPi, phi = (i + 0.5) / w * 2 * kPi;
        const Vec3 d{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                     std::cos(theta)};
        const double px = std::max(0.0, d.x), py = std::max(0.0, d.y), pz = std::max(0.0, d.z);
        const double nx = std::max(0.0, -d.x), ny = std::max(0.0, -d.y), nz = std::max(0.0, -d.z);
        const double want[3] = {px + 0.5 * (ny + nz), py + 0.5 * (nx + nz), pz + 0.5 * (nx + ny)};
        const double top = std::max({want[0], want[1], want[2]});
        const Rgb got = map.Radiance(d);
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(got[c], want[c], top / 128 + 1e-6)
              << "pixel (" << i << ", " << j << ") channel " << c;
      }
    // A quarter of the in-memory test's passes: a mirror moves a probe's colour by far more.
    if (std::string(name) == "axes.exr") ExpectAxisCodedOrientation(map, 256, 0.05);
  }
}

// ---- χ² tests of every sampler's pdf against its sampling routine.

// Bins uniform in (θ, φ) over the sphere; the expected count of a bin is the pdf integrated
// over it with a fine midpoint rule in (θ, φ), dω = sinθ dθ dφ (exact for a 1/sinθ factor).
struct ChiSquare {
  int theta_bins = 30, phi_bins = 60;
  double statistic = 0;
  int dof = 0;
  double total_expected_fraction = 0;
};

template <class SampleFn, class PdfFn>
ChiSquare RunChiSquare(SampleFn sample, PdfFn pdf, int samples, std::uint64_t seed,
                       int theta_bins = 30, int phi_bins = 60) {
  ChiSquare result;
  result.theta_bins = theta_bins;
  result.phi_bins = phi_bins;
  const int tb = result.theta_bins, pb = result.phi_bins;
  std::vector<double> observed(tb * pb, 0.0), expected(tb * pb, 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto bin_of = [&](const Vec3& w) {
    const int t = std::min(tb - 1, static_cast<int>(ThetaOf(w) / kPi * tb));
    const int p = std::min(pb - 1, static_cast<int>(PhiOf(w) / (2 * kPi) * pb));
    return t * pb + p;
  };
  for (int s = 0; s < samples; ++s) {
    Vec3 w;
    if (sample(u01(rng), u01(rng), u01(rng), &w)) observed[bin_of(w)] += 1;
  }
  const int sub = 24;
  for (int t = 0; t < tb; ++t)
    for (int p = 0; p < pb; ++p) {
      double integral = 0;
      for (int a = 0; a < sub; ++a) {
        const double theta = kPi * (t + (a + 0.5) / sub) / tb;
        for (int b = 0; b < sub; ++b) {
          const double phi = 2 * kPi * (p + (b + 0.5) / sub) / pb;
          integral += pdf(SphericalDirection(theta, phi)) * std::sin(theta);
        }
      }
      integral *= (kPi / tb) * (2 * kPi / pb) / (sub * sub);
      expected[t * pb + p] = integral * samples;
      result.total_expected_fraction += integral;
    }
  // Pool bins with fewer than 5 expected samples into one.
  double pooled_obs = 0, pooled_exp = 0;
  for (int k = 0; k < tb * pb; ++k) {
    if (expected[k] < 5.0) {
      pooled_obs += observed[k];
      pooled_exp += expected[k];
      continue;
    }
    result.statistic += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++result.dof;
  }
  if (pooled_exp >= 5.0) {
    result.statistic += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++result.dof;
  } else {
    EXPECT_LT(pooled_obs, 5 + 5 * pooled_exp) << "samples where the pdf says there are none";
  }
  return result;
}

// The χ² quantile at significance 1e-4 (Wilson–Hilferty; z = 3.719).
double ChiSquareThreshold(int dof) {
  const double k = dof, z = 3.719;
  const double t = 1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k));
  return k * t * t * t;
}

TEST(PreviewSamplers, EnvironmentSamplerPdfMatchesItsSamples) {
  for (const EnvironmentMap& map :
       {EnvironmentMap::Studio(64, 32), EnvironmentMap::Sky(30, 100, 64, 32),
        EnvironmentMap::AxisCoded(32, 16)}) {
    const EnvironmentSampler sampler(map);
    const ChiSquare chi = RunChiSquare(
        [&](double u1, double u2, double, Vec3* w) {
          double pdf = 0;
          return sampler.Sample(u1, u2, w, &pdf);
        },
        [&](const Vec3& w) { return sampler.Pdf(w); }, 400000, 7, map.height(), map.width());
    EXPECT_NEAR(chi.total_expected_fraction, 1.0, 2e-3) << map.name();
    EXPECT_LT(chi.statistic, ChiSquareThreshold(chi.dof)) << map.name() << " dof " << chi.dof;
  }
}

void ExpectBrdfSamplerConsistent(const BrdfSource& source, const std::string& kind) {
  const auto sampler = MakeBrdfSampler(source, 2);
  EXPECT_EQ(sampler->Kind(), kind);
  for (double theta_o : {0.0, 30.0, 65.0, 85.0}) {
    const Vec3 wo = SphericalDirectionDeg(theta_o, 40.0);
    const ChiSquare chi = RunChiSquare(
        [&](double u1, double u2, double u3, Vec3* w) {
          double pdf = 0;
          const bool ok = sampler->Sample(wo, u1, u2, u3, w, &pdf);
          if (ok) {
            EXPECT_NEAR(pdf, sampler->Pdf(wo, *w), 1e-9 * pdf);
          }
          return ok;
        },
        [&](const Vec3& w) { return sampler->Pdf(wo, w); }, 400000, 11);
    EXPECT_LE(chi.total_expected_fraction, 1.0 + 2e-3);
    EXPECT_LT(chi.statistic, ChiSquareThreshold(chi.dof))
        << source.Name() << " θo " << theta_o << " dof " << chi.dof;
  }
}

TEST(PreviewSamplers, GgxVisibleNormalSamplerPdfMatchesItsSamples) {
  ExpectBrdfSamplerConsistent(
      AnalyticBrdf(MakeMaterial(Model::kGgx, {0.3, 0.3, 0.3}, {0.5, 0.5, 0.5}, {0.4, 0.4, 0.4})),
      "ggx-vndf");
  ExpectBrdfSamplerConsistent(
      AnalyticBrdf(MakeMaterial(Model::kGgx, {0.0, 0.0, 0.0}, {0.9, 0.9, 0.9}, {0.15, 0.2, 0.1})),
      "ggx-vndf");
}

TEST(PreviewSamplers, TabulatedSamplerPdfMatchesItsSamples) {
  ExpectBrdfSamplerConsistent(AnalyticBrdf(test::LafortuneN20()), "tabulated");
  const std::string path = DataDir() + "/rgl/paper_white_rgb.bsdf";
  ASSERT_TRUE(fs::exists(path)) << "set BRDF_DATA_DIR to the shared brdf-data folder (" << path
                                << " is missing)";
  ExpectBrdfSamplerConsistent(RglBrdf::Load(path), "tabulated");
}

// ---- Measured sources against what they were captured from.

// A noise-free capture of any source on a (θin, θout ≤ 75°, φout) grid at 1° (the reference
// instrument's geometry for θin = 0, 20, 40, 60°).
Measurement CaptureOf(const BrdfSource& source, const std::vector<double>& theta_in,
                      int theta_out_max_deg = 75) {
  Measurement meas;
  meas.metadata.sample_name = source.Name();
  for (double ti : theta_in) {
    Slice slice;
    slice.theta_in_deg = ti;
    const Vec3 wi = SphericalDirectionDeg(ti, 0.0);
    for (int a = 0; a <= theta_out_max_deg; ++a)
      for (int b = 0; b < 360; ++b)
        slice.samples.push_back(
            test::MakeSample(ti, a, b, source.Eval(wi, SphericalDirectionDeg(a, b))));
    meas.slices.push_back(std::move(slice));
  }
  return meas;
}

// The light's polar angle beyond the measured θin range answered from the nearest slice only
// (Lut::SampleTexture, no reciprocity step): what the capture's evaluation would be without
// docs/design.md §5's reciprocity rule, for comparison.
class NearestSliceOnly final : public BrdfSource {
 public:
  explicit NearestSliceOnly(Lut lut) : lut_(std::move(lut)) {}
  std::string Name() const override { return "nearest-slice"; }
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    if (!(wi.z > 0.0) || !(wo.z > 0.0)) return {0.0, 0.0, 0.0};
    const double phi = std::hypot(wi.x, wi.y) > 0 ? RadToDeg(PhiOf(wo) - PhiOf(wi)) : 0.0;
    const auto f = lut_.SampleTexture(RadToDeg(ThetaOf(wi)), RadToDeg(ThetaOf(wo)), phi);
    return {f[0], f[1], f[2]};
  }

 private:
  Lut lut_;
};

// Both previews by the deterministic quadrature, so the difference is the evaluation's alone.
// Only pixels whose view direction is within `max_view_deg` of the normal count.
ImageDifference PreviewDifference(const BrdfSource& candidate, const BrdfSource& truth,
                                  double max_view_deg) {
  PreviewOptions o = SmallOptions(40, Estimator::kQuadrature);
  o.quadrature_subdivisions = 1;
  const EnvironmentMap studio = EnvironmentMap::Studio(96, 48);
  PreviewImage a = RenderPreview(candidate, studio, o), b = RenderPreview(truth, studio, o);
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      Vec3 n;
      if (!SphereNormal(x, y, o.width, o.height, o.camera.fill, &n) ||
          RadToDeg(std::acos(n.x)) > max_view_deg)
        a.object[y * o.width + x] = b.object[y * o.width + x] = 0;
    }
  return CompareImages(a, b);
}

// How many pixels of a size × size image show the sphere (default camera and fill).
std::size_t SpherePixels(int size) {
  std::size_t n = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (Vec3 normal; SphereNormal(x, y, size, size, Camera{}.fill, &normal)) ++n;
  return n;
}

// The capture evaluated the way `brdf preview CAPTURE.bpc` evaluates it: through its LUT
// (processing::MeasurementAsBrdf, as sources::OpenBrdf does).
ImageDifference CaptureDifference(const BrdfSource& truth, const std::vector<double>& theta_in,
                                  int theta_out_max_deg = 75, double max_view_deg = 90.0) {
  const LutBrdf captured =
      processing::MeasurementAsBrdf(CaptureOf(truth, theta_in, theta_out_max_deg));
  return PreviewDifference(captured, truth, max_view_deg);
}

const std::vector<double> kReferenceThetaIn = {0, 20, 40, 60};

// The reference instrument's capture: θin 0/20/40/60°, θout ≤ 75°.
//
// Which pixels count: those whose view direction lies within the measured θin range, at most
// 60° from the normal (75 % of the sphere's disc). For such a pixel every pair of directions
// has a measured value in one of its two orders: a light within 60° reads the measured slices
// (interpolated in the specular frame, docs/design.md §5); a light beyond 60° is answered by
// reciprocity from the slice at the view's angle, with the light's direction as the view,
// measured up to θout = 75° (§6 beyond). At the rim, where the view is beyond 60° too, the
// sphere under a map sees pairs with both directions beyond 60° that this instrument never
// measures; their value is the 60° slice's, which misses the grazing rise of this GGX's
// Fresnel and geometry terms. There the capture differs from the material by 5.8 % RMS (view
// ≤ 75°) and 11.8 % (every pixel): docs/preview.md ("Captures"), bench/capture_fidelity.cpp.
TEST(PreviewCapture, CaptureOfAnAnalyticMaterialPreviewsWithin2PercentOfIt) {
  const AnalyticBrdf material(
      MakeMaterial(Model::kGgx, {0.35, 0.2, 0.1}, {0.04, 0.04, 0.04}, {0.35, 0.35, 0.35}));
  const Lut lut = processing::BuildLut(CaptureOf(material, kReferenceThetaIn, 75));
  const ImageDifference measured = PreviewDifference(LutBrdf(lut, "capture"), material, 60.0);
  EXPECT_LT(measured.relative_rms, 0.02) << "pixels seen within the measured θin range (60°)";
  EXPECT_GT(measured.pixels, 650u);
  // Reciprocity is what brings the light beyond 60° in: without it, the held 60° slice.
  EXPECT_LT(measured.relative_rms,
            0.75 * PreviewDifference(NearestSliceOnly(lut), material, 60.0).relative_rms);
}

// The whole sphere. A sphere under a map is lit and seen at every angle up to grazing, so a
// capture covers every lit pixel only when it measured every incidence and every detector angle
// the sphere shows: θin every 5° (0–85°; the simulator and `brdf capture --device sim` take any
// list) and θout to 89°. Then every lit pixel of the sphere (the count is the sphere's own,
// from its geometry) is within 2 % (0.53 % for this GGX); with θout to the instrument's 75°
// the pixels seen within 75° are (docs/preview.md, "Captures").
std::vector<double> DenseThetaIn() {
  std::vector<double> t;
  for (int k = 0; k <= 17; ++k) t.push_back(5.0 * k);
  return t;
}

TEST(PreviewCapture, DenseCaptureOfAnAnalyticMaterialPreviewsWithin2PercentOfIt) {
  const AnalyticBrdf material(
      MakeMaterial(Model::kGgx, {0.35, 0.2, 0.1}, {0.04, 0.04, 0.04}, {0.35, 0.35, 0.35}));
  const ImageDifference dense = CaptureDifference(material, DenseThetaIn(), 75, 75.0);
  EXPECT_LT(dense.relative_rms, 0.02) << "pixels seen within the measured 75°";
  EXPECT_GT(dense.pixels, 800u);
  const ImageDifference every = CaptureDifference(material, DenseThetaIn(), 89);
  EXPECT_LT(every.relative_rms, 0.02) << "every lit pixel, capture measured to 89°";
  EXPECT_EQ(every.pixels, SpherePixels(40)) << "every lit pixel of the 40 × 40 sphere";
}

// An RGL file's virtual capture against the file's own direct evaluation (RglBrdf, what
// `brdf preview FILE.bsdf` renders): the reference geometry over the pixels seen within the
// measured 60° (0.57 %), and the dense geometry over the pixels seen within 75° and over every
// lit pixel of the sphere (1.09 %).
TEST(PreviewCapture, VirtualCaptureOfAnRglFilePreviewsWithin2PercentOfItsDirectEvaluation) {
  const std::string path = DataDir() + "/rgl/paper_white_rgb.bsdf";
  ASSERT_TRUE(fs::exists(path)) << "set BRDF_DATA_DIR to the shared brdf-data folder (" << path
                                << " is missing)";
  const RglBrdf rgl = RglBrdf::Load(path);
  EXPECT_LT(CaptureDifference(rgl, kReferenceThetaIn, 75, 60.0).relative_rms, 0.02);
  EXPECT_LT(CaptureDifference(rgl, DenseThetaIn(), 75, 75.0).relative_rms, 0.02);
  const ImageDifference every = CaptureDifference(rgl, DenseThetaIn(), 89);
  EXPECT_LT(every.relative_rms, 0.02) << "every lit pixel, capture measured to 89°";
  EXPECT_EQ(every.pixels, SpherePixels(40)) << "every lit pixel of the 40 × 40 sphere";
}

// ---- The fast path (Estimator::kHierarchical) against the brute-force quadrature.

// The hierarchical render of a whole image against kQuadrature (every map pixel, midpoint rule)
// at ~400 pixels spread over it: RMS over those pixels relative to their mean, the benchmark's
// error definition (docs/benchmarks.md). The brute-force sum is independent of the hierarchy,
// the interpolation and their tolerances, and is itself checked by the furnace and closed-form
// tests above.
double HierarchicalError(const BrdfSource& source, const EnvironmentMap& map, int size,
                         std::uint64_t* computed = nullptr, const Camera& camera = Camera()) {
  PreviewOptions o = SmallOptions(size, Estimator::kHierarchical);
  o.camera = camera;
  o.show_background = false;
  const PreviewImage fast = RenderPreview(source, map, o);
  EXPECT_EQ(fast.estimator, Estimator::kHierarchical);
  if (computed != nullptr) *computed = fast.computed_pixels;
  o.estimator = Estimator::kQuadrature;
  o.quadrature_subdivisions = 1;
  std::mt19937_64 rng(7);
  for (int k = 0; k < 400; ++k)
    o.pixel_subset.push_back(static_cast<std::uint32_t>(rng() % (size * size)));
  const PreviewImage reference = RenderPreview(source, map, o);
  double squares = 0, total = 0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < reference.object.size(); ++p) {
    if (!reference.object[p]) continue;
    EXPECT_TRUE(fast.object[p]);
    for (int c = 0; c < 3; ++c) {
      const double d = fast.rgb[3 * p + c] - reference.rgb[3 * p + c];
      squares += d * d;
      total += reference.rgb[3 * p + c];
    }
    n += 3;
  }
  EXPECT_GT(n, 3u * 150);
  const double error = std::sqrt(squares / n) / (total / n);
  std::printf(
      "%s under %s, %d²: %.3f %% RMS from the brute force at %zu pixels; %llu pixels "
      "integrated, the rest interpolated\n",
      source.Name().c_str(), map.name().c_str(), size, 100.0 * error, n / 3,
      static_cast<unsigned long long>(fast.computed_pixels));
  return error;
}

// The documented accuracy (preview.h, docs/preview.md): within 0.5 % RMS of the brute force.
constexpr double kHierarchicalBound = 0.005;

TEST(PreviewHierarchical, AnalyticGgxMatchesTheBruteForceQuadrature) {
  const EnvironmentMap studio = EnvironmentMap::Studio(512, 256);
  // plastic_matte_red (α 0.5) and a sharper metal (α 0.15, gold-like).
  const AnalyticBrdf matte(
      MakeMaterial(Model::kGgx, {0.55, 0.06, 0.05}, {0.04, 0.04, 0.04}, {0.5, 0.5, 0.5}));
  EXPECT_LT(HierarchicalError(matte, studio, 96), kHierarchicalBound);
  const AnalyticBrdf metal(
      MakeMaterial(Model::kGgx, {0, 0, 0}, {1.0, 0.78, 0.34}, {0.15, 0.15, 0.15}));
  std::uint64_t computed = 0;
  EXPECT_LT(HierarchicalError(metal, studio, 96, &computed), kHierarchicalBound);
  EXPECT_GT(computed, 0u);
  // The sky's sun (0.53°, far brighter than the rest) under the sharper lobe.
  EXPECT_LT(HierarchicalError(metal, EnvironmentMap::Sky(40, 30, 512, 256), 64),
            kHierarchicalBound);
}

TEST(PreviewHierarchical, PerspectiveViewOfTheSphereMatchesTheBruteForceQuadrature) {
  // The view direction then changes from pixel to pixel; the sphere seen from above.
  Camera camera;
  camera.projection = Camera::Projection::kPerspective;
  camera.fov_deg = 40.0;
  camera.theta_deg = 50.0;
  camera.phi_deg = 120.0;
  EXPECT_LT(HierarchicalError(AnalyticBrdf(test::GgxAlpha03()), EnvironmentMap::Studio(512, 256),
                              64, nullptr, camera),
            kHierarchicalBound);
}

TEST(PreviewHierarchical, LutMatchesTheBruteForceQuadrature) {
  // A LUT resampled from a capture of wood_oak's Lafortune lobe (θin 0–80° every 10°), evaluated
  // as `brdf preview` evaluates captures and tables.
  const AnalyticBrdf oak(
      MakeMaterial(Model::kLafortune, {0.45, 0.3, 0.17}, {0.05, 0.05, 0.05}, {8, 8, 8}));
  std::vector<double> theta_in;
  for (int k = 0; k <= 8; ++k) theta_in.push_back(10.0 * k);
  const brdf::LutBrdf lut(processing::BuildLut(CaptureOf(oak, theta_in, 89)), "oak lut");
  EXPECT_LT(HierarchicalError(lut, EnvironmentMap::Studio(512, 256), 96), kHierarchicalBound);
}

TEST(PreviewHierarchical, RglFileMatchesTheBruteForceQuadrature) {
  const std::string path = DataDir() + "/rgl/cc_ibiza_sunset_rgb.bsdf";
  ASSERT_TRUE(fs::exists(path)) << "set BRDF_DATA_DIR to the shared brdf-data folder (" << path
                                << " is missing)";
  const RglBrdf rgl = RglBrdf::Load(path);
  EXPECT_LT(HierarchicalError(rgl, EnvironmentMap::Studio(512, 256), 96), kHierarchicalBound);
}

TEST(PreviewHierarchical, FurnaceAndLambertClosedFormsHold) {
  // A white Lambertian under the furnace is 1 everywhere (no interpolation error can hide in a
  // constant), and the linear-gradient closed form of PreviewIrradiance holds pixel by pixel.
  const AnalyticBrdf white(MakeMaterial(Model::kLambert, {1, 1, 1}, {}, {}));
  const PreviewImage furnace = RenderPreview(white, EnvironmentMap::Furnace({1, 1, 1}, 256, 128),
                                             SmallOptions(64, Estimator::kHierarchical));
  for (std::size_t p = 0; p < furnace.object.size(); ++p) {
    if (!furnace.object[p]) continue;
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(furnace.rgb[3 * p + c], 1.0, 2e-3) << p;
  }
  const double a = 1.0, b = 0.8, rho = 0.7;
  const int width = 512, height = 256;
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  for (int j = 0; j < height; ++j) {
    const double c0 = std::cos(j * kPi / height), c1 = std::cos((j + 1) * kPi / height);
    for (int i = 0; i < width; ++i)
      for (int c = 0; c < 3; ++c)
        rgb[(static_cast<std::size_t>(j) * width + i) * 3 + c] =
            static_cast<float>(a + b * 0.5 * (c0 + c1));
  }
  const EnvironmentMap gradient(width, height, std::move(rgb), "gradient");
  const AnalyticBrdf lambert(MakeMaterial(Model::kLambert, {rho, rho, rho}, {}, {}));
  const int size = 64;
  PreviewOptions o = SmallOptions(size, Estimator::kHierarchical);
  const PreviewImage image = RenderPreview(lambert, gradient, o);
  int checked = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      Vec3 n;
      if (!SphereNormal(x, y, size, size, o.camera.fill, &n)) continue;
      const double expected = rho * (a + 2.0 * b * n.z / 3.0);  // default camera: world z = n.z
      EXPECT_NEAR(image.Pixel(x, y)[1], expected, 3e-3 * expected) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 2000);
}

TEST(PreviewHierarchical, HighlightSitsWhereMirrorReflectionPredicts) {
  for (const auto& [patch_theta, patch_phi] :
       std::vector<std::pair<double, double>>{{60, 20}, {90, 300}, {35, 0}})
    EXPECT_LT(HighlightErrorDeg(Estimator::kHierarchical, patch_theta, patch_phi), 1.5)
        << "patch at " << patch_theta << "," << patch_phi;
}

TEST(PreviewHierarchical, AutoPicksTheFastPathForTheSphereOnly) {
  const AnalyticBrdf material(test::GgxAlpha03());
  const EnvironmentMap studio = EnvironmentMap::Studio(64, 32);
  PreviewOptions o = SmallOptions(16, Estimator::kAuto, 2);
  EXPECT_EQ(RenderPreview(material, studio, o).estimator, Estimator::kHierarchical);
  o.shape = Shape::kPlane;
  EXPECT_EQ(RenderPreview(material, studio, o).estimator, Estimator::kMis);
  o.estimator = Estimator::kHierarchical;  // allowed on the plane when asked for
  EXPECT_EQ(RenderPreview(material, studio, o).estimator, Estimator::kHierarchical);
  const Mesh mesh = {
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}, {{0, 1, 2}}};
  o.shape = Shape::kMesh;
  o.mesh = &mesh;
  EXPECT_THROW(RenderPreview(material, studio, o), InvalidArgument);
  o.estimator = Estimator::kAuto;
  EXPECT_EQ(RenderPreview(material, studio, o).estimator, Estimator::kMis);
}

// ---- Meshes, cameras, lights.

class PreviewFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/brdf_preview_test_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  fs::path dir_;
};

// A UV sphere of radius 2 centred at (1, 1, 1) with exact vertex normals, as OBJ text.
std::string UvSphereObj(int rings, int segments) {
  std::ostringstream obj;
  obj.precision(17);
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const Vec3 n = SphericalDirection(kPi * r / rings, 2 * kPi * s / segments);
      obj << "v " << 1 + 2 * n.x << " " << 1 + 2 * n.y << " " << 1 + 2 * n.z << "\n";
      obj << "vn " << n.x << " " << n.y << " " << n.z << "\n";
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s + 1, b = r * segments + (s + 1) % segments + 1;
      const int c = a + segments, d = b + segments;
      obj << "f " << a << "//" << a << " " << c << "//" << c << " " << d << "//" << d << "\n";
      obj << "f " << a << "//" << a << " " << d << "//" << d << " " << b << "//" << b << "\n";
    }
  return obj.str();
}

TEST_F(PreviewFiles, TessellatedSphereMeshRendersLikeTheAnalyticSphere) {
  const Mesh mesh = LoadMesh(Write("sphere.obj", UvSphereObj(90, 180)));
  EXPECT_EQ(mesh.triangles.size(), 2u * 90 * 180);
  const AnalyticBrdf material(
      MakeMaterial(Model::kGgx, {0.3, 0.3, 0.3}, {0.5, 0.5, 0.5}, {0.3, 0.3, 0.3}));
  const EnvironmentMap studio = EnvironmentMap::Studio(128, 64);
  PreviewOptions o = SmallOptions(48, Estimator::kMis, 256);
  // The mesh is scaled so its bounding box's half diagonal (√3 radii) is 1: the sphere inside
  // has radius 1/√3, so the analytic sphere is framed √3 times smaller to match.
  o.camera.fill = 0.9 / std::sqrt(3.0);
  const PreviewImage sphere = RenderPreview(material, studio, o);
  o.camera.fill = 0.9;
  o.shape = Shape::kMesh;
  o.mesh = &mesh;
  const PreviewImage meshed = RenderPreview(material, studio, o);
  std::size_t disagree = 0;
  for (std::size_t p = 0; p < sphere.object.size(); ++p)
    disagree += sphere.object[p] != meshed.object[p];
  EXPECT_LT(disagree, 40u);
  EXPECT_LT(CompareImages(meshed, sphere).relative_rms, 0.03);
}

// A box standing on a square floor, lit from (θ = 45°, φ = 0) and seen from straight above: the
// floor is dark exactly where the box's shadow falls (towards −x, as long as the box is high).
TEST_F(PreviewFiles, MeshShadowsFallWhereTheGeometryPutsThem) {
  // Floor [−1, 1]² at z = 0; box [−0.2, 0.2]² × [0, 0.6]. The bounding box is [−1,1]²×[0,0.6]:
  // centre (0, 0, 0.3), half diagonal √(1 + 1 + 0.09).
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty float y\n"
      "property float z\nelement face 7\nproperty list uchar int vertex_indices\nend_header\n"
      "-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n"
      "-0.2 -0.2 0.6\n0.2 -0.2 0.6\n0.2 0.2 0.6\n-0.2 0.2 0.6\n"
      "-0.2 -0.2 0.0\n0.2 -0.2 0.0\n0.2 0.2 0.0\n-0.2 0.2 0.0\n"
      "4 0 1 2 3\n4 4 5 6 7\n4 8 9 5 4\n4 9 10 6 5\n4 10 11 7 6\n4 11 8 4 7\n3 0 1 2\n";
  const Mesh mesh = LoadMesh(Write("box.ply", ply));
  const AnalyticBrdf white(MakeMaterial(Model::kLambert, {1, 1, 1}, {}, {}));
  PreviewOptions o = SmallOptions(101);
  o.shape = Shape::kMesh;
  o.mesh = &mesh;
  o.camera.theta_deg = 0.0;  // looking down; image right = +y, image up = −x (preview.h)
  o.camera.fill = 1.0;
  o.environment_lighting = false;
  o.show_background = false;
  o.light = DirectionalLight{45.0, 0.0, {kPi, kPi, kPi}};
  const PreviewImage image = RenderPreview(white, EnvironmentMap::Furnace(), o);
  // World (x, y) on the floor → pixel: the scene is centred on (0, 0, 0.3) and scaled by
  // 1/√2.09; the orthographic frame spans ±1 scaled units vertically.
  const double scale = 1.0 / std::sqrt(2.09);
  auto pixel_of = [&](double x, double y, int* px, int* py) {
    *px = static_cast<int>((y * scale + 1.0) * 0.5 * 101);
    *py = static_cast<int>((x * scale + 1.0) * 0.5 * 101);  // image up is −x
  };
  int px = 0, py = 0;
  pixel_of(-0.5, 0.0, &px, &py);  // in the shadow: x from −0.2 − 0.6·tan45° = −0.8 to −0.2
  EXPECT_EQ(image.Pixel(px, py)[1], 0.0f);
  pixel_of(0.5, 0.0, &px, &py);  // lit floor: ρ/π · π · cos45°
  EXPECT_NEAR(image.Pixel(px, py)[1], std::cos(kPi / 4), 1e-4);
  pixel_of(-0.5, 0.6, &px, &py);  // beside the shadow
  EXPECT_NEAR(image.Pixel(px, py)[1], std::cos(kPi / 4), 1e-4);
  pixel_of(0.0, 0.0, &px, &py);  // the box's top, facing up
  EXPECT_NEAR(image.Pixel(px, py)[1], std::cos(kPi / 4), 1e-4);
}

TEST(PreviewCamera, BothProjectionsFrameTheBoundingSphereAsDocumented) {
  const AnalyticBrdf white(MakeMaterial(Model::kLambert, {1, 1, 1}, {}, {}));
  for (auto projection : {Camera::Projection::kOrthographic, Camera::Projection::kPerspective}) {
    PreviewOptions o = SmallOptions(200, Estimator::kMis, 1);
    o.camera.projection = projection;
    o.camera.fill = 0.6;
    const PreviewImage image = RenderPreview(white, EnvironmentMap::Furnace(), o);
    int column = 0;
    for (int y = 0; y < 200; ++y) column += image.object[y * 200 + 100];
    EXPECT_NEAR(column, 0.6 * 200, 2.0) << static_cast<int>(projection);
  }
}

TEST(PreviewLight, DirectionalLightOnAPlaneGivesTheCosineLaw) {
  const AnalyticBrdf white(MakeMaterial(Model::kLambert, {0.5, 0.5, 0.5}, {}, {}));
  PreviewOptions o = SmallOptions(16);
  o.shape = Shape::kPlane;
  o.camera.theta_deg = 30.0;
  o.environment_lighting = false;
  o.light = DirectionalLight{60.0, 123.0, {2.0, 2.0, 2.0}};
  const PreviewImage image = RenderPreview(white, EnvironmentMap::Furnace(), o);
  const float* centre = image.Pixel(8, 8);
  EXPECT_NEAR(centre[0], 0.5 / kPi * 2.0 * 0.5, 1e-6);  // ρ/π · E · cos60°
}

TEST(PreviewToneMap, FollowsTheDocumentedCurveAndSrgbEncoding) {
  PreviewImage image;
  image.width = 4;
  image.height = 1;
  image.rgb = {0.18f, 0.18f, 0.18f, 0.25f, 0.25f, 0.25f, 1.0f, 1.0f, 1.0f, 7.0f, -1.0f, NAN};
  const auto clamp = ToneMap(image, 0.0, ToneMapCurve::kClamp);
  EXPECT_EQ(clamp[0], 118);  // 18 % grey is sRGB code 118
  EXPECT_EQ(clamp[3], 137);  // sRGB(0.25) = 0.5371
  EXPECT_EQ(clamp[6], 255);
  EXPECT_EQ(clamp[9], 255);
  EXPECT_EQ(clamp[10], 0);
  EXPECT_EQ(clamp[11], 0);
  const auto brighter = ToneMap(image, 1.0, ToneMapCurve::kClamp);
  EXPECT_EQ(brighter[3], 188);  // 0.25 · 2 = 0.5 → sRGB 0.7354
  const auto reinhard = ToneMap(image, 0.0, ToneMapCurve::kReinhard);
  EXPECT_EQ(reinhard[6], 188);  // 1 / (1 + 1) = 0.5
}

TEST_F(PreviewFiles, WritesLinearExrAndPngAndRefusesOtherExtensions) {
  const AnalyticBrdf material(test::GgxAlpha03());
  PreviewOptions o = SmallOptions(24, Estimator::kMis, 4);
  const PreviewImage image = RenderPreview(material, EnvironmentMap::Studio(64, 32), o);
  const std::string exr = (dir_ / "a.exr").string(), png = (dir_ / "a.png").string();
  WritePreviewImage(exr, image, 0.0, ToneMapCurve::kClamp, {{"brdf:source", "test"}});
  const exporter::ExrFile back = exporter::ReadExr(exr);
  ASSERT_EQ(back.image.width, 24);
  EXPECT_EQ(back.image.rgb, image.rgb);
  EXPECT_EQ(back.Attribute("brdf:source"), "test");
  WritePreviewImage(png, image);
  std::ifstream in(png, std::ios::binary);
  char signature[8] = {};
  in.read(signature, 8);
  EXPECT_EQ(std::string(signature + 1, 3), "PNG");
  EXPECT_THROW(WritePreviewImage((dir_ / "a.tif").string(), image), InvalidArgument);
}

TEST_F(PreviewFiles, BrokenMeshesAndMapsFailWithTheFileAndPosition) {
  const std::string obj = Write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  try {
    LoadMesh(obj);
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.obj"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 4"), std::string::npos) << e.what();
  }
  const std::string ply = Write("bad.ply",
                                "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                                "property float x\nproperty float y\nproperty float z\n"
                                "end_header\n\x01\x02");
  EXPECT_THROW(LoadMesh(ply), FormatError);
  EXPECT_THROW(LoadMesh(Write("mesh.stl", "solid")), InvalidArgument);
  // A map that is not 2:1.
  exporter::FloatImage square;
  square.width = square.height = 8;
  square.rgb.assign(8 * 8 * 3, 1.0f);
  const std::string exr = (dir_ / "square.exr").string();
  exporter::WriteExr(exr, square, {}, {});
  try {
    EnvironmentMap::Load(exr);
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("8 × 8"), std::string::npos) << e.what();
  }
  EXPECT_THROW(EnvironmentMap::FromName("no-such-map"), InvalidArgument);
}

// A damaged map is refused in one line that names the file, the scanline (or block of
// scanlines) and the byte where the layout breaks, what was expected there and what was found,
// in the file format's terms. The files are made here with their layout written out from the
// published descriptions (Radiance RGBE: header, resolution line, run-length scanlines;
// OpenEXR: header attributes, offset table, blocks of 16 scanlines for ZIP), so the positions
// the messages must name are known independently of the readers.
std::string LoadError(const std::string& path) {
  try {
    EnvironmentMap::Load(path);
  } catch (const FormatError& e) {
    return e.what();
  } catch (const Error& e) {
    return std::string("not a FormatError: ") + e.what();
  }
  return "no error";
}

void ExpectDamageMessage(const std::string& message, const std::string& file,
                         const std::vector<std::string>& parts) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(file, 0), 0u) << message;
  EXPECT_NE(message.find("expected"), std::string::npos) << message;
  EXPECT_NE(message.find(", got "), std::string::npos) << message;
  for (const char* internal : {"OpenImageIO", "Imf", "::", "Iex", "oiio"})
    EXPECT_EQ(message.find(internal), std::string::npos) << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

TEST_F(PreviewFiles, DamagedRadianceMapsNameTheScanlineAndByte) {
  // 16 × 8 pixels; every scanline run-length encoded: 2 2 0 16, then per component one run of
  // 16 equal bytes (count 128 + 16 = 144, value): 12 bytes a scanline.
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n";
  std::string scanline = {2, 2, 0, 16};
  for (unsigned char v : {128, 64, 32, 129})
    scanline += {static_cast<char>(144), static_cast<char>(v)};
  std::string file = header;
  for (int row = 0; row < 8; ++row) file += scanline;
  const std::size_t start = header.size();  // byte of scanline 1
  const EnvironmentMap intact = EnvironmentMap::Load(Write("intact.hdr", file));
  ASSERT_EQ(intact.width(), 16);
  // RGBE (128, 64, 32, 129): (m + 0.5)/256 · 2^(129 − 128) per the format's decoding rule, or
  // m/256 · 2 for decoders without the half-step.
  EXPECT_NEAR(intact.Pixel(3, 5)[0], 1.0, 0.005);
  EXPECT_NEAR(intact.Pixel(3, 5)[2], 0.25, 0.005);

  // Cut 7 bytes into scanline 6: its head (4), the red run (2) and the green count are there.
  const std::size_t cut = start + 5 * 12 + 7;
  ExpectDamageMessage(LoadError(Write("cut.hdr", file.substr(0, cut))), (dir_ / "cut.hdr").string(),
                      {"scanline 6 of 8", "byte " + std::to_string(start + 60), "green",
                       "end of the file at byte " + std::to_string(cut)});
  // One bit flipped in scanline 3's green run count: 144 → 145, a run of 17 in 16 pixels.
  std::string flipped = file;
  const std::size_t count_byte = start + 2 * 12 + 4 + 2;
  flipped[count_byte] = static_cast<char>(flipped[count_byte] ^ 0x01);
  ExpectDamageMessage(
      LoadError(Write("flip.hdr", flipped)), (dir_ / "flip.hdr").string(),
      {"scanline 3 of 8", "run at byte " + std::to_string(count_byte), "green", "a run of 17"});
  // One bit flipped in scanline 8's head: its width 16 → 48.
  flipped = file;
  flipped[start + 7 * 12 + 3] = static_cast<char>(16 ^ 0x20);
  ExpectDamageMessage(
      LoadError(Write("width.hdr", flipped)), (dir_ / "width.hdr").string(),
      {"scanline 8 of 8", "byte " + std::to_string(start + 84), "16 pixels", "48 pixels"});
  // The header cut inside the resolution line's line: line 4 (byte 35) never ends.
  ExpectDamageMessage(LoadError(Write("head.hdr", file.substr(0, header.size() - 4))),
                      (dir_ / "head.hdr").string(),
                      {"line 4 of the header", "byte " + std::to_string(header.find("-Y"))});
}

TEST_F(PreviewFiles, DamagedExrMapsNameTheBlockOfScanlinesAndByte) {
  // 128 × 64, smooth (so ZIP compresses it and its blocks hold deflate streams): 4 blocks of
  // 16 scanlines.
  exporter::FloatImage image;
  image.width = 128;
  image.height = 64;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x)
      for (float v : {x / 128.0f, y / 64.0f, 0.5f}) image.rgb.push_back(v);
  const std::string path = (dir_ / "intact.exr").string();
  exporter::WriteExr(path, image, {exporter::ExrPixelType::kFloat, exporter::ExrCompression::kZip},
                     {});
  ASSERT_EQ(EnvironmentMap::Load(path).height(), 64);
  std::string file;
  {
    std::ifstream in(path, std::ios::binary);
    file.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The layout: magic and version (8 bytes), attributes "name\0type\0" + 4-byte size + value
  // up to an empty name, then 4 little-endian 8-byte block offsets.
  auto le32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(file[at + k]);
    return v;
  };
  std::size_t at = 8;
  while (file[at] != '\0') {
    at = file.find('\0', at) + 1;  // name
    at = file.find('\0', at) + 1;  // type
    at += 4 + le32(at);
  }
  const std::size_t table = at + 1;
  std::vector<std::size_t> block(4);
  for (int k = 0; k < 4; ++k) block[k] = le32(table + 8 * k);  // offsets below 4 GiB
  for (int k = 0; k < 4; ++k) ASSERT_EQ(le32(block[k]), 16u * k) << "block " << k << "'s first row";

  // Cut in the middle of block 3's data.
  const std::size_t cut = block[2] + 8 + le32(block[2] + 4) / 2;
  ExpectDamageMessage(
      LoadError(Write("cut.exr", file.substr(0, cut))), (dir_ / "cut.exr").string(),
      {"pixel block 3 of 4", "scanlines 33–48 of 64", "byte " + std::to_string(block[2]),
       "end of the file at byte " + std::to_string(cut)});
  // One bit flipped in the middle of block 2's deflate stream.
  std::string flipped = file;
  const std::size_t middle = block[1] + 8 + le32(block[1] + 4) / 2;
  flipped[middle] = static_cast<char>(flipped[middle] ^ 0x10);
  ExpectDamageMessage(LoadError(Write("flip.exr", flipped)), (dir_ / "flip.exr").string(),
                      {"pixel block 2 of 4", "scanlines 17–32 of 64",
                       "byte " + std::to_string(block[1]), "does not decode"});
  // One bit flipped in the table's third offset (bit 40: far past the end of the file): OpenEXR
  // rebuilds a damaged table from the blocks themselves, so this map still reads.
  flipped = file;
  flipped[table + 8 * 2 + 5] = static_cast<char>(flipped[table + 8 * 2 + 5] ^ 0x01);
  EXPECT_EQ(LoadError(Write("table.exr", flipped)), "no error");
  // The header cut at byte 20.
  ExpectDamageMessage(LoadError(Write("head.exr", file.substr(0, 20))),
                      (dir_ / "head.exr").string(), {"header attribute", "byte 8"});
}

TEST(PreviewProgressive, PassesAccumulateAndCancelStopsEarly) {
  const AnalyticBrdf material(test::GgxAlpha03());
  const EnvironmentMap studio = EnvironmentMap::Studio(64, 32);
  PreviewOptions o = SmallOptions(24);
  PreviewRenderer renderer(material, studio, o);
  EXPECT_EQ(renderer.RenderPasses(3), 3);
  EXPECT_EQ(renderer.RenderPasses(5), 5);
  EXPECT_EQ(renderer.passes(), 8);
  const double rms8 = renderer.EstimatedRelativeRms();
  renderer.RenderPasses(56);
  EXPECT_LT(renderer.EstimatedRelativeRms(), rms8 / 2.0);  // ∝ 1/√passes
  std::atomic<bool> cancel{true};
  o.cancel = &cancel;
  PreviewRenderer cancelled(material, studio, o);
  EXPECT_EQ(cancelled.RenderPasses(10), 0);
  EXPECT_EQ(cancelled.passes(), 0);
  // The same seed gives the same image; a shared sampler changes nothing.
  PreviewOptions same = SmallOptions(24);
  PreviewRenderer again(material, studio, same, renderer.sampler());
  again.RenderPasses(64);
  EXPECT_EQ(again.Image().rgb, renderer.Image().rgb);
}

// The one pass of the deterministic estimators reports the fraction of the object's pixels
// finished, from the calling thread. With one thread every piece of work is the caller's, so the
// reports of the hierarchical pass are known in advance from the sphere's geometry alone: its
// 64 × 64 image has 4 × 4 blocks of 16 pixels, done in four passes by the parity of their row
// and column (even rows' even columns, even rows' odd columns, then the odd rows' likewise), each
// pass row by row; after each block the fraction is the share of the sphere's pixels in the
// blocks done.
TEST(PreviewProgressive, DeterministicPassReportsTheFractionOfPixelsDoneFromTheCallingThread) {
  const AnalyticBrdf material(test::GgxAlpha03());
  const EnvironmentMap studio = EnvironmentMap::Studio(64, 32);
  const int size = 64;
  PreviewOptions o = SmallOptions(size, Estimator::kHierarchical);
  double block_share[4][4] = {};
  double all = 0.0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (Vec3 n; SphereNormal(x, y, size, size, o.camera.fill, &n)) {
        block_share[y / 16][x / 16] += 1.0;
        all += 1.0;
      }
  std::vector<double> expected;
  double done = 0.0;
  for (int pass = 0; pass < 4; ++pass)
    for (int r = pass / 2; r < 4; r += 2)
      for (int c = pass % 2; c < 4; c += 2) {
        done += block_share[r][c];
        expected.push_back(done / all);
      }
  expected.back() = 1.0;    // the same sum, in another order
  expected.push_back(1.0);  // the end of the pass
  const PreviewImage silent = RenderPreview(material, studio, o);
  std::vector<double> fractions, seconds;
  std::vector<std::thread::id> threads;
  o.pass_progress = [&](double fraction, double s) {
    fractions.push_back(fraction);
    seconds.push_back(s);
    threads.push_back(std::this_thread::get_id());
  };
  o.jobs = 1;
  const PreviewImage reported = RenderPreview(material, studio, o);
  ASSERT_EQ(fractions.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(fractions[k], expected[k], 1e-12);
  EXPECT_EQ(reported.rgb, silent.rgb) << "reporting changes nothing in the image";

  // Two threads, both deterministic estimators and single-pixel blocks: fractions never
  // decrease, times never decrease, every call is on the calling thread, the last is 1.
  o.jobs = 2;
  for (const auto& [estimator, block] :
       std::vector<std::pair<Estimator, int>>{{Estimator::kHierarchical, 16},
                                              {Estimator::kHierarchical, 1},
                                              {Estimator::kQuadrature, 16}}) {
    o.estimator = estimator;
    o.image_block = block;
    fractions.clear();
    seconds.clear();
    threads.clear();
    RenderPreview(material, studio, o);
    ASSERT_GE(fractions.size(), 2u);
    for (std::size_t k = 1; k < fractions.size(); ++k) {
      EXPECT_GE(fractions[k], fractions[k - 1]);
      EXPECT_GE(seconds[k], seconds[k - 1]);
    }
    EXPECT_GE(fractions.front(), 0.0);
    EXPECT_EQ(fractions.back(), 1.0);
    for (const std::thread::id& id : threads) EXPECT_EQ(id, std::this_thread::get_id());
  }

  // Cancelled from the callback: the pass stops, and no report claims it finished.
  std::atomic<bool> cancel{false};
  o.estimator = Estimator::kHierarchical;
  o.image_block = 16;
  o.jobs = 1;
  o.cancel = &cancel;
  fractions.clear();
  o.pass_progress = [&](double fraction, double) {
    fractions.push_back(fraction);
    cancel = true;
  };
  PreviewRenderer renderer(material, studio, o);
  EXPECT_EQ(renderer.RenderPasses(1), 0);
  ASSERT_EQ(fractions.size(), 1u);
  EXPECT_LT(fractions.back(), 1.0);
}

}  // namespace
}  // namespace brdf::preview
