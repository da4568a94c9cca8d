// The blind-spot fill's model evaluation (processing/src/processing/fill_model_eval.h) against the
// models' one definition, models::EvaluateRgb (brdf/core/models.h): the same doubles, bit for bit,
// at geometries over the whole hemisphere pair and shapes over the ranges FitFillModel searches.
#include "fill_model_eval.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "brdf/core/geometry.h"

namespace brdf::processing::detail {
namespace {

ShadingGeometry RandomGeometry(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> theta(0.0, 89.5), phi(0.0, 360.0);
  return ShadingGeometry::Of(SphericalDirectionDeg(theta(rng), 0.0),
                             SphericalDirectionDeg(theta(rng), phi(rng)));
}

// A material of `family` with random diffuse and specular colours in [0, 1) and `shape`.
Material RandomMaterial(Model family, double shape, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return Material::Make(family,
                        {Rgb{unit(rng), unit(rng), unit(rng)}, Rgb{unit(rng), unit(rng), unit(rng)},
                         Rgb{shape, shape, shape}},
                        "fill");
}

void ExpectSameBits(Model family, double shape_lo, double shape_hi) {
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> log_shape(std::log(shape_lo), std::log(shape_hi));
  int compared = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double shape = std::exp(log_shape(rng));
    const Material m = RandomMaterial(family, shape, rng);
    const ShadingGeometry g = RandomGeometry(rng);
    const Rgb want = models::EvaluateRgb(family, g, m.values.data());
    const std::array<double, 3> got = EvaluateFillModel(m, g);
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(std::bit_cast<std::uint64_t>(got[c]), std::bit_cast<std::uint64_t>(want[c]))
          << ModelName(family) << " shape " << shape << " channel " << c << ": " << got[c]
          << " against " << want[c];
      compared += want[c] > 0;
    }
  }
  EXPECT_GT(compared, 50000);  // the values compared are mostly non-zero
}

TEST(FillModelEval, GgxIsModelsEvaluateRgbBitForBit) { ExpectSameBits(Model::kGgx, 0.005, 1.5); }
TEST(FillModelEval, WardIsModelsEvaluateRgbBitForBit) { ExpectSameBits(Model::kWard, 0.005, 1.5); }
TEST(FillModelEval, LafortuneIsModelsEvaluateRgbBitForBit) {
  ExpectSameBits(Model::kLafortune, 1.0, 20000.0);
}

// EvaluateFillModelAt, as the fill calls it: rows of geometries sharing a light direction (it
// keeps GGX's light-side masking while n·l repeats), some of them below the horizon, some
// skipped (left as they were).
void ExpectRowsSameBits(Model family, double shape_lo, double shape_hi) {
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<double> unit(0.0, 1.0), theta(0.0, 89.5), view(0.0, 100.0),
      phi(0.0, 360.0);
  std::uniform_real_distribution<double> log_shape(std::log(shape_lo), std::log(shape_hi));
  constexpr int kRow = 64;
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const double shape = std::exp(log_shape(rng));
    const Material m = RandomMaterial(family, shape, rng);
    std::vector<ShadingGeometry> g(kRow);
    std::vector<bool> skip(kRow);
    double theta_in = theta(rng);
    for (int k = 0; k < kRow; ++k) {
      if (k % 20 == 0) theta_in = theta(rng);  // a new light every 20 geometries
      g[k] = ShadingGeometry::Of(SphericalDirectionDeg(theta_in, 0.0),
                                 SphericalDirectionDeg(view(rng), phi(rng)));
      skip[k] = unit(rng) < 0.2;
    }
    const std::array<double, 3> sentinel{-1.0, -2.0, -3.0};
    std::vector<std::array<double, 3>> got(kRow, sentinel);
    EvaluateFillModelAt(m, g.data(), kRow, got.data(), [&](int k) { return skip[k]; });
    for (int k = 0; k < kRow; ++k) {
      const Rgb want = skip[k] ? Rgb{sentinel[0], sentinel[1], sentinel[2]}
                               : models::EvaluateRgb(family, g[k], m.values.data());
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(std::bit_cast<std::uint64_t>(got[k][c]), std::bit_cast<std::uint64_t>(want[c]))
            << ModelName(family) << " shape " << shape << " entry " << k << " channel " << c << ": "
            << got[k][c] << " against " << want[c];
        compared += !skip[k] && want[c] > 0;
      }
    }
  }
  EXPECT_GT(compared, 20000);  // most entries are above the horizon and not skipped
}

TEST(FillModelEval, GgxRowsAreModelsEvaluateRgbBitForBit) {
  ExpectRowsSameBits(Model::kGgx, 0.005, 1.5);
}
TEST(FillModelEval, WardRowsAreModelsEvaluateRgbBitForBit) {
  ExpectRowsSameBits(Model::kWard, 0.005, 1.5);
}
TEST(FillModelEval, LafortuneRowsAreModelsEvaluateRgbBitForBit) {
  ExpectRowsSameBits(Model::kLafortune, 1.0, 20000.0);
}

TEST(FillModelEval, ChannelsWithTheirOwnShapesGoToEvaluateRgb) {
  const Material m = Material::Make(
      Model::kGgx, {Rgb{0.1, 0.2, 0.3}, Rgb{0.9, 0.5, 0.04}, Rgb{0.1, 0.3, 0.6}}, "three shapes");
  const ShadingGeometry g =
      ShadingGeometry::Of(SphericalDirectionDeg(30.0, 0.0), SphericalDirectionDeg(35.0, 170.0));
  const Rgb want = models::EvaluateRgb(Model::kGgx, g, m.values.data());
  const std::array<double, 3> got = EvaluateFillModel(m, g);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(got[c], want[c]) << "channel " << c;
  EXPECT_NE(got[0], got[2]);
}

TEST(FillModelEval, BelowTheHorizonIsZero) {
  const Material m = Material::Make(
      Model::kWard, {Rgb{0.5, 0.5, 0.5}, Rgb{0.2, 0.2, 0.2}, Rgb{0.3, 0.3, 0.3}}, "ward");
  const ShadingGeometry g =
      ShadingGeometry::Of(SphericalDirectionDeg(30.0, 0.0), SphericalDirectionDeg(95.0, 10.0));
  const std::array<double, 3> got = EvaluateFillModel(m, g);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(got[c], 0.0);
}

}  // namespace
}  // namespace brdf::processing::detail
