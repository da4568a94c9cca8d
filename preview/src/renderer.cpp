// The preview integrator (preview.h): camera rays, the per-pixel estimators, progressive
// accumulation and the deterministic quadrature.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "brdf/core/available_memory.h"
#include "brdf/core/error.h"
#include "brdf/preview/preview.h"
#include "hierarchical.h"
#include "preview_internal.h"
#include "scene.h"
#include "split_sum.h"

namespace brdf::preview {
namespace {

using detail::Frame;
using detail::Luminance;

std::uint64_t Mix(std::uint64_t x) {  // SplitMix64 finaliser
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
double ToUnit(std::uint64_t x) { return static_cast<double>(x >> 11) * 0x1.0p-53; }

// Random numbers per pixel and pass: each strategy's 2D point comes from the R2 Kronecker
// sequence over passes, α = (g⁻¹, g⁻²) with g the plastic number, the positive root of
// x³ = x + 1 (Roberts 2018); the BRDF sampler's lobe choice from the golden-ratio sequence.
// Every pixel shifts the sequences by its own uniform random offsets (Cranley–Patterson
// rotation), so each number is uniform on [0, 1) for every pass and the estimator stays
// unbiased, while successive passes of a pixel are stratified and the mean converges faster
// than with independent numbers. The per-pixel variance estimate treats the passes as
// independent, so it overstates the error of the mean (a conservative stop rule).
struct Kronecker {
  std::array<double, 5> alpha{};
  Kronecker() {
    double g = 1.3;
    for (int k = 0; k < 60; ++k) g -= (g * g * g - g - 1.0) / (3.0 * g * g - 1.0);
    alpha = {1.0 / g, 1.0 / (g * g), 1.0 / g, 1.0 / (g * g), 0.5 * (std::sqrt(5.0) - 1.0)};
  }
};

// The hierarchy's top level: 16 × 8 cells of 22.5°, each of which is always compared with its
// four children, so 32 × 16 is the coarsest resolution a pixel is integrated at.
constexpr int kHierarchyTopColumns = 16;
// The image size PreviewOptions::image_tolerance is stated for.
constexpr double kImageToleranceSize = 512.0;

// What a camera ray through a pixel found. Traced again wherever it is needed rather than kept
// per pixel (168 bytes a pixel, most of a preview's memory): a ray cast is cheap next to the
// estimate it serves, and it gives the same numbers every time.
struct PixelSetup {
  Vec3 position;
  Vec3 geometric_normal;
  Frame frame;
  Vec3 wo;  // towards the camera, local frame
};

// The fraction of a deterministic pass done, counted by the workers (one relaxed atomic add per
// chunk, no lock) and reported to PreviewOptions::pass_progress from the calling thread.
class PassFraction {
 public:
  PassFraction(const PreviewOptions& options, std::size_t total,
               std::chrono::steady_clock::time_point start)
      : callback_(options.pass_progress),
        cancel_(options.cancel),
        total_(std::max<std::size_t>(1, total)),
        start_(start) {}
  void Add(std::size_t units) {
    if (callback_) done_.fetch_add(units, std::memory_order_relaxed);
  }
  // Reports the current fraction (never less than the last one reported).
  void Report() {
    if (!callback_) return;
    const double f = std::min(1.0, static_cast<double>(done_.load(std::memory_order_relaxed)) /
                                       static_cast<double>(total_));
    last_ = std::max(last_, f);
    callback_(last_, Seconds());
  }
  // The end of a pass that was not cancelled: reports 1.
  void Finish() {
    if (!callback_ || (cancel_ != nullptr && cancel_->load())) return;
    last_ = 1.0;
    callback_(1.0, Seconds());
  }
  // What ParallelChunks calls on the calling thread.
  std::function<void()> Reporter() {
    if (!callback_) return {};
    return [this] { Report(); };
  }

 private:
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  const std::function<void(double, double)>& callback_;
  const std::atomic<bool>* cancel_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
  double last_ = 0.0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

struct PreviewRenderer::Impl {
  const BrdfSource& source;
  const EnvironmentMap& environment;
  PreviewOptions options;
  std::shared_ptr<const BrdfSampler> sampler;
  std::unique_ptr<EnvironmentSampler> environment_sampler;
  detail::Scene scene;
  double cos_rotation = 1.0, sin_rotation = 0.0;
  int jobs = 1;

  // Per image pixel, what is kept between passes is at most about 40 bytes (docs/benchmarks/
  // preview-memory.md): the object mask, the object pixels' index and sums; the background is
  // looked up again when the image is made, and the pixel set-up (PixelSetup) traced again.
  std::vector<std::uint8_t> object;         // per image pixel
  std::vector<std::uint32_t> object_index;  // image pixel of each object pixel
  std::vector<std::array<float, 3>> light;  // per object pixel: the directional light's share
  std::vector<double> sum;                  // per object pixel, RGB
  std::vector<double> sum_sq;               // per object pixel, luminance² (Monte Carlo only)
  // The camera (SetUpPixels).
  bool perspective = false;
  Vec3 eye{}, forward{}, right{}, up{};
  double aspect = 1.0, tan_half = 0.0, ortho_half_height = 1.0;
  int passes = 0;
  bool exact = false;  // quadrature or light-only: one pass is the answer
  double seconds = 0.0;
  std::uint64_t evaluations = 0;     // f_r evaluations of the deterministic estimators
  std::uint64_t computed_count = 0;  // kHierarchical: object pixels integrated (not interpolated)
  std::string evaluated_as;          // kHierarchical: the approximation's name, when one was used
  std::chrono::steady_clock::time_point pass_start;  // of the running RenderPasses call

  Impl(const BrdfSource& s, const EnvironmentMap& e, PreviewOptions o,
       std::shared_ptr<const BrdfSampler> sp)
      : source(s),
        environment(e),
        options(std::move(o)),
        sampler(std::move(sp)),
        scene(options.shape, options.mesh) {}

  Vec3 ToMap(const Vec3& w) const { return detail::RotateZ(w, cos_rotation, -sin_rotation); }
  Vec3 FromMap(const Vec3& m) const { return detail::RotateZ(m, cos_rotation, sin_rotation); }

  void Validate() const {
    const PreviewOptions& o = options;
    auto fail = [](const std::string& what) { throw InvalidArgument("preview: " + what); };
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
      fail("image size must be between 1 and 16384 pixels a side, got " + std::to_string(o.width) +
           " × " + std::to_string(o.height));
    if (!(o.camera.fill > 0.0 && o.camera.fill <= 1.0))
      fail("camera fill must be in (0, 1], got " + std::to_string(o.camera.fill));
    if (o.camera.projection == Camera::Projection::kPerspective &&
        !(o.camera.fov_deg > 0.0 && o.camera.fov_deg < 170.0))
      fail("field of view must be in (0, 170) degrees, got " + NumberText(o.camera.fov_deg));
    if (!std::isfinite(o.camera.theta_deg) || !std::isfinite(o.camera.phi_deg) ||
        !std::isfinite(o.environment_rotation_deg))
      fail("camera angles and the map rotation must be finite");
    if (o.estimator == Estimator::kQuadrature && o.shape == Shape::kMesh)
      fail("the quadrature reference needs a convex object (sphere or plane), not a mesh");
    if (o.estimator == Estimator::kHierarchical && o.shape == Shape::kMesh)
      fail("the hierarchical quadrature needs a convex object (sphere or plane), not a mesh");
    if (o.image_block < 1 || o.image_block > 64 || (o.image_block & (o.image_block - 1)) != 0)
      fail("the image block must be a power of two from 1 to 64, got " +
           std::to_string(o.image_block));
    if (!(o.hierarchical_tolerance > 0.0) || !(o.image_tolerance >= 0.0) ||
        !std::isfinite(o.hierarchical_tolerance) || !std::isfinite(o.image_tolerance))
      fail("the hierarchical tolerances must be finite, the map one > 0 and the image one ≥ 0");
    if (o.quadrature_subdivisions < 1 || o.quadrature_subdivisions > 16)
      fail("quadrature subdivisions must be between 1 and 16");
    if (o.samples_per_pixel < 1 && !(o.target_relative_rms > 0.0))
      fail("need samples per pixel ≥ 1 or a target RMS > 0");
    if (o.target_relative_rms < 0.0 || !std::isfinite(o.target_relative_rms))
      fail("the target RMS must be ≥ 0");
    if (o.light) {
      if (!(o.light->theta_deg >= 0.0 && o.light->theta_deg <= 180.0) ||
          !std::isfinite(o.light->phi_deg))
        fail("light direction: polar angle in [0, 180] degrees and a finite azimuth");
      for (double e : o.light->irradiance)
        if (!(e >= 0.0) || !std::isfinite(e)) fail("light irradiance must be finite and ≥ 0");
    }
  }

  void SetUpPixels() {
    const PreviewOptions& o = options;
    const double rot = DegToRad(o.environment_rotation_deg);
    cos_rotation = std::cos(rot);
    sin_rotation = std::sin(rot);
    const Vec3 c = SphericalDirectionDeg(o.camera.theta_deg, o.camera.phi_deg);
    forward = c * -1.0;
    right = detail::Cross(forward, Vec3{0, 0, 1});
    if (detail::Length(right) < 1e-9) {  // looking straight down or up: keep φ's sense
      const double phi = DegToRad(o.camera.phi_deg);
      right = {-std::sin(phi), std::cos(phi), 0.0};
    }
    right = Normalize(right);
    up = detail::Cross(right, forward);
    aspect = static_cast<double>(o.width) / o.height;
    perspective = o.camera.projection == Camera::Projection::kPerspective;
    const double half_fov = DegToRad(o.camera.fov_deg) * 0.5;
    // The unit bounding sphere's diameter spans `fill` of the frame height.
    ortho_half_height = 1.0 / o.camera.fill;
    const double distance =
        perspective ? 1.0 / std::sin(std::atan(std::tan(half_fov) * o.camera.fill)) : 10.0;
    tan_half = std::tan(half_fov);
    eye = c * distance;

    const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
    object.assign(pixels, 0);
    const std::vector<std::uint8_t> wanted = WantedPixels();
    ParallelChunks(static_cast<std::size_t>(o.height), 8, jobs, nullptr,
                   [&](std::size_t y0, std::size_t y1) {
                     PixelSetup s;
                     Vec3 dir;
                     for (std::size_t p = y0 * o.width; p < y1 * o.width; ++p)
                       if ((wanted.empty() || wanted[p]) && Trace(p, &s, &dir)) object[p] = 1;
                   });
    std::size_t hits = 0;
    for (std::uint8_t b : object) hits += b;
    object_index.reserve(hits);
    for (std::size_t p = 0; p < pixels; ++p)
      if (object[p]) object_index.push_back(static_cast<std::uint32_t>(p));
    if (o.light) {
      const Vec3 light_dir = SphericalDirectionDeg(o.light->theta_deg, o.light->phi_deg);
      light.assign(hits, {0.0f, 0.0f, 0.0f});
      ParallelChunks(hits, 256, jobs, nullptr, [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) {
          const PixelSetup s = SetupOf(k);
          if (!(Dot(light_dir, s.geometric_normal) > 0.0)) continue;
          const Vec3 wi = s.frame.ToLocal(light_dir);
          if (wi.z > 0.0 && !scene.Occluded(ShadowOrigin(s), light_dir)) {
            const Rgb f = source.Eval(wi, s.wo);
            for (int ch = 0; ch < 3; ++ch)
              light[k][ch] = static_cast<float>(o.light->irradiance[ch] * f[ch] * wi.z);
          }
        }
      });
    }
    sum.assign(hits * 3, 0.0);
    const bool sampling = options.environment_lighting &&
                          options.estimator != Estimator::kQuadrature &&
                          options.estimator != Estimator::kHierarchical &&
                          options.estimator != Estimator::kEngineSplitSum;
    if (sampling) sum_sq.assign(hits, 0.0);
  }

  // PreviewOptions::pixel_subset as a mask over the image's pixels (empty: every pixel).
  std::vector<std::uint8_t> WantedPixels() const {
    std::vector<std::uint8_t> wanted;
    if (options.pixel_subset.empty()) return wanted;
    const std::size_t pixels = static_cast<std::size_t>(options.width) * options.height;
    wanted.assign(pixels, 0);
    for (std::uint32_t p : options.pixel_subset)
      if (p < pixels) wanted[p] = 1;
    return wanted;
  }

  // The camera ray through image pixel p (its direction in `dir`) and what it hits.
  bool Trace(std::size_t p, PixelSetup* s, Vec3* dir) const {
    const PreviewOptions& o = options;
    const std::size_t x = p % o.width, y = p / o.width;
    const double sx = ((x + 0.5) / o.width * 2.0 - 1.0) * aspect;
    const double sy = 1.0 - (y + 0.5) / o.height * 2.0;
    Vec3 origin;
    if (perspective) {
      origin = eye;
      *dir = Normalize(forward + right * (sx * tan_half) + up * (sy * tan_half));
    } else {
      origin = eye + right * (sx * ortho_half_height) + up * (sy * ortho_half_height);
      *dir = forward;
    }
    detail::Hit hit;
    if (!scene.Intersect(origin, *dir, &hit)) return false;
    s->position = hit.position;
    s->geometric_normal = hit.geometric_normal;
    s->frame = Frame::FromNormal(hit.normal);
    s->wo = s->frame.ToLocal(*dir * -1.0);
    return true;
  }
  // The set-up of object pixel k (SetUpPixels found that its ray hits).
  PixelSetup SetupOf(std::size_t k) const {
    PixelSetup s;
    Vec3 dir;
    Trace(object_index[k], &s, &dir);
    return s;
  }
  std::size_t ObjectPixels() const { return object_index.size(); }

  static Vec3 ShadowOrigin(const PixelSetup& s) { return s.position + s.geometric_normal * 1e-6; }

  // L_env · f · cos / pdf for world direction w (0 when below the surface or shadowed).
  Rgb Incident(const PixelSetup& s, const Vec3& w, const Vec3& wi, const Rgb& radiance) const {
    if (!(wi.z > 0.0) || Dot(w, s.geometric_normal) <= 0.0) return {0, 0, 0};
    if (radiance[0] == 0.0 && radiance[1] == 0.0 && radiance[2] == 0.0) return {0, 0, 0};
    const Rgb f = source.Eval(wi, s.wo);
    if (f[0] == 0.0 && f[1] == 0.0 && f[2] == 0.0) return {0, 0, 0};
    if (scene.Occluded(ShadowOrigin(s), w)) return {0, 0, 0};
    return {radiance[0] * f[0] * wi.z, radiance[1] * f[1] * wi.z, radiance[2] * f[2] * wi.z};
  }

  Rgb EstimateOnce(std::size_t k, const PixelSetup& s, int pass, const Kronecker& sequence) const {
    const std::uint64_t key = Mix(options.seed ^ Mix(object_index[k]));
    std::array<double, 5> u;
    for (int d = 0; d < 5; ++d) {
      const double shift = ToUnit(Mix(key + static_cast<std::uint64_t>(d) * 0x632be59bd9b4e019ull));
      double x = shift + pass * sequence.alpha[d];
      u[d] = x - std::floor(x);
    }
    Rgb out = {0, 0, 0};
    const Estimator e = options.estimator;
    if (e != Estimator::kBrdf) {
      Vec3 m;
      double pe = 0;
      if (environment_sampler->Sample(u[0], u[1], &m, &pe)) {
        const Vec3 w = FromMap(m);
        const Vec3 wi = s.frame.ToLocal(w);
        const float* px = nullptr;
        int i = 0, j = 0;
        detail::MapPixelOf(environment, m, &i, &j);
        px = environment.Pixel(i, j);
        const Rgb c = Incident(s, w, wi, {px[0], px[1], px[2]});
        if (c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0) {
          double weight = 1.0 / pe;
          if (e == Estimator::kMis) {
            const double pb = sampler->Pdf(s.wo, wi);
            weight = pe / (pe * pe + pb * pb);  // power heuristic pe²/(pe²+pb²), over pe
          }
          for (int ch = 0; ch < 3; ++ch) out[ch] += c[ch] * weight;
        }
      }
    }
    if (e != Estimator::kEnvironment) {
      Vec3 wi;
      double pb = 0;
      if (sampler->Sample(s.wo, u[2], u[3], u[4], &wi, &pb)) {
        const Vec3 w = s.frame.ToWorld(wi);
        const Vec3 m = ToMap(w);
        const Rgb c = Incident(s, w, wi, environment.Radiance(m));
        if (c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0) {
          double weight = 1.0 / pb;
          if (e == Estimator::kMis) {
            const double pe = environment_sampler->Pdf(m);
            weight = pb / (pb * pb + pe * pe);
          }
          for (int ch = 0; ch < 3; ++ch) out[ch] += c[ch] * weight;
        }
      }
    }
    return out;
  }

  int RenderPasses(int count) {
    if (count < 1) return 0;
    if (exact) return 0;
    const auto start = std::chrono::steady_clock::now();
    pass_start = start;
    const std::atomic<bool>* cancel = options.cancel;
    if (!options.environment_lighting) {  // the directional light alone is already exact
      exact = true;
      passes = 1;
      return 1;
    }
    if (options.estimator == Estimator::kQuadrature ||
        options.estimator == Estimator::kHierarchical ||
        options.estimator == Estimator::kEngineSplitSum) {
      if (options.estimator == Estimator::kQuadrature)
        Quadrature();
      else if (options.estimator == Estimator::kEngineSplitSum)
        SplitSum();
      else
        Hierarchical();
      if (cancel != nullptr && cancel->load()) return 0;
      exact = true;
      passes = 1;
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return 1;
    }
    static const Kronecker kSequence;
    std::vector<double> call_sum(sum.size(), 0.0), call_sq(sum_sq.size(), 0.0);
    const int first = passes;
    ParallelChunks(ObjectPixels(), 128, jobs, cancel, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const PixelSetup s = SetupOf(k);
        for (int n = 0; n < count; ++n) {
          const Rgb v = EstimateOnce(k, s, first + n, kSequence);
          for (int ch = 0; ch < 3; ++ch) call_sum[3 * k + ch] += v[ch];
          const double l = Luminance(v);
          call_sq[k] += l * l;
        }
      }
    });
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (cancel != nullptr && cancel->load()) return 0;
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += call_sum[i];
    for (std::size_t i = 0; i < sum_sq.size(); ++i) sum_sq[i] += call_sq[i];
    passes += count;
    return count;
  }

