// `brdf fit --robust` (FitOptions::robust: Cauchy's ρ(s) = b²·ln(1 + s/b²) per sample and
// channel, b = 1.4826 × the median |r| at the start unless given) against outside references:
//
// - the truth: captures by the simulated reference instrument (noise level 1, through the real
//   driver) of materials with known parameters, with a fixed fraction of the samples replaced by
//   large outliers (dust, a glint, a hot pixel: the value times 3–10 plus 0.2–1 1/sr). The robust
//   fit must come back to the true parameters, the plain one is pulled away;
// - SciPy: scipy.optimize.least_squares(loss="cauchy", f_scale=b) fitting the same model
//   (bench/fit/scipy_baseline.py's transcription of the published formulas) on the same samples,
//   with solid-angle weights the oracle computes from the grid itself
//   (tests/python/fit_weights.py), from the same start (tests/python/robust_fit_oracle.py)
//   reaches the same cost and
//   parameters, numpy's Cauchy cost at the reported parameters is the reported cost (and its
//   ½·Σ r² at the plain fit the plain fit's), and numpy's 1.4826 × median |r| at the start is
//   the reported scale.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <string>

#include "../device/device_test_support.h"
#include "brdf/fit/fit.h"
#include "fit_data_csv.h"
#include "synthetic_capture.h"
#include "test_support.h"

namespace brdf::processing {
namespace {

// The reference geometry with φout every 4° (27,360 samples), at noise level 1.
Measurement NoisyCapture(const Material& m, std::uint64_t seed) {
  device::SimulatedFirmware firmware(device::testing::Config(m, 1.0, 1, 4, seed));
  return device::testing::CaptureMeasurement(firmware);
}

// Replaces `fraction` of the samples (chosen by a fixed seed) with outliers: all three channels
// times a factor in [3, 10] plus an offset in [0.2, 1] 1/sr. Returns how many were replaced.
std::size_t AddOutliers(Measurement* meas, double fraction, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1), factor(3, 10), offset(0.2, 1.0);
  std::size_t n = 0;
  for (Slice& s : meas->slices)
    for (Sample& x : s.samples) {
      if (u(rng) >= fraction) continue;
      const double k = factor(rng), a = offset(rng);
      for (float& v : x.rgb) v = static_cast<float>(v * k + a);
      ++n;
    }
  return n;
}

// The largest |fit − truth| / max(|truth|, floor) over all values.
double WorstRelativeError(const Material& fit, const Material& truth, double floor) {
  double worst = 0;
  for (int i = 0; i < DescribeModel(truth.model).value_count; ++i) {
    const double t = truth.values[static_cast<std::size_t>(i)];
    worst = std::max(worst, std::fabs(fit.values[static_cast<std::size_t>(i)] - t) /
                                std::max(std::fabs(t), floor));
  }
  return worst;
}

struct Case {
  const char* label;
  Material truth;
};
std::vector<Case> Cases() {
  return {
      {"ggx",
       Material::Make(Model::kGgx, {{0.4, 0.2, 0.1}, {0.05, 0.05, 0.05}, {0.15, 0.15, 0.15}})},
      {"unreal-defaultlit",
       Material::Make(Model::kUnrealDefaultLit,
                      {{0.8, 0.6, 0.3}, {0.5, 0, 0}, {0.5, 0, 0}, {0.3, 0, 0}})},
  };
}

// 3 % of the samples are outliers. Without a robust loss they carry most of the cost (each is
// 3–10× its true value) and pull the colours and the lobe far off. With Cauchy's loss an
// outlier's influence on the gradient, ψ(r) = r/(1 + r²/b²), falls as b²/r once |r| ≫ b, and
// here |r| is 10–1000 b: the robust fit is held to the tolerances the noise alone allows
// (fit_test.cpp, FitRecovery.NoisyCaptures...: 3 % or 0.005 for colours and reflectances, 5 % for
// lobe widths; Unreal's Specular 0.05 absolute, as it moves f0 by only 0.08·(1 − metallic) per
// unit), and the plain fit is at least five times further off than the robust one.
TEST(FitRobust, OutliersPullThePlainFitAwayButNotTheRobustOne) {
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.label);
    Measurement meas = NoisyCapture(c.truth, 11);
    const std::size_t outliers = AddOutliers(&meas, 0.03, 5);
    ASSERT_GT(outliers, meas.SampleCount() / 50);
    FitOptions o;
    o.model = c.truth.model;
    const FitResult plain = FitMaterial(meas, o);
    o.robust = true;
    const FitResult robust = FitMaterial(meas, o);
    ASSERT_NE(robust.report.status, FitStatus::kFailed) << robust.report.message;
    EXPECT_TRUE(robust.report.robust);
    EXPECT_GT(robust.report.robust_scale, 0);

