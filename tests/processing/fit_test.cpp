// brdf::fit: recovery of known parameters from simulated captures, cross-model sanity, the
// engine fits against naive mappings, and --extrapolate auto against clamping.
//
// Ground truth: the parameters the captures were simulated from (noise-free: the analytic
// material evaluated at every sample; with noise: the simulated instrument at its reference
// noise level through the real driver), and for the extrapolation the analytic GGX values
// between 75° and 90°.
#include "brdf/fit/fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "../device/device_test_support.h"
#include "brdf/core/error.h"
#include "synthetic_capture.h"

namespace brdf::processing {
namespace {

// The reference geometry (θin 0/20/40/60°, θout 0–75° at 1°) with φout every `phi_step_deg`.
// 2° halves the samples of the full capture; the lobes tested here are all wider than 2° in φ
// where it matters (n = 500 is 5° wide at half maximum in θ and wider in φ away from the pole).
Measurement NoiseFreeCapture(const Material& m, double phi_step_deg = 2.0) {
  Measurement meas;
  meas.metadata.sample_name = "synthetic " + std::string(ModelName(m.model));
  for (double ti : {0.0, 20.0, 40.0, 60.0}) {
    Slice s;
    s.theta_in_deg = ti;
    const Vec3 l = SphericalDirectionDeg(ti, 0);
    for (int to = 0; to <= 75; ++to)
      for (double po = 0; po < 360; po += phi_step_deg) {
        Sample x;
        x.theta_in_deg = static_cast<float>(ti);
        x.theta_out_deg = static_cast<float>(to);
        x.phi_out_deg = static_cast<float>(po);
        const Rgb f = m.Evaluate(l, SphericalDirectionDeg(to, po));
        for (int c = 0; c < 3; ++c) x.rgb[c] = static_cast<float>(f[c]);
        s.samples.push_back(x);
      }
    meas.slices.push_back(std::move(s));
  }
  return meas;
}

// A capture by the simulated reference instrument at noise level 1, φout every 2°.
Measurement NoisyCapture(const Material& m, std::uint64_t seed = 7) {
  device::SimulatedFirmware firmware(device::testing::Config(m, 1.0, 1, 2, seed));
  return device::testing::CaptureMeasurement(firmware);
}

struct Case {
  const char* label;
  Material truth;
};

std::vector<Case> RecoveryCases() {
  using M = Material;
  return {
      {"lambert", M::Make(Model::kLambert, {{0.8, 0.5, 0.2}})},
      {"ggx sharp alpha 0.05",
       M::Make(Model::kGgx, {{0.1, 0.2, 0.3}, {0.9, 0.6, 0.3}, {0.05, 0.05, 0.05}})},
      {"ggx rough alpha 0.5",
       M::Make(Model::kGgx, {{0.3, 0.2, 0.1}, {0.04, 0.04, 0.04}, {0.5, 0.5, 0.5}})},
      {"lafortune sharp n 500",
       M::Make(Model::kLafortune, {{0.2, 0.3, 0.1}, {0.5, 0.4, 0.6}, {500, 500, 500}})},
      {"lafortune rough n 5",
       M::Make(Model::kLafortune, {{0.4, 0.3, 0.2}, {0.3, 0.3, 0.3}, {5, 5, 5}})},
      {"blinn-phong sharp n 500",
       M::Make(Model::kBlinnPhong, {{0.1, 0.1, 0.2}, {0.6, 0.5, 0.4}, {500, 500, 500}})},
      {"blinn-phong rough n 10",
       M::Make(Model::kBlinnPhong, {{0.3, 0.4, 0.5}, {0.2, 0.2, 0.2}, {10, 10, 10}})},
      {"ward sharp alpha 0.05",
       M::Make(Model::kWard, {{0.2, 0.1, 0.05}, {0.1, 0.08, 0.06}, {0.05, 0.05, 0.05}})},
      {"ward rough alpha 0.4",
       M::Make(Model::kWard, {{0.3, 0.3, 0.3}, {0.2, 0.2, 0.2}, {0.4, 0.4, 0.4}})},
      {"unreal metal-ish", M::Make(Model::kUnrealDefaultLit,
                                   {{0.9, 0.7, 0.3}, {0.6, 0, 0}, {0.5, 0, 0}, {0.25, 0, 0}})},
      {"unreal rough dielectric",
       M::Make(Model::kUnrealDefaultLit, {{0.2, 0.5, 0.3}, {0.1, 0, 0}, {0.7, 0, 0}, {0.7, 0, 0}})},
      {"hdrp lit", M::Make(Model::kUnityHdrpLit, {{0.8, 0.3, 0.2}, {0.4, 0, 0}, {0.75, 0, 0}})},
      {"hdrp lit specular",
       M::Make(Model::kUnityHdrpLitSpecular, {{0.5, 0.4, 0.3}, {0.3, 0.2, 0.1}, {0.5, 0, 0}})},
      {"urp lit", M::Make(Model::kUnityUrpLit, {{0.3, 0.6, 0.9}, {0.6, 0, 0}, {0.8, 0, 0}})},
      {"urp lit specular",
       M::Make(Model::kUnityUrpLitSpecular, {{0.6, 0.5, 0.2}, {0.2, 0.3, 0.4}, {0.4, 0, 0}})},
  };
}

// |fit − truth| within `rel` of the truth, or `abs_floor` for values near 0.
void ExpectParameters(const Material& fit, const Material& truth, double rel, double abs_floor,
                      const std::string& label) {
  const ModelInfo& info = DescribeModel(truth.model);
  for (const ParameterInfo& p : info.parameters)
    for (int c = 0; c < p.Count(); ++c) {
      const double t = truth.values[static_cast<std::size_t>(p.offset + c)];
      const double f = fit.values[static_cast<std::size_t>(p.offset + c)];
      EXPECT_NEAR(f, t, std::max(rel * std::fabs(t), abs_floor))
          << label << ": " << p.name << "[" << c << "]";
    }
}

TEST(FitRecovery, NoiseFreeCapturesGiveTheParametersBackWithinOnePercent) {
  for (const Case& c : RecoveryCases()) {
    FitOptions o;
    o.model = c.truth.model;
    const FitResult r = FitMaterial(NoiseFreeCapture(c.truth), o);
    EXPECT_EQ(r.report.status, FitStatus::kConverged) << c.label << ": " << r.report.message;
    ExpectParameters(r.material, c.truth, 0.01, 1e-4, c.label);
    EXPECT_LT(r.report.median_relative_error, 1e-3) << c.label;
    EXPECT_EQ(r.report.slices.size(), 4u) << c.label;
    EXPECT_TRUE(r.report.representable) << c.label << ": " << r.report.chromaticity_error;
  }
}

// At the reference noise level the simulated detector adds shot and read noise of a few per
// cent per sample (device/include/brdf/device/simulator.h) and the white-reference calibration
// a per-slice gain error well under 1 %; over ~55,000 samples the noise averages out, so the
// fitted values move by a few per cent at most. The tolerances: 3 % (or 0.005 absolute) for
// reflectances and colours, 5 % for the lobe widths and exponents, whose sharpest lobes rest on
// the fewest samples. Unreal's Specular is the exception: it only adds 0.08·Specular·(1 −
// Metallic) to f0 (0.016 of 0.55 here), so a 0.1 % error in f0 moves it by 0.025; it is held to
// 0.05 absolute.
// Every recovery case, sharp and rough, every model (test::NoisyRecoveryTolerance).
TEST(FitRecovery, NoisyCapturesGiveTheParametersBackWithinStatedTolerances) {
  for (const Case& c : RecoveryCases()) {
    FitOptions o;
    o.model = c.truth.model;
    const FitResult r = FitMaterial(NoisyCapture(c.truth), o);
    EXPECT_EQ(r.report.status, FitStatus::kConverged) << c.label << ": " << r.report.message;
    const ModelInfo& info = DescribeModel(c.truth.model);
    for (const ParameterInfo& p : info.parameters)
      for (int ch = 0; ch < p.Count(); ++ch) {
        const double t = c.truth.values[static_cast<std::size_t>(p.offset + ch)];
        EXPECT_NEAR(r.material.values[static_cast<std::size_t>(p.offset + ch)], t,
                    test::NoisyRecoveryTolerance(info, p, t))
            << c.label << ": " << p.name << "[" << ch << "]";
      }
  }
}

TEST(FitCrossModel, GgxDataFittedByPhongLobesHasALargerFiniteError) {
  const Material ggx = RecoveryCases()[1].truth;  // sharp GGX
  const Measurement meas = NoiseFreeCapture(ggx);
  FitOptions o;
  o.model = Model::kGgx;
  const double own = FitMaterial(meas, o).report.final_cost;
  for (Model other : {Model::kBlinnPhong, Model::kLafortune}) {
    o.model = other;
    const FitReport r = FitMaterial(meas, o).report;
    EXPECT_TRUE(std::isfinite(r.final_cost)) << ModelName(other);
    EXPECT_GT(r.final_cost, 10 * own + 1e-12) << ModelName(other);
    EXPECT_TRUE(std::isfinite(r.rmse));
  }
}

TEST(FitCrossModel, ALambertianIsFittedWithNearZeroSpecularByEveryModel) {
  const Material lambert = Material::Make(Model::kLambert, {{0.7, 0.5, 0.3}});
  const Measurement meas = NoiseFreeCapture(lambert, 6.0);
  for (Model model : AllModels()) {
    FitOptions o;
    o.model = model;
    const FitResult r = FitMaterial(meas, o);
    const Material& m = r.material;
    const std::string name(ModelName(model));
    switch (model) {
      case Model::kLambert:
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.values[c], lambert.values[c], 1e-4) << name;
        break;
      case Model::kLafortune:
      case Model::kBlinnPhong:
      case Model::kGgx:
      case Model::kWard:
        for (int c = 0; c < 3; ++c) {
          EXPECT_LT(m.Parameter(1)[c], 2e-3) << name << " specular, channel " << c;
          EXPECT_NEAR(m.Parameter(0)[c], lambert.values[c], 0.01) << name;
        }
        break;
      case Model::kUnrealDefaultLit:
        EXPECT_LT(m.Parameter("metallic")[0], 0.01) << name;
        EXPECT_LT(m.Parameter("specular")[0], 0.03) << name;  // f0 = 0.08·specular < 0.0024
        break;
      case Model::kUnityHdrpLit:
      case Model::kUnityUrpLit:
        // The metallic workflow has a 4 % dielectric f0 at metallic 0: as little as it can.
        EXPECT_LT(m.Parameter("metallic")[0], 0.01) << name;
        break;
      case Model::kUnityHdrpLitSpecular:
      case Model::kUnityUrpLitSpecular:
        // HDRP's Disney diffuse is not Lambertian (darker at grazing light and view, brighter
        // retro-reflection): up to 2 % of specular colour makes up some of the difference.
        for (int c = 0; c < 3; ++c) EXPECT_LT(m.Parameter("specular_color")[c], 0.02) << name;
        break;
    }
  }
}

// Naive hand mappings from a GGX fit, as a technical artist would type them without an engine
// fit: base colour = kd, metallic 0, Unreal specular = f0/0.08, roughness = √α,
// smoothness = 1 − √α, specular colour = f0.
Material NaiveFromGgx(const Material& ggx, Model engine) {
  const Rgb kd = ggx.Parameter(0), f0 = ggx.Parameter(1), alpha = ggx.Parameter(2);
  const double a = (alpha[0] + alpha[1] + alpha[2]) / 3, r = std::sqrt(a);
  const double f0g = std::clamp(f0[1] / 0.08, 0.0, 1.0);
  auto clamp = [](Rgb v) {
    for (double& x : v) x = std::clamp(x, 0.0, 1.0);
    return v;
  };
  switch (engine) {
    case Model::kUnrealDefaultLit:
      return Material::Make(engine, {clamp(kd), {0, 0, 0}, {f0g, 0, 0}, {r, 0, 0}});
    case Model::kUnityHdrpLit:
    case Model::kUnityUrpLit:
      return Material::Make(engine, {clamp(kd), {0, 0, 0}, {1 - r, 0, 0}});
    default:
      return Material::Make(engine, {clamp(kd), clamp(f0), {1 - r, 0, 0}});
  }
}

// A red plastic and a gold-like metal (no diffuse, coloured f0): the naive mapping has no
// metallic for the metal, so it is the harder case for the mapping, not for the fit.
TEST(FitEngines, EngineFitsAreNeverWorseThanTheNaiveMappingOfTheGgxFit) {
  const Material plastic =
      Material::Make(Model::kGgx, {{0.5, 0.1, 0.05}, {0.05, 0.05, 0.05}, {0.15, 0.15, 0.15}});
  const Material metal =
      Material::Make(Model::kGgx, {{0, 0, 0}, {0.95, 0.75, 0.35}, {0.25, 0.25, 0.25}});
  for (const Material* truth : {&plastic, &metal}) {
    const Measurement meas = NoiseFreeCapture(*truth, 4.0);
    FitOptions o;
    o.model = Model::kGgx;
    const Material ggx = FitMaterial(meas, o).material;
    for (Model engine :
         {Model::kUnrealDefaultLit, Model::kUnityHdrpLit, Model::kUnityHdrpLitSpecular,
          Model::kUnityUrpLit, Model::kUnityUrpLitSpecular}) {
      o.model = engine;
      const FitReport fit = FitMaterial(meas, o).report;
      const FitReport naive = EvaluateFit(meas, NaiveFromGgx(ggx, engine), o);
      EXPECT_LE(fit.final_cost, naive.final_cost)
          << ModelName(engine) << (truth == &metal ? " metal" : " plastic");
    }
  }
}

TEST(FitReportTest, CountsExcludedSamplesAndWritesAMaterialFileWithTheReport) {
  const Material truth = RecoveryCases()[2].truth;
  Measurement meas = NoiseFreeCapture(truth, 6.0);
  std::size_t flagged_invalid = 0, flagged_saturated = 0, beyond = 0;
  for (Slice& s : meas.slices)
    for (std::size_t i = 0; i < s.samples.size(); ++i) {
      Sample& x = s.samples[i];
      if (i % 97 == 0) {
        x.flags = kFlagInvalid;
        x.rgb = {-1, -1, -1};  // garbage that must not matter
        ++flagged_invalid;
      } else if (i % 89 == 0) {
        x.flags = kFlagSaturated;
        x.rgb = {0.01f, 0.01f, 0.01f};  // clipped
        ++flagged_saturated;
      } else if (x.theta_out_deg > 70) {
        ++beyond;
      }
    }
  FitOptions o;
  o.model = Model::kGgx;
  o.max_theta_out_deg = 70;
  const FitResult r = FitMaterial(meas, o);
  EXPECT_EQ(r.report.excluded_invalid, flagged_invalid);
  EXPECT_EQ(r.report.excluded_saturated, flagged_saturated);
  EXPECT_EQ(r.report.excluded_theta_out, beyond);
  EXPECT_EQ(r.report.samples_used + flagged_invalid + flagged_saturated + beyond,
            meas.SampleCount());
  ExpectParameters(r.material, truth, 0.01, 1e-3, "ggx with flagged samples");
  // The result is a material file with the report under "fit"; any material reader takes it,
  // and the fitted-material reader gives back the report it was written from.
  const std::string file = FittedMaterialToJson(r);
  const Material plain = ParseMaterialJson(file, "fit.json");
  EXPECT_EQ(plain.values, r.material.values);
  EXPECT_NE(plain.extra_json.find("\"final_cost\""), std::string::npos);
  const FittedMaterial again = ParseFittedMaterialJson(file, "fit.json");
  EXPECT_EQ(again.material.values, r.material.values);
  EXPECT_EQ(again.material.extra_json, "{}");
  const FitReport& a = again.report;
  const FitReport& b = r.report;
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.loss, b.loss);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(a.rmse, b.rmse);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.samples_used, b.samples_used);
  EXPECT_EQ(a.excluded_invalid, b.excluded_invalid);
  EXPECT_EQ(a.excluded_saturated, b.excluded_saturated);
  EXPECT_EQ(a.excluded_theta_out, b.excluded_theta_out);
  EXPECT_EQ(a.warnings, b.warnings);
  EXPECT_EQ(a.software_version, b.software_version);
  ASSERT_EQ(a.slices.size(), b.slices.size());
  for (std::size_t i = 0; i < a.slices.size(); ++i) {
    EXPECT_EQ(a.slices[i].theta_in_deg, b.slices[i].theta_in_deg);
    EXPECT_EQ(a.slices[i].samples, b.slices[i].samples);
    EXPECT_EQ(a.slices[i].rmse, b.slices[i].rmse);
  }
  // Written again, the file is the same text.
  EXPECT_EQ(FittedMaterialToJson(again), file);
}