  // The engines' split sum (PreviewOptions::engine_ibl): two probe lookups per pixel.
  void SplitSum() {
    const detail::SplitSumLighting lighting(environment);
    const IblPack& pack = *options.engine_ibl;
    PassFraction progress(options, ObjectPixels(), pass_start);
    ParallelChunks(
        ObjectPixels(), 64, jobs, options.cancel,
        [&](std::size_t b, std::size_t e) {
          for (std::size_t k = b; k < e; ++k) {
            const PixelSetup s = SetupOf(k);
            const double mu = std::clamp(s.wo.z, 0.0, 1.0);
            const Vec3 n = s.frame.n;
            const Vec3 wo = s.frame.ToWorld(s.wo);
            const IblPack::Row row = pack.At(mu);
            const Vec3 r = IblSpecularDirection(n, wo, row.alpha);
            const Rgb irradiance =
                pack.broad_alpha >= 1.0
                    ? lighting.Irradiance(ToMap(n))
                    : lighting.Prefiltered(pack.broad_alpha,
                                           ToMap(IblBroadDirection(n, wo, pack.broad_alpha)));
            const Rgb prefiltered = lighting.Prefiltered(row.alpha, ToMap(r));
            for (int ch = 0; ch < 3; ++ch)
              sum[3 * k + ch] =
                  row.diffuse[ch] * irradiance[ch] + row.specular[ch] * prefiltered[ch];
          }
          progress.Add(e - b);
        },
        progress.Reporter());
    progress.Finish();
  }

