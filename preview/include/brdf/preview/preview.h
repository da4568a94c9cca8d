// Environment-lit previews of any BRDF: a sphere, a plane or a mesh lit by a distant
// environment map (and optionally one directional light), rendered headless to linear HDR
// radiance. `brdf preview` and the viewer's preview mode both call this; no VTK, no display.
//
// What is computed. For the camera ray through each pixel that hits the object at x with
// shading normal n, the pixel value is the outgoing radiance of the rendering equation with
// direct lighting from the map (no interreflection between parts of the object):
//
//   L_o(x, ω_o) = ∫_{H²(n)} L_env(ω_i) · V(x, ω_i) · f_r(ω_i, ω_o) · cosθ_i dω_i
//               + E_light · V(x, ω_light) · f_r(ω_light, ω_o) · cosθ_light
//
// with f_r from BrdfSource::Eval in the local frame of x (z = n, ω_i towards the light, ω_o
// towards the camera; brdf_source.h), cosθ_i = n·ω_i, V the visibility of the map (always 1
// for the sphere and the plane, which cannot shadow themselves; traced through a BVH for
// meshes). Pixels that miss the object show the map itself, L_env(ray direction), or black when
// `show_background` is off. Values are linear Rec.709 RGB radiance in the map's units: a
// Lambertian of albedo ρ under a uniform map of radiance L renders as ρ·L everywhere.
//
// The integral is estimated without bias (Estimator): importance sampling of the map
// (a piecewise-constant 2D distribution over its pixels, with the sinθ Jacobian of the
// equirectangular parameterisation), of the BRDF (visible-normal sampling of the GGX lobe for
// analytic GGX materials; for every other source a tabulated distribution built from the
// source's own values on a grid around the mirror direction, per θ_in slice), or both combined
// by multiple importance sampling with the power heuristic. The pdf each sampler reports is the
// exact density of the directions it draws (tests check this with χ² tests). For the sphere and
// the plane a deterministic quadrature over every map pixel is also available; it is the
// reference the tests compare the estimators against. For them too, Estimator::kHierarchical is
// the fast deterministic path (an adaptive quadrature over a hierarchy of the map with image-space
// interpolation, within about 0.5 % RMS of that reference; docs/preview.md), and kAuto picks it
// for the sphere.
//
// World frame and map orientation (docs/preview.md): z is up. A direction ω(θ, φ) =
// (sinθ cosφ, sinθ sinφ, cosθ) has θ measured from +z (the zenith) and φ from +x towards +y.
// The equirectangular map has θ = 0 (zenith) on its top row and φ = 0 on its left edge, φ
// increasing to the right: pixel (i, j) of a W × H map covers φ ∈ [2π·i/W, 2π·(i+1)/W),
// θ ∈ [π·j/H, π·(j+1)/H). `environment_rotation_deg` turns the map about +z (φ increases).
// The default camera sits on the +x axis looking towards −x, so the map's centre column
// (φ = 180°) is the background straight behind the object.
//
// Units: angles in degrees in every option (the names end in _deg), radiance in the map's
// units, times in seconds.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/geometry.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/core/models.h"

namespace brdf::preview {

// An equirectangular environment map of linear Rec.709 RGB radiance (see the orientation
// above). Immutable after construction; safe to read from many threads.
class EnvironmentMap {
 public:
  // `rgb` holds width·height·3 floats, row-major, row 0 at the top (θ = 0). Negative, NaN and
  // infinite values are refused. Throws InvalidArgument (sizes, values).
  EnvironmentMap(int width, int height, std::vector<float> rgb, std::string name = "map");

  // Built-in procedural maps (no files). Sizes default to 1024 × 512.
  //  - Studio: a dim vertical gradient (0.05 below the horizon rising to 0.25 at the zenith)
  //    with three soft boxes: a large key light above and in front of the default camera, a
  //    fill on the other side, a rim light behind the object; the default map.
  //  - Sky: an analytic clear daylight sky (CIE clear-sky luminance distribution, bluish,
  //    brighter towards the sun and the horizon) over a grey ground of albedo 0.2, plus a sun
  //    disc of 0.53° at `sun_theta_deg`, `sun_phi_deg`.
  //  - Furnace: uniform radiance `radiance` in every direction (white-furnace tests).
  //  - AxisCoded: for checking orientation. The colour of each direction ω says where it
  //    points: +x red, +y green, +z (up) blue, and the opposite axes in the complementary
  //    colours at half strength (−x cyan, −y magenta, −z yellow):
  //      R = max(0, ω.x) + ½·(max(0, −ω.y) + max(0, −ω.z))
  //      G = max(0, ω.y) + ½·(max(0, −ω.x) + max(0, −ω.z))
  //      B = max(0, ω.z) + ½·(max(0, −ω.x) + max(0, −ω.y))
  //    evaluated at each pixel's centre direction.
  static EnvironmentMap Studio(int width = 1024, int height = 512);
  static EnvironmentMap Sky(double sun_theta_deg = 40.0, double sun_phi_deg = 30.0,
                            int width = 1024, int height = 512);
  static EnvironmentMap Furnace(Rgb radiance = {1.0, 1.0, 1.0}, int width = 64, int height = 32);
  static EnvironmentMap AxisCoded(int width = 256, int height = 128);