TEST(FittedMaterialTest, AFileWithoutAUsableReportIsRefused) {
  const std::string material = R"("model": "ggx", "kd": 0.1, "f0": 0.04, "alpha": 0.2)";
  for (const auto& [fit, member] : std::vector<std::pair<std::string, std::string>>{
           {"", "\"fit\""},
           {R"(, "fit": 3)", "\"fit\""},
           {R"(, "fit": {"rmse": 0.1})", "\"status\""},
           {R"(, "fit": {"status": "done", "rmse": 0.1})", "\"status\""},
           {R"(, "fit": {"status": "converged"})", "\"rmse\""},
           {R"(, "fit": {"status": "converged", "rmse": 0.1, "iterations": -2})",
            "\"iterations\""}}) {
    try {
      ParseFittedMaterialJson("{" + material + fit + "}", "m.json");
      ADD_FAILURE() << "accepted " << fit;
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("m.json"), std::string::npos) << e.what();
      EXPECT_NE(e.position().find(member), std::string::npos) << fit << ": " << e.position();
    }
  }
}

TEST(FitOptionsTest, BadOptionsAreRefused) {
  const Measurement meas = NoiseFreeCapture(RecoveryCases()[0].truth, 30.0);
  FitOptions o;
  o.starts = 0;
  EXPECT_THROW(FitMaterial(meas, o), InvalidArgument);
  o = {};
  o.max_theta_out_deg = 0;
  EXPECT_THROW(FitMaterial(meas, o), InvalidArgument);
  EXPECT_THROW(FitLossFromName("l2"), InvalidArgument);
  Measurement empty = meas;
  for (Slice& s : empty.slices)
    for (Sample& x : s.samples) x.flags = kFlagInvalid;
  EXPECT_THROW(FitMaterial(empty, FitOptions{}), FormatError);
}