  // Σ over map pixels (split n × n, midpoint rule in solid angle) of L · f · cos · ΔΩ. The
  // directions are made from per-row and per-column sines and cosines as they are needed (a
  // table of all of them held 48 bytes per map pixel and subdivision², 6 GB for a 1024 × 512
  // map at 16 subdivisions); the products are SphericalDirection's, in the same order.
  void Quadrature() {
    const int n = options.quadrature_subdivisions;
    const int width = environment.width(), height = environment.height();
    struct SubRow {
      double sin_theta, cos_theta, solid_angle;
    };
    std::vector<SubRow> rows;
    for (int j = 0; j < height; ++j)
      for (int a = 0; a < n; ++a) {
        const double t0 = (j + static_cast<double>(a) / n) * kPi / height;
        const double t1 = (j + static_cast<double>(a + 1) / n) * kPi / height;
        const double theta = 0.5 * (t0 + t1);
        rows.push_back({std::sin(theta), std::cos(theta),
                        (std::cos(t0) - std::cos(t1)) * 2.0 * kPi / (width * n)});
      }
    std::vector<double> sin_phi, cos_phi;
    for (int i = 0; i < width; ++i)
      for (int b = 0; b < n; ++b) {
        const double phi = (i + (b + 0.5) / n) * 2.0 * kPi / width;
        sin_phi.push_back(std::sin(phi));
        cos_phi.push_back(std::cos(phi));
      }
    std::atomic<std::uint64_t> counted{0};
    PassFraction progress(options, ObjectPixels(), pass_start);
    ParallelChunks(
        ObjectPixels(), 16, jobs, options.cancel,
        [&](std::size_t b0, std::size_t e0) {
          std::uint64_t count = 0;
          for (std::size_t k = b0; k < e0; ++k) {
            const PixelSetup s = SetupOf(k);
            Rgb total = {0, 0, 0};
            for (int j = 0; j < height; ++j)
              for (int a = 0; a < n; ++a) {
                const SubRow& row = rows[static_cast<std::size_t>(j) * n + a];
                for (int i = 0; i < width; ++i) {
                  const float* px = environment.Pixel(i, j);
                  if (px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f) continue;
                  const Rgb e = {px[0] * row.solid_angle, px[1] * row.solid_angle,
                                 px[2] * row.solid_angle};
                  for (int b = 0; b < n; ++b) {
                    const std::size_t c = static_cast<std::size_t>(i) * n + b;
                    const Vec3 w = FromMap(
                        {row.sin_theta * cos_phi[c], row.sin_theta * sin_phi[c], row.cos_theta});
                    const Vec3 wi = s.frame.ToLocal(w);
                    if (!(wi.z > 0.0)) continue;
                    const Rgb f = source.Eval(wi, s.wo);
                    ++count;
                    for (int ch = 0; ch < 3; ++ch) total[ch] += e[ch] * f[ch] * wi.z;
                  }
                }
              }
            for (int ch = 0; ch < 3; ++ch) sum[3 * k + ch] = total[ch];
          }
          counted += count;
          progress.Add(e0 - b0);
        },
        progress.Reporter());
    progress.Finish();
    evaluations = counted;
  }

