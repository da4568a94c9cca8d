// Bounds of the preview that must hold whatever the values are: the hierarchical quadrature's
// work does not depend on the sign or the size of f_r (a negated or scaled source refines the
// same cells), and a source whose values are noise cannot make it refine every cell down to the
// map's pixels. The oracles are symmetries of the integral (negating or scaling f_r by 2^100
// negates or scales every pixel exactly) and the documented per-point evaluation budget.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "brdf/core/brdf_source.h"
#include "brdf/preview/preview.h"
#include "processing/synthetic_capture.h"

namespace brdf::preview {
namespace {

// f_r of a material times a constant (negative, or a power of two so that the product is exact).
class Scaled final : public BrdfSource {
 public:
  Scaled(Material m, double factor) : inner_(std::move(m)), factor_(factor) {}
  std::string Name() const override { return "scaled"; }
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    const Rgb f = inner_.Eval(wi, wo);
    return {f[0] * factor_, f[1] * factor_, f[2] * factor_};
  }

 private:
  AnalyticBrdf inner_;
  double factor_;
};

// Values in [−1, 1] that change with every direction pair: no cell ever looks converged.
class Noise final : public BrdfSource {
 public:
  std::string Name() const override { return "noise"; }
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (double v : {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z}) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      h = (h ^ bits) * 0xbf58476d1ce4e5b9ull;
      h ^= h >> 31;
    }
    const double u = static_cast<double>(h >> 11) * 0x1.0p-53 * 2.0 - 1.0;
    return {u, u, u};
  }
};

PreviewOptions Hierarchical(int size) {
  PreviewOptions o;
  o.width = o.height = size;
  o.estimator = Estimator::kHierarchical;
  o.jobs = 2;
  return o;
}

TEST(PreviewBounds, NegatedOrScaledValuesRefineExactlyAsTheIntactOnes) {
  const Material ggx = test::GgxAlpha03();
  const EnvironmentMap studio = EnvironmentMap::Studio(256, 128);
  const PreviewOptions o = Hierarchical(48);
  const PreviewImage intact = RenderPreview(Scaled(ggx, 1.0), studio, o);
  const PreviewImage negated = RenderPreview(Scaled(ggx, -1.0), studio, o);
  const double big = std::ldexp(1.0, 100);  // about 1.3e30, exact in binary
  const PreviewImage scaled = RenderPreview(Scaled(ggx, big), studio, o);
  ASSERT_GT(intact.brdf_evaluations, 0u);
  // The same cells refined and the same pixels integrated: the same work.
  EXPECT_EQ(negated.brdf_evaluations, intact.brdf_evaluations);
  EXPECT_EQ(scaled.brdf_evaluations, intact.brdf_evaluations);
  EXPECT_EQ(negated.computed_pixels, intact.computed_pixels);
  EXPECT_EQ(scaled.computed_pixels, intact.computed_pixels);
  // And the integral is linear in f_r.
  int lit = 0;
  for (std::size_t k = 0; k < intact.rgb.size(); ++k) {
    if (!intact.object[k / 3]) continue;
    lit += intact.rgb[k] > 0.0f;
    EXPECT_EQ(negated.rgb[k], -intact.rgb[k]) << k;
    EXPECT_EQ(scaled.rgb[k], static_cast<float>(big * intact.rgb[k])) << k;
  }
  EXPECT_GT(lit, 1000);
}

TEST(PreviewBounds, NoiseCannotRefineEveryCellToTheMapsPixels) {
  // A 1024 × 512 map: refining every cell above the horizon down to its pixels would cost about
  // 260 000 evaluations per point, the budget is 16 384 (hierarchical.h, max_evaluations).
  const EnvironmentMap studio = EnvironmentMap::Studio(1024, 512);
  PreviewOptions o = Hierarchical(16);
  o.image_block = 1;  // every object pixel integrated
  const PreviewImage image = RenderPreview(Noise(), studio, o);
  ASSERT_GT(image.computed_pixels, 100u);
  // Per point: the budget, plus the 4 children each of the 16 × 8 top cells still compares once
  // it is spent, plus the top cells themselves; and the ~1000 top-level estimates that find the
  // image's scale first.
  const std::uint64_t per_point = 16384 + 5 * 128;
  EXPECT_LE(image.brdf_evaluations, image.computed_pixels * per_point + 1024 * 128)
      << image.brdf_evaluations / image.computed_pixels << " evaluations per point";
}

}  // namespace
}  // namespace brdf::preview