TEST(FitLosses, EveryLossAndTheRobustOptionRecoverNoiseFreeParameters) {
  const Material truth = RecoveryCases()[1].truth;
  const Measurement meas = NoiseFreeCapture(truth, 4.0);
  for (FitLoss loss : {FitLoss::kNgan, FitLoss::kLog, FitLoss::kCbrt})
    for (bool robust : {false, true}) {
      FitOptions o;
      o.loss = loss;
      o.robust = robust;
      const FitResult r = FitMaterial(meas, o);
      ExpectParameters(r.material, truth, 0.01, 1e-3,
                       std::string(FitLossName(loss)) + (robust ? " robust" : ""));
    }
}

// The cost Ceres reports (summed per block from the fitter's own kernels and derivatives) is
// the cost of the fitted material evaluated sample by sample through models::EvaluateRgb.
TEST(FitLosses, ReportedCostIsTheCostOfTheFittedMaterial) {
  const Material truth =
      Material::Make(Model::kGgx, {{0.3, 0.2, 0.1}, {0.05, 0.05, 0.05}, {0.2, 0.2, 0.2}});
  Measurement meas = NoiseFreeCapture(truth, 6.0);
  for (Slice& s : meas.slices)  // a misfit for every model, so the costs are far from 0
    for (std::size_t i = 0; i < s.samples.size(); ++i) s.samples[i].rgb[i % 3] *= 1.2f;
  for (Model model : {Model::kGgx, Model::kLafortune, Model::kWard, Model::kUnrealDefaultLit,
                      Model::kUnityHdrpLit, Model::kUnityUrpLit, Model::kUnityUrpLitSpecular})
    for (FitLoss loss : {FitLoss::kNgan, FitLoss::kLog, FitLoss::kCbrt}) {
      FitOptions o;
      o.model = model;
      o.loss = loss;
      const FitResult r = FitMaterial(meas, o);
      const double again = EvaluateFit(meas, r.material, o).final_cost;
      EXPECT_GT(again, 0) << ModelName(model);
      EXPECT_NEAR(r.report.final_cost, again, 1e-9 * again)
          << ModelName(model) << " " << FitLossName(loss);
    }
}