  // An equirectangular .exr or .hdr file (RGB; alpha and further channels ignored), read in
  // the orientation above. Texels that carry no usable radiance (a NaN, +Inf — a half-float
  // value beyond 65504, such as a sun, overflows to it —, −Inf or a negative value in any
  // channel) are taken as black and counted in load_warning(); a map with no usable texel at
  // all is refused. Throws IoError / FormatError naming the file.
  static EnvironmentMap Load(const std::string& path);
  // "studio", "sky", "furnace", "axes" or a file path. Throws InvalidArgument for an unknown
  // name that is not an existing file either.
  static EnvironmentMap FromName(const std::string& name_or_path);

  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& name() const { return name_; }
  // Load(): one line naming the file and how many texels were taken as black and why; empty
  // when every texel was usable (and for maps not read from a file).
  const std::string& load_warning() const { return load_warning_; }
  const std::vector<float>& rgb() const { return rgb_; }
  const float* Pixel(int i, int j) const {
    return &rgb_[(static_cast<std::size_t>(j) * width_ + i) * 3];
  }
  // Radiance arriving from world direction `w` (unit vector pointing away from the object,
  // towards the map), nearest pixel: the map is piecewise constant, exactly the function every
  // estimator integrates.
  Rgb Radiance(const Vec3& w) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> rgb_;
  std::string name_;
  std::string load_warning_;
};

enum class Shape { kSphere, kPlane, kMesh };

// A triangle mesh in world units (the renderer scales and centres it to fit the view).
// Normals are per vertex (unit, outward); when a file has none they are the area-weighted
// averages of the adjacent face normals.
struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // same size as positions
  std::vector<std::array<std::uint32_t, 3>> triangles;
};
// Reads an ASCII or binary little-endian PLY (vertex x, y, z, optional nx, ny, nz; faces as
// vertex index lists, polygons fanned into triangles) or a Wavefront OBJ (v, vn, f; other
// statements ignored). Throws IoError / FormatError naming the file and the line or byte.
Mesh LoadMesh(const std::string& path);

struct Camera {
  enum class Projection { kOrthographic, kPerspective };
  Projection projection = Projection::kOrthographic;
  // Where the camera sits, seen from the object's centre: polar angle from +z and azimuth
  // from +x, degrees. The camera looks at the centre with +z projecting upwards in the image.
  double theta_deg = 90.0;
  double phi_deg = 0.0;
  // Perspective only: full vertical field of view. The distance is chosen so the object's
  // bounding sphere fills the frame, as the orthographic view does.
  double fov_deg = 30.0;
  // Fraction of the frame height the bounding sphere's diameter covers (both projections).
  double fill = 0.9;
};

// The camera a picture of `shape` gets when the user names none: Camera{} (θ = 90°, on +x) for
// the sphere and meshes; for the plane, which lies at z = 0 and that camera sees edge-on, the
// camera at θ = 60°, φ = 0, which sees it obliquely from above.
Camera DefaultCamera(Shape shape);

// One distant directional light (for direct-lighting pictures): it arrives from world direction
// (theta_deg, phi_deg) (the direction towards the light) with irradiance `irradiance` on a
// surface facing it.
struct DirectionalLight {
  double theta_deg = 45.0;
  double phi_deg = 0.0;
  Rgb irradiance = {kPi, kPi, kPi};  // a white Lambertian facing the light renders as 1
};

