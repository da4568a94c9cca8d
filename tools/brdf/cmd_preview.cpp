// `brdf preview SOURCE [--compare SOURCE2] --out IMAGE.exr|.png`: renders a source on a sphere,
// a plane or a mesh under an environment map (brdf::preview), prints the RMS difference with
// --compare, shows progress with an ETA on stderr.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/preview/preview.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"
#include "progress.h"

namespace brdf::cli {
namespace {

bool ParsePair(const std::string& text, double* a, double* b) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) return false;
  try {
    std::size_t used = 0;
    *a = std::stod(text.substr(0, comma), &used);
    if (used != comma) return false;
    const std::string rest = text.substr(comma + 1);
    *b = std::stod(rest, &used);
    return used == rest.size() && std::isfinite(*a) && std::isfinite(*b);
  } catch (const std::exception&) {
    return false;
  }
}

preview::Estimator EstimatorFromName(const std::string& name) {
  if (name == "auto") return preview::Estimator::kAuto;
  if (name == "hierarchical") return preview::Estimator::kHierarchical;
  if (name == "mis") return preview::Estimator::kMis;
  if (name == "env") return preview::Estimator::kEnvironment;
  if (name == "brdf") return preview::Estimator::kBrdf;
  if (name == "quadrature") return preview::Estimator::kQuadrature;
  throw InvalidArgument(
      "--estimator: expected auto, hierarchical, mis, env, brdf or quadrature, got '" + name + "'");
}

const char* EstimatorName(preview::Estimator e) {
  switch (e) {
    case preview::Estimator::kHierarchical:
      return "hierarchical";
    case preview::Estimator::kQuadrature:
      return "quadrature";
    case preview::Estimator::kEnvironment:
      return "env";
    case preview::Estimator::kBrdf:
      return "brdf";
    case preview::Estimator::kEngineSplitSum:
      return "engine-split-sum";
    default:
      return "mis";
  }
}

// One line on stderr, redrawn on a terminal, at most one plain line a second otherwise.
class PassProgress {
 public:
  PassProgress(std::string label, bool enabled)
      : label_(std::move(label)), enabled_(enabled), tty_(::isatty(2) == 1) {}
  void Update(int passes, int target_passes, double rms, double target_rms, double seconds) {
    if (!enabled_) return;
    if (!tty_ && seconds - last_ < 1.0) return;
    last_ = seconds;
    double eta = 0;
    std::string what;
    if (target_rms > 0) {
      // The error falls as 1/√passes.
      const double needed =
          std::isfinite(rms) ? passes * (rms / target_rms) * (rms / target_rms) : 0;
      eta = needed > passes ? seconds / passes * (needed - passes) : 0;
      what = std::isfinite(rms) ? "error " + Percent(rms) + " → " + Percent(target_rms)
                                : "estimating the error";
    } else {
      eta = seconds / passes * (target_passes - passes);
      what = std::to_string(passes) + "/" + std::to_string(target_passes) + " passes";
    }
    std::fprintf(stderr, "%s%s: %s, %s elapsed, ETA %s%s", tty_ ? "\r\033[K" : "", label_.c_str(),
                 what.c_str(), Progress::FormatDuration(seconds).c_str(),
                 Progress::FormatDuration(eta).c_str(), tty_ ? "" : "\n");
    std::fflush(stderr);
  }
  // The one pass of a deterministic estimator: the fraction of the object's pixels done. On a
  // terminal the line is redrawn up to ten times a second; otherwise a plain line is printed at
  // each further 10 % or after a second, and always at 100 %.
  void UpdateFraction(double fraction, double seconds) {
    if (!enabled_) return;
    const int decile = static_cast<int>(fraction * 10.0 + 1e-9);
    const bool done = fraction >= 1.0;
    if (!done) {
      if (tty_ && seconds - last_ < 0.1) return;
      if (!tty_ && decile <= last_decile_ && seconds - last_ < 1.0) return;
    }
    if (done && printed_done_) return;
    last_ = seconds;
    last_decile_ = decile;
    printed_done_ = done;
    // The rate since the first report, so that the set-up before the first pixels (the map
    // hierarchy, the lattice pass) does not count as the pixels' cost.
    if (first_seconds_ < 0.0) {
      first_fraction_ = fraction;
      first_seconds_ = seconds;
    }
    const bool known = done || fraction > first_fraction_;
    const double eta =
        done    ? 0.0
        : known ? (seconds - first_seconds_) / (fraction - first_fraction_) * (1.0 - fraction)
                : 0.0;
    std::fprintf(stderr, "%s%s: %.0f %% of the pixels, %s elapsed, ETA %s%s",
                 tty_ ? "\r\033[K" : "", label_.c_str(), std::floor(100.0 * fraction),
                 Progress::FormatDuration(seconds).c_str(),
                 known ? Progress::FormatDuration(eta).c_str() : "--", tty_ ? "" : "\n");
    std::fflush(stderr);
  }
  void Done(const preview::PreviewImage& image, bool light_only) {
    if (!enabled_) return;
    if (light_only) {  // no integral over the map: one BRDF evaluation per pixel, exact
      std::size_t object = 0;
      for (std::uint8_t o : image.object) object += o;
      std::fprintf(stderr, "%s%s: the directional light only (exact), %zu object pixels, %s\n",
                   tty_ ? "\r\033[K" : "", label_.c_str(), object,
                   Progress::FormatDuration(image.seconds).c_str());
      return;
    }
    if (image.estimator == preview::Estimator::kEngineSplitSum) {
      std::fprintf(stderr,
                   "%s%s: the engine's split sum (IBL pack, SH irradiance, GGX-prefiltered "
                   "map), %s\n",
                   tty_ ? "\r\033[K" : "", label_.c_str(),
                   Progress::FormatDuration(image.seconds).c_str());
      return;
    }
    const bool deterministic = image.estimator == preview::Estimator::kHierarchical ||
                               image.estimator == preview::Estimator::kQuadrature;
    if (deterministic) {
      std::size_t object = 0;
      for (std::uint8_t o : image.object) object += o;
      const std::string of =
          image.evaluated_as.empty() ? std::string() : " of " + image.evaluated_as;
      std::fprintf(stderr,
                   "%s%s: %s quadrature, %llu BRDF evaluations%s, %llu of %zu object pixels "
                   "integrated (the rest interpolated), %s\n",
                   tty_ ? "\r\033[K" : "", label_.c_str(), EstimatorName(image.estimator),
                   static_cast<unsigned long long>(image.brdf_evaluations), of.c_str(),
                   static_cast<unsigned long long>(image.computed_pixels), object,
                   Progress::FormatDuration(image.seconds).c_str());
      return;
    }
    const double rms = image.relative_rms_estimate;
    std::fprintf(stderr, "%s%s: %d passes (%s), estimated error %s, %s\n", tty_ ? "\r\033[K" : "",
                 label_.c_str(), image.samples_per_pixel, EstimatorName(image.estimator),
                 std::isfinite(rms) ? Percent(rms).c_str() : "unknown",
                 Progress::FormatDuration(image.seconds).c_str());
  }

