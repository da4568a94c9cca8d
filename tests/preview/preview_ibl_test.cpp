// `--ibl engine` (PreviewOptions::engine_ibl): the engines' split sum of the IBL pack rendered
// on the CPU. Truths from outside the code under test: the directional albedo E(μ) of each
// pixel's view by a brute-force quadrature on a grid of its own (tests/brute_force_albedo.h) (white
// furnace: a uniform radiance 1 map lights a pixel with exactly E(μ), and so must both the engine's
// image and the true preview), and, for a GGX material near the normal, the true environment-lit
// preview itself.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/core/models.h"
#include "brdf/preview/preview.h"
#include "brdf/sources/open.h"
#include "brute_force_albedo.h"

namespace brdf::preview {
namespace {

// μ = n·ω_o of pixel (x, y) of the default orthographic sphere view (radius 0.45 of the image
// height, centred), or −1 off the sphere.
double PixelMu(int x, int y, int size) {
  const double r = std::hypot(x + 0.5 - size / 2.0, y + 0.5 - size / 2.0) / (0.45 * size);
  return r < 1.0 ? std::sqrt(1.0 - r * r) : -1.0;
}

PreviewOptions SphereOptions(int size) {
  PreviewOptions o;
  o.width = o.height = size;
  o.show_background = false;
  o.jobs = 2;
  return o;
}

void ExpectFurnaceEqualsAlbedo(const BrdfSource& source, double tolerance) {
  // 1024 × 512 like the other built-in maps: the hierarchical quadrature integrates f_r at
  // most per map pixel, and the default 64 × 32 furnace's 5.6° pixels put it 2 % off E(μ) for
  // a glossy lobe at single pixels.
  const EnvironmentMap furnace = EnvironmentMap::Furnace({1.0, 1.0, 1.0}, 1024, 512);
  const IblPack pack = ComputeIblPack(source);
  constexpr int kSize = 64;
  PreviewOptions engine_options = SphereOptions(kSize);
  engine_options.engine_ibl = &pack;
  const PreviewImage engine = RenderPreview(source, furnace, engine_options);
  EXPECT_EQ(engine.estimator, Estimator::kEngineSplitSum);
  PreviewOptions true_options = SphereOptions(kSize);
  true_options.estimator = Estimator::kAuto;  // what `brdf preview` runs: hierarchical
  const PreviewImage truth = RenderPreview(source, furnace, true_options);
  EXPECT_EQ(truth.estimator, Estimator::kHierarchical);
  // Pixels along the horizontal radius from the centre to the rim: every μ the sphere shows.
  int checked = 0;
  const int y = kSize / 2;
  for (int x = kSize / 2; x < kSize; ++x) {
    const double mu = PixelMu(x, y, kSize);
    if (mu < 0.02) continue;  // the last pixels, whose μ varies too fast across the pixel
    const Rgb albedo = testing::BruteForceAlbedo(source, mu, 800, 720);
    for (int c = 0; c < 3; ++c) {
      const double e = albedo[c];
      EXPECT_NEAR(engine.Pixel(x, y)[c], e, tolerance * e)
          << source.Name() << " engine, mu " << mu << " channel " << c;
      // The hierarchical quadrature's own accuracy (docs/preview.md): up to 0.77 % measured,
      // at μ ≈ 0.14 for the glossy gold; 0.5 % elsewhere.
      EXPECT_NEAR(truth.Pixel(x, y)[c], e, 2.0 * tolerance * e)
          << source.Name() << " true preview, mu " << mu << " channel " << c;
    }
    ++checked;
  }
  EXPECT_GT(checked, 25);
}

TEST(PreviewIbl, WhiteFurnaceEngineAndTrueImagesEqualTheAlbedoOfAGgxMaterial) {
  const AnalyticBrdf gold(Material::Make(
      Model::kGgx, {{0, 0, 0}, {0.962585, 0.786916, 0.40822}, {0.15, 0.15, 0.15}}, "gold"));
  ExpectFurnaceEqualsAlbedo(gold, 0.005);
  const AnalyticBrdf red(
      Material::Make(Model::kGgx, {{0.5, 0.04, 0.04}, {0.04, 0.04, 0.04}, {0.3, 0.3, 0.3}}, "red"));
  ExpectFurnaceEqualsAlbedo(red, 0.005);
}

TEST(PreviewIbl, WhiteFurnaceEngineAndTrueImagesEqualTheAlbedoOfACaptureLut) {
  const sources::OpenedSource capture =
      sources::OpenBrdf(BRDF_SOURCE_DIR "/data-samples/captures/gold.bpc");
  ExpectFurnaceEqualsAlbedo(*capture.brdf, 0.005);
}

TEST(PreviewIbl, EngineImageOfAGgxMaterialNearTheNormalIsWithin10PercentOfTheTruth) {
  // Near the normal the split sum's assumption n = v = R holds: the engine's image must be close
  // to the environment-lit truth there. With the one-lobe pack this was 3.4 % RMS over μ ≥ 0.9
  // (gold, studio, 96²); the two-lobe pack describes one GGX lobe as a sharp core plus a broad
  // skirt (α = 0.2: α_eq 0.17, broad_alpha 0.31; tests/core/ibl_pack_test.cpp), which costs this
  // case 8.2 % while the measured materials gain (ibl_browser: pooled p95 17.1 → 7.9 %);
  // docs/benchmarks/ibl.md.
  const AnalyticBrdf gold(Material::Make(
      Model::kGgx, {{0, 0, 0}, {0.962585, 0.786916, 0.40822}, {0.15, 0.15, 0.15}}, "gold"));
  const EnvironmentMap studio = EnvironmentMap::Studio();
  const IblPack pack = ComputeIblPack(gold);
  constexpr int kSize = 96;
  PreviewOptions engine_options = SphereOptions(kSize);
  engine_options.engine_ibl = &pack;
  const PreviewImage engine = RenderPreview(gold, studio, engine_options);
  PreviewOptions true_options = SphereOptions(kSize);
  true_options.estimator = Estimator::kHierarchical;
  const PreviewImage truth = RenderPreview(gold, studio, true_options);
  auto luminance = [](const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; };
  double sum_sq = 0.0, sum = 0.0;
  int n = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      if (PixelMu(x, y, kSize) < 0.9) continue;
      const double d = luminance(engine.Pixel(x, y)) - luminance(truth.Pixel(x, y));
      sum_sq += d * d;
      sum += luminance(truth.Pixel(x, y));
      ++n;
    }
  ASSERT_GT(n, 500);
  const double relative_rms = std::sqrt(sum_sq / n) / (sum / n);
  EXPECT_LT(relative_rms, 0.10);
}

}  // namespace
}  // namespace brdf::preview