enum class Estimator {
  kMis,          // one map sample and one BRDF sample per pass, power heuristic (default)
  kEnvironment,  // map importance sampling only
  kBrdf,         // BRDF importance sampling only
  kQuadrature,   // deterministic sum over every map pixel (sphere and plane only)
  // Sphere and plane only: the fast deterministic path. Per computed pixel, an adaptive
  // quadrature over a hierarchy of the map: every level stores the exact integrals of L and of
  // Y·ω over its cells (Y the luminance), a cell contributes f_r at its luminance centroid times
  // those integrals (the cosine integrated exactly), and cells are split where a cell and its
  // four children disagree, where they hold a large share of the pixel, around the mirror
  // direction, and (without BRDF evaluations) at the horizon. Between computed pixels, bilinear
  // interpolation over image blocks whose centre and edge midpoints, computed too, agree with
  // it. Deterministic: one pass; the tolerances are the options below.
  kHierarchical,
  // kHierarchical for the sphere, kMis otherwise (what `brdf preview` uses by default).
  kAuto,
  // Not an estimator of the integral: the engines' split-sum image of PreviewOptions::engine_ibl
  // (what an image rendered with it reports; set whenever engine_ibl is given).
  kEngineSplitSum,
};

// The documented tone map of the 8-bit output (ToneMap below).
enum class ToneMapCurve {
  kClamp,     // x ↦ min(x, 1)
  kReinhard,  // x ↦ x / (1 + x), per channel
};

struct PreviewOptions {
  Shape shape = Shape::kSphere;
  const Mesh* mesh = nullptr;     // kMesh: the mesh (must outlive the renderer)
  int width = 512, height = 512;  // pixels
  Camera camera;
  double environment_rotation_deg = 0.0;  // turns the map about +z
  bool environment_lighting = true;       // false: only `light` illuminates (the map stays the
                                          // background unless show_background is off)
  bool show_background = true;
  std::optional<DirectionalLight> light;
  Estimator estimator = Estimator::kMis;
  // Stop rules of RenderPreview: the first one reached ends the render. `samples_per_pixel`
  // counts passes (a MIS pass draws one map and one BRDF direction per pixel);
  // `target_relative_rms` stops when EstimatedRelativeRms() falls below it (0: off);
  // kQuadrature ignores both (one exact pass).
  int samples_per_pixel = 64;
  double target_relative_rms = 0.0;
  int max_samples_per_pixel = 65536;
  int jobs = 0;            // worker threads; 0 = hardware threads
  std::uint64_t seed = 1;  // same seed, same options → the same image
  // kQuadrature: each map pixel is split into n × n parts (midpoint rule in solid angle).
  int quadrature_subdivisions = 2;
  // kHierarchical. Both tolerances are relative to the image's mean object luminance Ȳ
  // (estimated first from the coarsest level at about 1000 pixels), the scale the benchmark's
  // RMS error is measured against. A map cell of solid angle Ω is split when the luminance of
  // its estimate and its four children's differ by more than hierarchical_tolerance·Ȳ·(Ω/2π)^0.1.
  // Image blocks of image_block × image_block pixels (a power of two) are filled by
  // biquadratic interpolation through the pixels computed at their corners, centre and edge
  // midpoints when those midpoints differ from the bilinear interpolation of the corners by at
  // most image_tolerance·Ȳ·min(width, height)/512 in every channel, else split in four down to
  // single pixels; 1: every pixel computed. The tolerance is stated for 512 pixels across and
  // shrinks in smaller images, where a block spans a larger part of the object. With the
  // defaults the image is within about 0.04–0.8 % RMS of the brute-force kQuadrature at 512²
  // for the benchmark's materials, up to 1.4 % for some RGL files and more in smaller images
  // (docs/preview.md, docs/benchmarks.md).
  double hierarchical_tolerance = 0.002;
  int image_block = 16;
  double image_tolerance = 0.1;
  // Kept for references at a subset of pixels: when non-empty, only these image pixels
  // (y · width + x) are rendered; the others are neither object nor lit (black, object 0).
  std::vector<std::uint32_t> pixel_subset;
  // Called after every pass from the calling thread: passes done, the current estimate of the
  // relative RMS error, seconds since the start. Return false to stop early.
  std::function<bool(int passes, double relative_rms, double seconds)> progress;
  // The deterministic estimators (kHierarchical, kQuadrature) finish in one long pass; during
  // it this is called from the calling thread (after each piece of work that thread finishes,
  // so often: throttle the printing) with the fraction of the object's pixels finished, never
  // decreasing, and the seconds since the pass started; the last call of a pass that was not
  // cancelled has fraction 1. The workers only count (no locks, no calls).
  std::function<void(double fraction_done, double seconds)> pass_progress;
  // Checked between tiles; when it becomes true the current pass is abandoned and the render
  // returns with the passes completed so far.
  const std::atomic<bool>* cancel = nullptr;
  // When set (it must outlive the renderer), the map lights the object the way an engine's
  // probes light this material instead of by the integral above (`brdf preview --ibl engine`):
  // per pixel, with μ = n·ω_o and R = 2μn − ω_o, the split sum of brdf/core/ibl_pack.h,
  //   L_o = D(μ)·Ē(n) + S(μ)·P(α_eq(μ), R),
  // the pack's row read at μ as a linear texture, Ē from the map's order-2 SH and P from a GGX
  // filtered-importance-sampled mip pyramid of the map (256 samples; docs/preview.md). One
  // deterministic pass; any shape; no shadowing from the map (an engine's probe has none);
  // `estimator` is ignored and the image reports kEngineSplitSum. The directional light, if
  // any, is still f_r from the source.
  const IblPack* engine_ibl = nullptr;
};