  // The fast path (Estimator::kHierarchical, hierarchical.h): the adaptive map quadrature per
  // computed pixel, bilinear interpolation over image blocks that pass the midpoint checks.
  void Hierarchical() {
    const detail::MapHierarchy hierarchy(environment, kHierarchyTopColumns, jobs);
    detail::HierarchicalSettings settings;
    settings.tolerance = options.hierarchical_tolerance;
    // The source's faster approximation when it has one (an RGL file's tabulated form,
    // brdf/core/rgl.h RglTabulatedBrdf: docs/preview.md states its deviation).
    const std::unique_ptr<BrdfSource> approximation = source.QuadratureApproximation();
    if (approximation) evaluated_as = approximation->Name();
    const detail::HierarchicalIntegrator integrator(
        hierarchy, approximation ? *approximation : source, settings);
    std::atomic<std::uint64_t> counted{0}, computed_pixels{0};
    auto radiance = [&](std::size_t k, double scale, bool top_only, std::uint64_t* count) {
      const PixelSetup s = SetupOf(k);
      return integrator.Radiance(ToMap(s.frame.s), ToMap(s.frame.t), ToMap(s.frame.n), s.wo, scale,
                                 top_only, count);
    };
    // The scale the tolerances are relative to: the mean absolute object luminance, from the
    // top level's estimate at about 1000 pixels spread over the object (absolute, so that the
    // refinement and its cost do not depend on the values' sign).
    const std::size_t stride = std::max<std::size_t>(1, ObjectPixels() / 1024);
    std::vector<double> sample((ObjectPixels() + stride - 1) / stride, 0.0);
    ParallelChunks(sample.size(), 64, jobs, options.cancel, [&](std::size_t b, std::size_t e) {
      std::uint64_t count = 0;
      for (std::size_t k = b; k < e; ++k)
        sample[k] = Luminance(radiance(k * stride, 0.0, true, &count));
      counted += count;
    });
    double scale = 0.0;
    for (double y : sample) scale += std::fabs(y);
    scale /= std::max<std::size_t>(1, sample.size());
    auto compute = [&](std::size_t k, std::uint64_t* count) {
      ++computed_pixels;
      return radiance(k, scale, false, count);
    };
    auto store = [&](std::size_t k, const Rgb& v) {
      for (int ch = 0; ch < 3; ++ch) sum[3 * k + ch] = v[ch];
    };
    const int block = options.image_block;
    // Progress counts the object pixels of finished blocks (the lattice pass before them is
    // about 1/block² of the work).
    PassFraction progress(options, ObjectPixels(), pass_start);
    if (block <= 1) {
      ParallelChunks(
          ObjectPixels(), 64, jobs, options.cancel,
          [&](std::size_t b, std::size_t e) {
            std::uint64_t count = 0;
            for (std::size_t k = b; k < e; ++k) store(k, compute(k, &count));
            counted += count;
            progress.Add(e - b);
          },
          progress.Reporter());
      progress.Finish();
      evaluations = counted;
      computed_count = computed_pixels;
      return;
    }
    const int width = options.width, height = options.height;
    std::vector<std::int32_t> index(object.size(), -1);  // image pixel → object pixel
    for (std::size_t k = 0; k < object_index.size(); ++k)
      index[object_index[k]] = static_cast<std::int32_t>(k);
    auto object_at = [&](int x, int y) { return index[static_cast<std::size_t>(y) * width + x]; };
    // The value of each object pixel, computed or interpolated, is kept in `sum` (image pixel
    // g is object pixel index[g]).
    auto value = [&](std::size_t g) -> double* {
      return &sum[3 * static_cast<std::size_t>(index[g])];
    };
    auto load = [&](std::size_t g) {
      const double* v = value(g);
      return Rgb{v[0], v[1], v[2]};
    };
    // Phase 1: every object pixel on the lattice x, y ≡ 0 (mod block).
    const int lattice_rows = (height + block - 1) / block;
    ParallelChunks(static_cast<std::size_t>(lattice_rows), 1, jobs, options.cancel,
                   [&](std::size_t b, std::size_t e) {
                     std::uint64_t count = 0;
                     for (std::size_t r = b; r < e; ++r) {
                       const int y = static_cast<int>(r) * block;
                       for (int x = 0; x < width; x += block)
                         if (const int k = object_at(x, y); k >= 0) store(k, compute(k, &count));
                     }
                     counted += count;
                   });
    // image_tolerance holds at 512 pixels across and scales with the size (preview.h): the
    // biquadratic fill's error relative to the midpoints' deviation from the bilinear grows
    // with the block's angular size, which is larger in a smaller image.
    const double tolerance = options.image_tolerance * scale *
                             std::min(options.width, options.height) / kImageToleranceSize;
    // Phase 2: each block owns its pixels [x0, x0 + block) × [y0, y0 + block) and reads its
    // far edges too. A pixel integrated by one block is integrated once: `integrated` keeps it for
    // the neighbours sharing that edge. Blocks run in four passes by the parity of their row and
    // column, each block by one thread, so two blocks that run at the same time never share a
    // pixel, and the threads end a pass within about one block of each other (with whole block
    // rows as the unit, a few of which carry most of the work, one thread sat idle at the end of
    // each pass). The order does not change the result: a pixel's integral is the same whichever
    // block computes it, and a block decides from its own pixels' values alone.
    const int block_columns = (width + block - 1) / block;
    std::vector<std::size_t> block_pixels(static_cast<std::size_t>(lattice_rows) * block_columns,
                                          0);
    for (std::uint32_t p : object_index)
      ++block_pixels[p / width / block * block_columns + p % width / block];
    // Only pixels on the lattice's lines (x or y ≡ 0 mod block) are shared between blocks, so
    // only they keep their integral here: a row of slots per lattice row, then a column of slots
    // per lattice column for the pixels not on a lattice row.
    const std::size_t row_slots = static_cast<std::size_t>(lattice_rows) * width;
    std::vector<Rgb> integrated(row_slots + static_cast<std::size_t>(block_columns) * height,
                                Rgb{0, 0, 0});
    std::vector<std::uint8_t> has_integral(integrated.size(), 0);
    auto slot = [&](int x, int y) -> std::size_t {
      if (y % block == 0) return static_cast<std::size_t>(y / block) * width + x;
      if (x % block == 0) return row_slots + static_cast<std::size_t>(x / block) * height + y;
      return std::size_t(-1);
    };
    for (int c = 0; c < block_columns; ++c)
      for (int r = 0; r < lattice_rows; ++r)
        if (const std::size_t g = static_cast<std::size_t>(r) * block * width + c * block;
            index[g] >= 0) {
          const std::size_t q = slot(c * block, r * block);
          integrated[q] = load(g);
          has_integral[q] = 1;
        }
    for (int pass = 0; pass < 4; ++pass) {
      const int row_parity = pass / 2, column_parity = pass % 2;
      const std::size_t pass_columns = (block_columns + 1 - column_parity) / 2;
      // Task k of the pass: the block at this column and row of the block lattice.
      auto column_of = [&](std::size_t task) {
        return 2 * static_cast<int>(task % pass_columns) + column_parity;
      };
      auto row_of = [&](std::size_t task) { return 2 * (task / pass_columns) + row_parity; };
      ParallelChunks(
          (lattice_rows + 1 - row_parity) / 2 * pass_columns, 1, jobs, options.cancel,
          [&](std::size_t b, std::size_t e) {
            std::uint64_t count = 0;
            const int side = block + 1;
            std::vector<Rgb> local(static_cast<std::size_t>(side) * side);
            std::vector<std::uint8_t> known(local.size());
            for (std::size_t task = b; task < e; ++task) {
              const int c = column_of(task);
              const std::size_t r = row_of(task);
              const int x0 = c * block, y0 = static_cast<int>(r) * block;
              auto inside = [&](int dx, int dy) {
                return x0 + dx < width && y0 + dy < height && object_at(x0 + dx, y0 + dy) >= 0;
              };
              auto at = [&](int dx, int dy) -> Rgb& { return local[dy * side + dx]; };
              // known: 0 nothing, 1 computed (exact), 2 interpolated.
              std::fill(known.begin(), known.end(), 0);
              for (int dy : {0, block})
                for (int dx : {0, block})
                  if (inside(dx, dy)) {
                    at(dx, dy) = load(static_cast<std::size_t>(y0 + dy) * width + x0 + dx);
                    known[dy * side + dx] = 1;
                  }
              // The integral at (dx, dy), from `integrated` when another block integrated it (a
              // pixel inside the block is integrated at most once, `known` says when).
              Rgb fresh;
              auto integral = [&](int dx, int dy) -> const Rgb& {
                const std::size_t q = slot(x0 + dx, y0 + dy);
                if (q == std::size_t(-1)) {
                  fresh = compute(object_at(x0 + dx, y0 + dy), &count);
                  return fresh;
                }
                if (!has_integral[q]) {
                  integrated[q] = compute(object_at(x0 + dx, y0 + dy), &count);
                  has_integral[q] = 1;
                }
                return integrated[q];
              };
              auto computed = [&](int dx, int dy) -> const Rgb& {
                if (known[dy * side + dx] != 1) {
                  at(dx, dy) = integral(dx, dy);
                  known[dy * side + dx] = 1;
                }
                return at(dx, dy);
              };
              auto close = [&](const Rgb& got, const Rgb& a, const Rgb& b2) {
                for (int ch = 0; ch < 3; ++ch)
                  if (std::fabs(got[ch] - 0.5 * (a[ch] + b2[ch])) > tolerance) return false;
                return true;
              };
              // The square at (dx, dy) of `size`, all of it on the object, corners computed:
              // interpolated when its centre and edge midpoints pass, else split in four.
              auto refine = [&](auto&& self, int dx, int dy, int size) -> void {
                if (size <= 1) return;
                const int h = size / 2;
                const Rgb c00 = at(dx, dy), c10 = at(dx + size, dy), c01 = at(dx, dy + size),
                          c11 = at(dx + size, dy + size);
                const Rgb diagonal = {0.5 * (c00[0] + c11[0]), 0.5 * (c00[1] + c11[1]),
                                      0.5 * (c00[2] + c11[2])};
                const Rgb other = {0.5 * (c10[0] + c01[0]), 0.5 * (c10[1] + c01[1]),
                                   0.5 * (c10[2] + c01[2])};
                bool ok = close(computed(dx + h, dy), c00, c10);
                ok = close(computed(dx, dy + h), c00, c01) && ok;
                ok = close(computed(dx + size, dy + h), c10, c11) && ok;
                ok = close(computed(dx + h, dy + size), c01, c11) && ok;
                ok = close(computed(dx + h, dy + h), diagonal, other) && ok;
                if (!ok || h == 1) {
                  for (int qy : {dy, dy + h})
                    for (int qx : {dx, dx + h}) self(self, qx, qy, h);
                  return;
                }
                // Biquadratic through the nine computed points over the whole square: they
                // passed the check, so the image is smooth here, and the quadratic's error is of
                // third order in the square's size where the bilinear's is of second order
                // (at the default tolerance, half the interpolation error for the same pixels;
                // docs/benchmarks.md).
                Rgb node[3][3];
                for (int row = 0; row < 3; ++row)
                  for (int col = 0; col < 3; ++col) node[row][col] = at(dx + col * h, dy + row * h);
                // The Lagrange basis of the nodes 0, ½, 1.
                auto basis = [](double u, double* l) {
                  l[0] = 2.0 * (u - 0.5) * (u - 1.0);
                  l[1] = -4.0 * u * (u - 1.0);
                  l[2] = 2.0 * u * (u - 0.5);
                };
                for (int y = 0; y <= size; ++y) {
                  double lv[3];
                  basis(static_cast<double>(y) / size, lv);
                  for (int x = 0; x <= size; ++x) {
                    if (known[(dy + y) * side + dx + x]) continue;
                    double lu[3];
                    basis(static_cast<double>(x) / size, lu);
                    Rgb& out = at(dx + x, dy + y);
                    for (int ch = 0; ch < 3; ++ch) {
                      double v = 0.0;
                      for (int row = 0; row < 3; ++row)
                        for (int col = 0; col < 3; ++col)
                          v += lv[row] * lu[col] * node[row][col][ch];
                      out[ch] = v;
                    }
                    known[(dy + y) * side + dx + x] = 2;
                  }
                }
              };
              // The rim and the image edges: the largest squares wholly on the object are refined
              // as above; what is left is computed pixel by pixel below.
              auto cover = [&](auto&& self, int dx, int dy, int size) -> void {
                bool whole = true;
                for (int y = dy; whole && y <= dy + size; ++y)
                  for (int x = dx; whole && x <= dx + size; ++x) whole = inside(x, y);
                if (whole) {
                  for (int qy : {dy, dy + size})
                    for (int qx : {dx, dx + size}) computed(qx, qy);
                  refine(refine, dx, dy, size);
                } else if (size > 2) {
                  const int h = size / 2;
                  for (int qy : {dy, dy + h})
                    for (int qx : {dx, dx + h}) self(self, qx, qy, h);
                }
              };
              cover(cover, 0, 0, block);
              for (int dy = 0; dy < block; ++dy)
                for (int dx = 0; dx < block; ++dx) {
                  if ((dx == 0 && dy == 0) || !inside(dx, dy)) continue;  // lattice corner, or off
                  const Rgb v = known[dy * side + dx] ? at(dx, dy) : integral(dx, dy);
                  double* out = value(static_cast<std::size_t>(y0 + dy) * width + x0 + dx);
                  for (int ch = 0; ch < 3; ++ch) out[ch] = v[ch];
                }
            }
            counted += count;
            for (std::size_t task = b; task < e; ++task)
              progress.Add(block_pixels[row_of(task) * block_columns + column_of(task)]);
          },
          progress.Reporter());
    }
    progress.Finish();
    evaluations = counted;
    computed_count = computed_pixels;
  }