    const ModelInfo& info = DescribeModel(c.truth.model);
    for (const ParameterInfo& p : info.parameters)
      for (int ch = 0; ch < p.Count(); ++ch) {
        const std::size_t i = static_cast<std::size_t>(p.offset + ch);
        const double t = c.truth.values[i];
        EXPECT_NEAR(robust.material.values[i], t, test::NoisyRecoveryTolerance(info, p, t))
            << p.name << "[" << ch << "]";
      }
    const double robust_error = WorstRelativeError(robust.material, c.truth, 0.05);
    const double plain_error = WorstRelativeError(plain.material, c.truth, 0.05);
    EXPECT_GT(plain_error, 5 * robust_error)
        << "plain " << plain_error << ", robust " << robust_error;
    RecordProperty(
        std::string(c.label) + "_worst_relative_error",
        "plain " + std::to_string(plain_error) + ", robust " + std::to_string(robust_error));
  }
}

// From the plain fit as start (one refinement, the scale chosen there), under the ngan and the
// log loss. Both optimisers minimise the same ½·Σ b²·ln(1 + r²/b²); the tolerances are those of
// two converged optimisers of one smooth function: costs within 1e-6 relative (Ceres stops at
// a relative cost change of 1e-10, SciPy at 1e-12, on a cost that is flat to second order at
// the optimum) and the Ceres cost never above SciPy's by more than that; parameters within
// 1e-3 relative (0.002 absolute for near-zero values and Unreal's weakly determined Specular),
// the scale within 1e-3 (numpy's median of an even count averages the two middle values).
TEST(FitRobust, CostScaleAndOptimumAgreeWithScipyCauchy) {
  const brdf::test::ScopedTempDir tmp("fit-robust");
  for (const Case& c : Cases())
    for (FitLoss loss : {FitLoss::kNgan, FitLoss::kLog}) {
      const std::string label = std::string(c.label) + " " + std::string(FitLossName(loss));
      SCOPED_TRACE(label);
      Measurement meas = NoisyCapture(c.truth, 13);
      AddOutliers(&meas, 0.03, 17);
      FitOptions o;
      o.model = c.truth.model;
      o.loss = loss;
      const FitResult plain = FitMaterial(meas, o);
      const Material& start = plain.material;
      o.robust = true;
      o.start = start;
      o.starts = 1;
      const FitResult r = FitMaterial(meas, o);
      ASSERT_NE(r.report.status, FitStatus::kFailed) << r.report.message;

      const std::filesystem::path dir =
          tmp / (std::string(c.label) + "-" + std::string(FitLossName(loss)));
      std::filesystem::create_directories(dir);
      testing::WriteFitData(dir / "fit_data.csv", PrepareFitData(meas, o));
      std::ofstream(dir / "start.json") << MaterialToJson(start);
      std::ofstream(dir / "fitted.json") << MaterialToJson(r.material);
      {
        nlohmann::json job;
        job["model"] = std::string(ModelName(c.truth.model));
        job["loss"] = std::string(FitLossName(loss));
        job["scale"] = r.report.robust_scale;
        std::ofstream(dir / "job.json") << job.dump();
      }
      const std::optional<nlohmann::json> oracle =
          testing::RunFitOracle("robust_fit_oracle.py", dir);
      ASSERT_TRUE(oracle.has_value());
      const nlohmann::json& want = *oracle;

      // The plain fit's reported cost is numpy's ½·Σ r² at its parameters.
      const double plain_cost = want["plain_cost_at_start"].get<double>();
      EXPECT_NEAR(plain.report.final_cost, plain_cost, 1e-9 * plain_cost);
      EXPECT_NEAR(r.report.robust_scale, want["auto_scale"].get<double>(),
                  1e-3 * want["auto_scale"].get<double>());
      const double cost_at_fitted = want["cost_at_fitted"].get<double>();
      EXPECT_NEAR(r.report.final_cost, cost_at_fitted, 1e-9 * cost_at_fitted);
      // The robust fit moved: the start is not already the optimum of the robust cost.
      EXPECT_LT(r.report.final_cost, 0.9 * want["cost_at_start"].get<double>());
      const double scipy_cost = want["scipy_cost"].get<double>();
      EXPECT_NEAR(r.report.final_cost, scipy_cost, 1e-6 * scipy_cost);
      EXPECT_LE(r.report.final_cost, scipy_cost * (1 + 1e-6));
      const std::vector<double> x = want["scipy_x"].get<std::vector<double>>();
      ASSERT_EQ(x.size(), static_cast<std::size_t>(DescribeModel(c.truth.model).value_count));
      for (std::size_t i = 0; i < x.size(); ++i)
        EXPECT_NEAR(r.material.values[i], x[i], std::max(1e-3 * std::fabs(x[i]), 2e-3))
            << "value " << i;
      RecordProperty(label + "_costs", "ceres " + std::to_string(r.report.final_cost) + ", scipy " +
                                           std::to_string(scipy_cost));
    }
}

}  // namespace
}  // namespace brdf::processing