// The object of a preview by the name the commands take: "sphere", "plane", or a mesh file
// (LoadMesh into *mesh, which must outlive the render). Sets options->shape, options->mesh and
// the default camera for that shape (DefaultCamera).
void SelectShape(const std::string& name, Mesh* mesh, PreviewOptions* options);

// A linear HDR image and what produced it.
struct PreviewImage {
  int width = 0, height = 0;
  std::vector<float> rgb;                 // width·height·3, row 0 at the top, linear radiance
  std::vector<std::uint8_t> object;       // width·height: 1 where the camera ray hits the object
  Estimator estimator = Estimator::kMis;  // what produced it (kAuto resolved)
  std::uint64_t brdf_evaluations = 0;     // kHierarchical and kQuadrature: f_r evaluations
  std::uint64_t computed_pixels = 0;      // deterministic estimators: pixels integrated, the
                                          // rest interpolated (kHierarchical)
  // kHierarchical: the name of what was evaluated instead of the source, when the source
  // offered a faster approximation (BrdfSource::QuadratureApproximation: an RGL file's
  // tabulated form); empty when the source itself was evaluated.
  std::string evaluated_as;
  int samples_per_pixel = 0;           // passes accumulated
  double relative_rms_estimate = 0.0;  // EstimatedRelativeRms() when the image was taken
  double seconds = 0.0;
  const float* Pixel(int x, int y) const {
    return &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
  }
};

// A progressive render: each RenderPasses() call adds passes to a running mean, so a viewer can
// refine the picture while idle and show Image() between calls. Changing the camera or the map
// rotation means a new renderer; the BRDF sampler (the costly part for measured sources) can be
// built once and shared between renderers (BrdfSampler below).
class BrdfSampler;

class PreviewRenderer {
 public:
  // `source`, `environment` and options.mesh must outlive the renderer; `sampler` may be null
  // (built here). Throws InvalidArgument for inconsistent options (sizes < 1, kMesh without a
  // mesh or with an empty one, kQuadrature on a mesh, fill not in (0, 1], ...) and, before
  // any work, for a render whose EstimatedPeakBytes exceed the memory this process can still
  // take (brdf/core/available_memory.h), naming both figures.
  PreviewRenderer(const BrdfSource& source, const EnvironmentMap& environment,
                  PreviewOptions options, std::shared_ptr<const BrdfSampler> sampler = nullptr);
  ~PreviewRenderer();
  PreviewRenderer(const PreviewRenderer&) = delete;
  PreviewRenderer& operator=(const PreviewRenderer&) = delete;

  // Adds `passes` passes (kQuadrature: computes the exact image once; further calls do
  // nothing). Uses options.jobs threads; returns early (the partial pass discarded) when
  // options.cancel becomes true. Returns the number of passes completed by this call.
  int RenderPasses(int passes);

  int passes() const;
  // The current mean.
  PreviewImage Image() const;
  // The estimated RMS of the image's error, relative to its mean: sqrt(mean over object pixels
  // of the variance of each pixel's mean luminance) / (mean object-pixel luminance). Infinite
  // before 4 passes; 0 for kQuadrature.
  double EstimatedRelativeRms() const;