// --extrapolate auto on a noise-free GGX capture: between 75° and 90° the §6 band with the
// chosen p, l is closer to the true GGX values than clamping (p = 1). The band is computed with
// the test's own §6 curve (synthetic_capture.h: the Bézier solved by bisection), not with the
// library's ExtrapolationFactor.
TEST(AutoExtrapolation, BeatsClampingOnANoiseFreeGgxCapture) {
  const Material truth =
      Material::Make(Model::kGgx, {{0.05, 0.05, 0.05}, {0.6, 0.5, 0.4}, {0.2, 0.2, 0.2}});
  const Measurement meas = NoiseFreeCapture(truth, 4.0);
  const AutoExtrapolationResult r = ChooseExtrapolationAuto(meas);
  ASSERT_TRUE(r.fit.has_value());
  EXPECT_DOUBLE_EQ(r.theta_b_deg, 75.0);
  EXPECT_LT(r.params.p, 1.0);
  double err_auto = 0, err_clamp = 0;
  for (double ti : {0.0, 20.0, 40.0, 60.0}) {
    const Vec3 l = SphericalDirectionDeg(ti, 0);
    for (double po = 0; po < 360; po += 4) {
      const Rgb at_b = truth.Evaluate(l, SphericalDirectionDeg(75, po));  // the measured f(θb)
      for (double t = 76; t <= 89.5; t += 0.5) {
        const Rgb want = truth.Evaluate(l, SphericalDirectionDeg(t, po));
        const double fa = test::FactorReference(t, 75.0, r.params.p, r.params.l);
        for (int c = 0; c < 3; ++c) {
          err_auto += std::pow(at_b[c] * fa - want[c], 2);
          err_clamp += std::pow(at_b[c] - want[c], 2);
        }
      }
    }
  }
  EXPECT_LT(err_auto, 0.5 * err_clamp) << "p " << r.params.p << " l " << r.params.l;
  EXPECT_LT(r.band_rmse, r.band_rmse_clamp);
  EXPECT_NE(AutoExtrapolationJson(r).find("\"ggx_fit\""), std::string::npos);
}

}  // namespace
}  // namespace brdf::processing
