// The engine-model fits against SciPy: for each of the five engine models (Unreal Default Lit,
// HDRP Lit in both forms, URP Lit in both forms), the cost Ceres reports is numpy's ½·Σ r² at
// the fitted parameters, and no lower cost is found by scipy.optimize.least_squares fitting the
// same model (bench/fit/scipy_baseline.py, transcribed from the engines' shader sources) to the
// same samples with solid-angle weights the oracle computes from the grid itself
// (tests/python/fit_weights.py), from the fitted parameters, from the middle of the range and
// from a random point (tests/python/engine_fit_oracle.py). A fit that stops short of its
// optimum, or settles in a worse local one, fails.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "../device/device_test_support.h"
#include "brdf/fit/fit.h"
#include "fit_data_csv.h"
#include "test_support.h"

namespace brdf::processing {
namespace {

// A red plastic and a gold-like metal (no diffuse, coloured f0), captured by the simulated
// reference instrument at noise level 1 with θout every 1° and φout every 8° (13,680 samples):
// neither is exactly any engine model, so every fit has a residual to minimise.
TEST(FitEngines, EngineFitsReachScipysOptimumOfTheSameModel) {
  const brdf::test::ScopedTempDir tmp("fit-engine-scipy");
  const Material plastic =
      Material::Make(Model::kGgx, {{0.5, 0.1, 0.05}, {0.05, 0.05, 0.05}, {0.15, 0.15, 0.15}});
  const Material metal =
      Material::Make(Model::kGgx, {{0, 0, 0}, {0.95, 0.75, 0.35}, {0.25, 0.25, 0.25}});
  const Model engines[] = {Model::kUnrealDefaultLit, Model::kUnityHdrpLit,
                           Model::kUnityHdrpLitSpecular, Model::kUnityUrpLit,
                           Model::kUnityUrpLitSpecular};
  for (const Material* truth : {&plastic, &metal}) {
    const std::string label = truth == &metal ? "metal" : "plastic";
    SCOPED_TRACE(label);
    device::SimulatedFirmware firmware(device::testing::Config(*truth, 1.0, 1, 8, 21));
    const Measurement meas = device::testing::CaptureMeasurement(firmware);
    FitOptions o;
    const std::filesystem::path dir = tmp / label;
    std::filesystem::create_directories(dir);
    testing::WriteFitData(dir / "fit_data.csv", PrepareFitData(meas, o));
    nlohmann::json job;
    std::vector<FitReport> reports;
    for (Model engine : engines) {
      o.model = engine;
      const FitResult r = FitMaterial(meas, o);
      ASSERT_NE(r.report.status, FitStatus::kFailed) << ModelName(engine) << r.report.message;
      reports.push_back(r.report);
      job["fits"].push_back({{"model", std::string(ModelName(engine))},
                             {"fitted", nlohmann::json::parse(MaterialToJson(r.material))}});
    }
    std::ofstream(dir / "job.json") << job.dump();
    const std::optional<nlohmann::json> oracle = testing::RunFitOracle("engine_fit_oracle.py", dir);
    ASSERT_TRUE(oracle.has_value());
    const nlohmann::json& want = *oracle;
    ASSERT_EQ(want["fits"].size(), reports.size());
    for (std::size_t i = 0; i < reports.size(); ++i) {
      const nlohmann::json& w = want["fits"][i];
      const std::string name = w["model"].get<std::string>();
      SCOPED_TRACE(name);
      // The reported cost is numpy's at the reported parameters.
      const double at_fitted = w["cost_at_fitted"].get<double>();
      EXPECT_NEAR(reports[i].final_cost, at_fitted, 1e-9 * at_fitted);
      // No start brings SciPy below it: Ceres stops at a relative cost change of 1e-10, SciPy
      // at 1e-12, so Ceres may sit that little above the same optimum, never more.
      const double scipy_cost = w["scipy_cost"].get<double>();
      EXPECT_LE(reports[i].final_cost, scipy_cost * (1 + 1e-6))
          << "SciPy from its '" << w["scipy_start"].get<std::string>() << "' start reached "
          << scipy_cost << " at " << w["scipy_x"].dump() << "; the fit stopped at "
          << reports[i].final_cost << " at " << w["fitted_x"].dump();
      std::ostringstream costs;
      costs.precision(10);
      costs << "ceres " << reports[i].final_cost << ", scipy " << scipy_cost;
      RecordProperty(label + "_" + name + "_costs", costs.str());
    }
  }
}

}  // namespace
}  // namespace brdf::processing