  const std::shared_ptr<const BrdfSampler>& sampler() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// An upper bound of the memory a render with these options and this map needs, in bytes: at most
// about 40 bytes per image pixel kept between passes (the object mask, the object pixels' index
// and RGB sums, their luminance² and the light's share when they apply) plus the image made at
// the end (13 bytes a pixel) and a Monte Carlo pass's sums, plus the hierarchical quadrature's
// map hierarchy (about 37 bytes per map pixel); the map itself is not counted (it exists
// already). docs/benchmarks/preview-memory.md compares it with measured peaks.
std::uint64_t EstimatedPeakBytes(const PreviewOptions& options, const EnvironmentMap& environment);

// One call: renders until options' stop rules are met.
PreviewImage RenderPreview(const BrdfSource& source, const EnvironmentMap& environment,
                           const PreviewOptions& options);

// Importance sampling of a BRDF's cosine-weighted lobe, f_r(ω_i, ω_o)·cosθ_i over ω_i for a
// fixed ω_o, in the local frame (z = normal, both directions pointing away from the surface).
// Built for one source: visible-normal GGX sampling mixed with cosine sampling for analytic
// GGX materials, a tabulated distribution otherwise (see the file comment). Thread-safe.
class BrdfSampler {
 public:
  virtual ~BrdfSampler() = default;
  // Draws ω_i from (u1, u2, u3) ∈ [0, 1)³ given ω_o (ω_o.z > 0). Returns false when it draws
  // nothing (the direction would have zero density). `pdf` is per unit solid angle.
  virtual bool Sample(const Vec3& wo, double u1, double u2, double u3, Vec3* wi,
                      double* pdf) const = 0;
  // The density Sample() draws ω_i with, per unit solid angle (0 below the horizon).
  virtual double Pdf(const Vec3& wo, const Vec3& wi) const = 0;
  // "ggx-vndf" or "tabulated".
  virtual std::string Kind() const = 0;
};
// Chooses the sampler for a source (AnalyticBrdf with a GGX material → visible normals).
// Building the tabulated one evaluates the source on its grid (about 10^5 evaluations) on
// `jobs` threads (0 = hardware threads).
std::shared_ptr<const BrdfSampler> MakeBrdfSampler(const BrdfSource& source, int jobs = 0);

// Importance sampling of an environment map (map radiance, by max RGB channel, times the pixel's
// solid angle), in world directions. Exposed for tests and tools.
class EnvironmentSampler {
 public:
  explicit EnvironmentSampler(const EnvironmentMap& map);
  ~EnvironmentSampler();
  EnvironmentSampler(EnvironmentSampler&&) noexcept;
  // Draws a world direction from (u1, u2) ∈ [0, 1)²; false for an all-black map.
  bool Sample(double u1, double u2, Vec3* w, double* pdf) const;
  double Pdf(const Vec3& w) const;  // per unit solid angle

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The RMS difference of two images of the same size over the pixels where either shows the
// object (`object` masks), per channel, absolute and relative to the mean of `reference` there.
struct ImageDifference {
  double rms = 0.0;
  double relative_rms = 0.0;
  double max_abs = 0.0;
  std::size_t pixels = 0;
};
ImageDifference CompareImages(const PreviewImage& image, const PreviewImage& reference);

// `a | b | a − b`: the two renders side by side and their signed difference, all of a's size,
// separated by 4-pixel black gutters. The difference panel is linear: positive (a brighter)
// shown in the red channel, negative in the blue one, as |a − b| luminance scaled by
// `difference_gain` (1: the same scale as the renders).
PreviewImage SideBySide(const PreviewImage& a, const PreviewImage& b, double difference_gain = 1.0);

// The 8-bit picture of a linear image: every channel is multiplied by 2^exposure_ev, passed
// through `curve`, clamped to [0, 1] and encoded with the sRGB transfer function, rounded to
// 8 bits. width·height·3 bytes, row 0 at the top.
std::vector<std::uint8_t> ToneMap(const PreviewImage& image, double exposure_ev = 0.0,
                                  ToneMapCurve curve = ToneMapCurve::kClamp);

// Writes `image` by extension: .exr (float RGB, linear radiance, no tone map; header attributes
// name the source, map and samples) or .png (ToneMap with the given exposure and curve).
// Written atomically. Throws InvalidArgument for another extension, IoError when writing fails.
void WritePreviewImage(const std::string& path, const PreviewImage& image, double exposure_ev = 0.0,
                       ToneMapCurve curve = ToneMapCurve::kClamp,
                       const std::vector<std::pair<std::string, std::string>>& attributes = {});

}  // namespace brdf::preview