  double RelativeRms() const {
    if (exact) return 0.0;
    if (passes < 4 || object_index.empty()) return std::numeric_limits<double>::infinity();
    const double n = passes;
    double variance = 0.0, mean = 0.0;
    for (std::size_t k = 0; k < ObjectPixels(); ++k) {
      const double l = Luminance({sum[3 * k] / n, sum[3 * k + 1] / n, sum[3 * k + 2] / n});
      mean += l;
      variance += std::max(0.0, (sum_sq[k] / n - l * l) / (n - 1.0));  // of the mean
    }
    mean /= static_cast<double>(ObjectPixels());
    variance /= static_cast<double>(ObjectPixels());
    if (!(mean > 0.0)) return variance > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
    return std::sqrt(variance) / mean;
  }

  PreviewImage Image() const {
    PreviewImage image;
    image.width = options.width;
    image.height = options.height;
    const std::size_t pixels = object.size();
    image.rgb.assign(pixels * 3, 0.0f);
    image.object = object;
    // The background where the rays miss (looked up again: it is the map's radiance, no
    // integral), the directional light's share and the passes' mean where they hit.
    if (options.show_background) {
      const std::vector<std::uint8_t> wanted = WantedPixels();
      ParallelChunks(static_cast<std::size_t>(options.height), 8, jobs, nullptr,
                     [&](std::size_t y0, std::size_t y1) {
                       PixelSetup s;
                       Vec3 dir;
                       for (std::size_t p = y0 * options.width; p < y1 * options.width; ++p) {
                         if (object[p] || (!wanted.empty() && !wanted[p])) continue;
                         Trace(p, &s, &dir);
                         const Rgb c = environment.Radiance(ToMap(dir));
                         for (int ch = 0; ch < 3; ++ch)
                           image.rgb[3 * p + ch] = static_cast<float>(c[ch]);
                       }
                     });
    }
    for (std::size_t k = 0; k < light.size(); ++k)
      for (int ch = 0; ch < 3; ++ch) image.rgb[3 * object_index[k] + ch] = light[k][ch];
    if (passes > 0 && options.environment_lighting)
      for (std::size_t k = 0; k < ObjectPixels(); ++k)
        for (int ch = 0; ch < 3; ++ch)
          image.rgb[3 * object_index[k] + ch] += static_cast<float>(sum[3 * k + ch] / passes);
    image.samples_per_pixel = passes;
    image.estimator = options.estimator;
    image.brdf_evaluations = evaluations;
    image.computed_pixels = exact ? (computed_count > 0 ? computed_count : ObjectPixels()) : 0;
    image.evaluated_as = evaluated_as;
    image.relative_rms_estimate = RelativeRms();
    image.seconds = seconds;
    return image;
  }
};

PreviewRenderer::PreviewRenderer(const BrdfSource& source, const EnvironmentMap& environment,
                                 PreviewOptions options, std::shared_ptr<const BrdfSampler> sampler)
    : impl_(std::make_unique<Impl>(source, environment, std::move(options), std::move(sampler))) {
  const auto start = std::chrono::steady_clock::now();
  if (impl_->options.engine_ibl != nullptr)
    impl_->options.estimator = Estimator::kEngineSplitSum;
  else if (impl_->options.estimator == Estimator::kEngineSplitSum)
    throw InvalidArgument("preview: the engine split sum needs PreviewOptions::engine_ibl");
  if (impl_->options.estimator == Estimator::kAuto)
    impl_->options.estimator =
        impl_->options.shape == Shape::kSphere ? Estimator::kHierarchical : Estimator::kMis;
  impl_->Validate();
  // Refused before any work rather than killed half-way by the kernel.
  if (const auto available = QueryAvailableMemory()) {
    const std::uint64_t needed = EstimatedPeakBytes(impl_->options, environment);
    if (needed > available->bytes)
      throw InvalidArgument("preview: a " + std::to_string(impl_->options.width) + " × " +
                            std::to_string(impl_->options.height) + " image under a " +
                            std::to_string(environment.width()) + " × " +
                            std::to_string(environment.height()) + " map needs about " +
                            MemoryText(needed) + " of memory, more than the " +
                            MemoryText(available->bytes) + " this process can take (" +
                            available->limited_by + "); a smaller image would fit");
  }
  impl_->jobs = ResolveJobs(impl_->options.jobs);
  const bool sampling = impl_->options.environment_lighting &&
                        impl_->options.estimator != Estimator::kQuadrature &&
                        impl_->options.estimator != Estimator::kHierarchical &&
                        impl_->options.estimator != Estimator::kEngineSplitSum;
  if (sampling) {
    if (impl_->sampler == nullptr) impl_->sampler = MakeBrdfSampler(source, impl_->jobs);
    impl_->environment_sampler = std::make_unique<EnvironmentSampler>(environment);
  }
  impl_->SetUpPixels();
  impl_->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
PreviewRenderer::~PreviewRenderer() = default;

int PreviewRenderer::RenderPasses(int passes) { return impl_->RenderPasses(passes); }
int PreviewRenderer::passes() const { return impl_->passes; }
PreviewImage PreviewRenderer::Image() const { return impl_->Image(); }
double PreviewRenderer::EstimatedRelativeRms() const { return impl_->RelativeRms(); }
const std::shared_ptr<const BrdfSampler>& PreviewRenderer::sampler() const {
  return impl_->sampler;
}

std::uint64_t EstimatedPeakBytes(const PreviewOptions& options, const EnvironmentMap& environment) {
  Estimator e = options.estimator;
  if (options.engine_ibl != nullptr) e = Estimator::kEngineSplitSum;
  if (e == Estimator::kAuto)
    e = options.shape == Shape::kSphere ? Estimator::kHierarchical : Estimator::kMis;
  const bool sampling = options.environment_lighting && e != Estimator::kQuadrature &&
                        e != Estimator::kHierarchical && e != Estimator::kEngineSplitSum;
  // Per image pixel, every pixel counted as an object pixel (an upper bound): the mask (1),
  // the object index (4), the RGB sums (24), the image made at the end (13).
  std::uint64_t per_pixel = 1 + 4 + 24 + 13;
  if (options.light) per_pixel += 12;
  if (sampling) per_pixel += 8 + 32;  // luminance², and one call's sums while it runs
  if (e == Estimator::kHierarchical) {
    per_pixel += 4;  // image pixel → object pixel
    // The integrals kept on the block lattice's lines: 25 bytes for 2/block of the pixels.
    per_pixel += 50 / std::max(1, options.image_block);
  }
  const std::uint64_t pixels = static_cast<std::uint64_t>(std::max(0, options.width)) *
                               static_cast<std::uint64_t>(std::max(0, options.height));
  std::uint64_t bytes = pixels * per_pixel;
  const std::uint64_t map_pixels =
      static_cast<std::uint64_t>(environment.width()) * environment.height();
  // The hierarchy: 64-byte cells, 1/3 of a cell per map pixel over the stored levels (level 0
  // is made from the map when asked for), and the 64-byte sums of the level being built (a
  // quarter of a pixel's).
  if (e == Estimator::kHierarchical) bytes += map_pixels * (64 / 3 + 16);
  if (e == Estimator::kEngineSplitSum) bytes += map_pixels * 24;  // the prefiltered pyramid
  if (options.pixel_subset.size() > 0) bytes += pixels;           // the subset's mask
  return bytes;
}

Camera DefaultCamera(Shape shape) {
  Camera camera;
  if (shape == Shape::kPlane) camera.theta_deg = 60.0;
  return camera;
}

void SelectShape(const std::string& name, Mesh* mesh, PreviewOptions* options) {
  if (name == "sphere") {
    options->shape = Shape::kSphere;
  } else if (name == "plane") {
    options->shape = Shape::kPlane;
  } else {
    *mesh = LoadMesh(name);
    options->shape = Shape::kMesh;
    options->mesh = mesh;
  }
  options->camera = DefaultCamera(options->shape);
}

PreviewImage RenderPreview(const BrdfSource& source, const EnvironmentMap& environment,
                           const PreviewOptions& options) {
  PreviewRenderer renderer(source, environment, options);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const bool by_rms = options.target_relative_rms > 0.0;
  const int limit = by_rms ? options.max_samples_per_pixel : options.samples_per_pixel;
  int batch = 1;
  while (renderer.passes() < limit) {
    if (options.cancel != nullptr && options.cancel->load()) break;
    const double t0 = elapsed();
    const int done = renderer.RenderPasses(std::min(batch, limit - renderer.passes()));
    if (done == 0) break;  // cancelled, or exact after one pass
    const double per_pass = (elapsed() - t0) / done;
    const double rms = renderer.EstimatedRelativeRms();
    if (options.progress && !options.progress(renderer.passes(), rms, elapsed())) break;
    if (by_rms && rms <= options.target_relative_rms) break;
    // About four progress reports a second.
    batch = std::clamp(static_cast<int>(0.25 / std::max(per_pass, 1e-6)), 1, 256);
    if (by_rms && std::isfinite(rms) && rms > 0.0) {
      // rms ∝ 1/√n: do not overshoot the passes the target needs by much.
      const double needed = renderer.passes() * (rms / options.target_relative_rms) *
                            (rms / options.target_relative_rms);
      batch = std::clamp(static_cast<int>(needed) - renderer.passes() + 1, 1, batch);
    }
    if (by_rms && renderer.passes() < 4) batch = 4 - renderer.passes();
  }
  return renderer.Image();
}

}  // namespace brdf::preview