 private:
  static std::string Percent(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f %%", 100.0 * x);
    return buf;
  }
  std::string label_;
  bool enabled_, tty_;
  double last_ = -1.0;
  int last_decile_ = 0;
  double first_fraction_ = 0.0, first_seconds_ = -1.0;
  bool printed_done_ = false;
};

preview::PreviewImage Render(const BrdfSource& source, const preview::EnvironmentMap& map,
                             preview::PreviewOptions options, const PreviewCommandOptions& cli) {
  PassProgress progress("preview " + source.Name(), !cli.quiet);
  options.progress = [&](int passes, double rms, double seconds) {
    if (rms == 0.0) return true;  // a deterministic estimator: done in one pass, Done() reports
    progress.Update(passes, options.samples_per_pixel, rms, options.target_relative_rms, seconds);
    return true;
  };
  if (!cli.quiet)
    options.pass_progress = [&](double fraction, double seconds) {
      progress.UpdateFraction(fraction, seconds);
    };
  preview::PreviewImage image = preview::RenderPreview(source, map, options);
  progress.Done(image, !options.environment_lighting);
  return image;
}

}  // namespace

int RunPreview(const PreviewCommandOptions& cli) {
  const std::string ext = LowerExtension(cli.out);
  if (ext != ".exr" && ext != ".png")
    throw InvalidArgument("--out: expected an .exr (linear HDR) or .png (tone-mapped) file, got '" +
                          cli.out + "'");
  if (cli.size < 1 || cli.size > 8192)
    throw InvalidArgument("--size: expected 1 to 8192 pixels, got " + std::to_string(cli.size));
  preview::PreviewOptions options;
  options.width = options.height = cli.size;
  options.estimator = EstimatorFromName(cli.estimator);
  // A pass count or an error target asks for Monte Carlo.
  if (options.estimator == preview::Estimator::kAuto && (cli.spp_given || cli.rms > 0))
    options.estimator = preview::Estimator::kMis;
  options.quadrature_subdivisions = cli.subdivisions;
  if (cli.sample_pixels > 0) {
    // A fixed random choice of image pixels for this size (not the render seed), so that
    // references at different settings cover the same pixels.
    std::vector<std::uint32_t> all(static_cast<std::size_t>(cli.size) * cli.size);
    for (std::size_t p = 0; p < all.size(); ++p) all[p] = static_cast<std::uint32_t>(p);
    std::mt19937_64 shuffle(0x5eed);
    std::shuffle(all.begin(), all.end(), shuffle);
    all.resize(std::min(all.size(), static_cast<std::size_t>(cli.sample_pixels)));
    options.pixel_subset = std::move(all);
  }
  options.samples_per_pixel = cli.spp;
  options.target_relative_rms = cli.rms;
  options.jobs = cli.jobs;
  options.seed = cli.seed;
  options.environment_rotation_deg = cli.env_rotation_deg;
  double a = 0, b = 0;
  preview::Mesh mesh;
  preview::SelectShape(cli.mesh, &mesh, &options);
  if (!cli.view.empty()) {
    if (!ParsePair(cli.view, &a, &b) || a < 0 || a > 180)
      throw InvalidArgument("--view: expected THETA,PHI in degrees with THETA in [0, 180], got '" +
                            cli.view + "'");
    options.camera.theta_deg = a;
    options.camera.phi_deg = b;
  }
  if (cli.fov_deg > 0) {
    options.camera.projection = preview::Camera::Projection::kPerspective;
    options.camera.fov_deg = cli.fov_deg;
  }
  if (!cli.light.empty()) {
    if (!ParsePair(cli.light, &a, &b) || a < 0 || a > 180)
      throw InvalidArgument("--light: expected THETA,PHI in degrees with THETA in [0, 180], got '" +
                            cli.light + "'");
    options.light = preview::DirectionalLight{a, b};
    // A direct-lighting picture: the map lights the object only when --env says so.
    options.environment_lighting = cli.env_given;
    options.show_background = cli.env_given;
  }
  if (cli.no_background) options.show_background = false;
  // The overwrite rule of every writing command, checked before any rendering work.
  ReportRemovedTemporaries(CheckWritableOutput(cli.out, cli.force));
  const preview::EnvironmentMap map = preview::EnvironmentMap::FromName(cli.env);
  if (!map.load_warning().empty()) std::fprintf(stderr, "%s\n", map.load_warning().c_str());

  std::optional<processing::ExtrapolationParams> extrapolate;
  if (!cli.extrapolate.empty()) extrapolate = ParseExtrapolationOption(cli.extrapolate);
  std::vector<std::string> warnings;
  sources::OpenOptions open_options;
  open_options.extrapolation = extrapolate;
  sources::OpenedSource opened = sources::OpenBrdf(cli.file, open_options);
  warnings.insert(warnings.end(), opened.warnings.begin(), opened.warnings.end());
  std::vector<std::string> notes;
  if (const auto note = opened.SphereCoverageNote(cli.file)) notes.push_back(*note);
  const std::unique_ptr<BrdfSource> source = std::move(opened.brdf);
  std::unique_ptr<BrdfSource> second;
  if (!cli.compare.empty()) {
    sources::OpenedSource other = sources::OpenBrdf(cli.compare, open_options);
    warnings.insert(warnings.end(), other.warnings.begin(), other.warnings.end());
    if (const auto note = other.SphereCoverageNote(cli.compare)) notes.push_back(*note);
    second = std::move(other.brdf);
  }
  for (const std::string& w : warnings) std::fprintf(stderr, "%s\n", w.c_str());
  // A sphere (and a mesh) shows every pair of directions; a capture measured only some of them.
  if (!cli.quiet && options.shape != preview::Shape::kPlane)
    for (const std::string& n : notes) std::fprintf(stderr, "%s\n", n.c_str());

  // --ibl engine: the source's IBL pack, lit as an engine's probes light it; --compare's
  // source keeps the integral (the truth the engine is compared with).
  IblPack pack;
  preview::PreviewOptions first_options = options;
  if (cli.ibl == "engine") {
    pack = ComputeIblPack(*source);
    first_options.engine_ibl = &pack;
  } else if (cli.ibl != "true") {
    throw InvalidArgument("--ibl: expected true or engine, got '" + cli.ibl + "'");
  }
  const preview::PreviewImage first = Render(*source, map, first_options, cli);
  preview::PreviewImage out = first;
  std::vector<std::pair<std::string, std::string>> attributes = {
      {"brdf:source", cli.file},
      {"brdf:environment", map.name()},
      {"brdf:object", cli.mesh},
      {"brdf:estimator", EstimatorName(first.estimator)},
      {"brdf:ibl", cli.ibl}};
  if (second) {
    const preview::PreviewImage other = Render(*second, map, options, cli);
    const preview::ImageDifference d = preview::CompareImages(first, other);
    out = preview::SideBySide(first, other);
    attributes.emplace_back("brdf:compare", cli.compare);
    attributes.emplace_back("brdf:layout",
                            "source | compare | signed difference (red: source "
                            "brighter, blue: compare brighter)");
    std::printf("RMS difference: %.6g (%.3f %% of the mean of %s) over %zu pixels; largest %.6g\n",
                d.rms, 100.0 * d.relative_rms, cli.compare.c_str(), d.pixels, d.max_abs);
  }
  preview::WritePreviewImage(
      cli.out, out, cli.exposure_ev,
      cli.tone_map == "reinhard" ? preview::ToneMapCurve::kReinhard : preview::ToneMapCurve::kClamp,
      attributes);
  if (!cli.quiet) std::fprintf(stderr, "wrote %s\n", cli.out.c_str());
  return 0;
}

}  // namespace brdf::cli
