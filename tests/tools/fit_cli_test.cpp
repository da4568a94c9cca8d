// `brdf fit` run as a user runs it: a material file fitted back by its own model gives its
// parameters (the file's own values are the truth), `--model all` writes one material file per
// model and prints the comparison table with the engine instructions, a bad input is reported
// and skipped, an existing output is refused without --force.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

using Json = nlohmann::json;

class FitCommand : public ToolTest {};

TEST_F(FitCommand, FitsAMaterialFileBackToItsOwnParameters) {
  WriteText(dir_ / "plastic.json",
            R"({"model":"ggx","kd":[0.4,0.1,0.05],"f0":0.04,"alpha":[0.12,0.12,0.12]})");
  const ToolRun r = RunTool(
      "fit " + Quote(dir_ / "plastic.json") + " --model ggx --out " + Quote(dir_ / "fit.json"),
      dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json j = Json::parse(ReadAll(dir_ / "fit.json"));
  EXPECT_EQ(j["model"], "ggx");
  const double kd[] = {0.4, 0.1, 0.05};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(j["kd"][c].get<double>(), kd[c], 0.01 * kd[c]) << c;
    EXPECT_NEAR(j["f0"][c].get<double>(), 0.04, 0.01 * 0.04) << c;
    EXPECT_NEAR(j["alpha"][c].get<double>(), 0.12, 0.01 * 0.12) << c;
  }
  EXPECT_EQ(j["fit"]["status"], "converged");
  EXPECT_EQ(j["fit"]["slices"].size(), 4u);
  EXPECT_EQ(j["fit"]["samples_used"].get<int>(), 4 * 76 * 360);
  EXPECT_NE(r.out.find("rmse per theta_in"), std::string::npos) << r.out;
  // The result is itself a material file: eval reads it.
  const ToolRun e = RunTool("eval " + Quote(dir_ / "fit.json") + " --in 30,0 --out 30,180", dir_);
  EXPECT_EQ(e.exit_code, 0) << e.err;
  // Writing over it again needs --force.
  const ToolRun again = RunTool(
      "fit " + Quote(dir_ / "plastic.json") + " --model ggx --out " + Quote(dir_ / "fit.json"),
      dir_);
  EXPECT_NE(again.exit_code, 0);
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
}

TEST_F(FitCommand, AllModelsWriteOneFileEachAndSayWhatToTypeInTheEngines) {
  WriteText(dir_ / "red.json", R"({"model":"ggx","kd":[0.5,0.05,0.05],"f0":0.04,"alpha":0.2})");
  // Into a folder that does not exist yet; progress on stderr, one line per model (not a
  // terminal), the last one "10/10".
  const ToolRun r = RunTool(
      "fit " + Quote(dir_ / "red.json") + " --model all --out " + Quote(dir_ / "new" / "fits"),
      dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* m :
       {"lambert", "lafortune", "ggx", "blinn-phong", "ward", "unreal-defaultlit", "unity-hdrp-lit",
        "unity-hdrp-lit-specular", "unity-urp-lit", "unity-urp-lit-specular"}) {
    const fs::path f = dir_ / "new" / "fits" / (std::string("red.") + m + ".json");
    ASSERT_TRUE(fs::exists(f)) << f;
    EXPECT_EQ(Json::parse(ReadAll(f))["model"], m);
    EXPECT_NE(r.err.find(std::string(" ") + m + " (converged, "), std::string::npos) << r.err;
  }
  EXPECT_EQ(r.ErrLines().size(), 10u) << r.err;
  EXPECT_NE(r.err.find("fit 10/10 "), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("Unreal Engine: Base Color "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Unity HDRP: Base Map "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Unity URP: Base Map "), std::string::npos) << r.out;
}

// A colour shift is a property of the measurement, not of a model: every model's report
// records it, the table says it once. RGL's vch_silk_blue is such a measurement: its hue
// changes with angle beyond any mix of two colours.
TEST_F(FitCommand, AWarningEveryModelSharesIsPrintedOnce) {
  const std::string input = brdf::test::DataPath("rgl/vch_silk_blue_rgb.bsdf");
  const ToolRun r =
      RunTool("fit " + Quote(input) + " --model all --out " + Quote(dir_ / "fits"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string warning = "the measured hue changes with angle";
  std::size_t count = 0;
  for (std::size_t at = r.out.find(warning); at != std::string::npos;
       at = r.out.find(warning, at + 1))
    ++count;
  EXPECT_EQ(count, 1u) << r.out;
  EXPECT_NE(r.out.find("that none of these models can represent"), std::string::npos) << r.out;
  for (const char* m : {"ggx", "unity-hdrp-lit-specular", "unity-urp-lit"}) {
    const Json fit = Json::parse(
        ReadAll(dir_ / "fits" / (std::string("vch_silk_blue_rgb.") + m + ".json")))["fit"];
    EXPECT_TRUE(fit["colour_shift"].get<bool>()) << m;
    bool recorded = false;
    for (const Json& w : fit["warnings"]) recorded |= w.get<std::string>().find(warning) == 0;
    EXPECT_TRUE(recorded) << m << ": " << fit["warnings"].dump();
  }
}

TEST_F(FitCommand, BadInputsAreReportedAndSkipped) {
  WriteText(dir_ / "good.json", R"({"model":"lambert","rho":0.5})");
  WriteText(dir_ / "bad.json", R"({"model":"lambert","rho":-0.5})");
  const ToolRun r = RunTool("fit " + Quote(dir_ / "good.json") + " " + Quote(dir_ / "bad.json") +
                                " --model lambert --out " + Quote(dir_ / "out"),
                            dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "good.lambert.json"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "bad.lambert.json"));
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'rho'"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("fitted 1 of 2"), std::string::npos) << r.out;
  // Progress: one step per input and model, the bad input counted as failed.
  EXPECT_NE(r.err.find("fit 1/2 "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fit 2/2 "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.json FAILED"), std::string::npos) << r.err;
  // One input and one model into a file in a folder that does not exist yet.
  const ToolRun one = RunTool("fit " + Quote(dir_ / "good.json") + " --model lambert --out " +
                                  Quote(dir_ / "a" / "b" / "good.json"),
                              dir_);
  EXPECT_EQ(one.exit_code, 0) << one.err;
  EXPECT_TRUE(fs::exists(dir_ / "a" / "b" / "good.json"));
}

// --robust, --loss, --max-theta-out and --starts reach the report: a material file captured
// noise-free on the reference geometry (4 × 76 × 360 samples), so the counts are the geometry's.
TEST_F(FitCommand, OptionsAreRecordedInTheReport) {
  WriteText(dir_ / "m.json", R"({"model":"ggx","kd":[0.3,0.2,0.1],"f0":0.05,"alpha":0.2})");
  const ToolRun r = Run("fit " + Quote(dir_ / "m.json") + " --out " + Quote(dir_ / "o.json") +
                        " --robust --loss log --max-theta-out 60 --starts 3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json fit = Json::parse(ReadAll(dir_ / "o.json"))["fit"];
  EXPECT_EQ(fit["loss"], "log");
  EXPECT_EQ(fit["robust"], true);
  EXPECT_GT(fit["robust_scale"].get<double>(), 0);
  EXPECT_EQ(fit["starts"], 3);
  EXPECT_EQ(fit["samples_used"].get<int>(), 4 * 61 * 360);           // θout 0…60
  EXPECT_EQ(fit["excluded"]["theta_out"].get<int>(), 4 * 15 * 360);  // θout 61…75
  EXPECT_NEAR(Json::parse(ReadAll(dir_ / "o.json"))["alpha"][1].get<double>(), 0.2, 0.002);
}

// --extrapolate auto in convert and atlas: the chosen p, l and the GGX fit are recorded (the
// sidecar's and the manifest's "extrapolation" and "fitted_models"), the fit is the material
// file's own GGX (its parameters are the truth), both commands choose the same p, l for the
// same input, and the LUT holds them: its band texels (θout beyond θb = 75°, and below the
// horizon the value at 90°, §5), decoded here from the KTX2 bytes, are the §6 curve
// f(75°, φ)·((1 − α) + α·p) with the recorded p, l and the material's own f. (Within 10° of the
// nadir φout is not defined by the texel's direction to better than the texel: left out.)
TEST_F(FitCommand, ExtrapolateAutoIsRecordedByConvertAndAtlas) {
  WriteText(dir_ / "g.json", R"({"model":"ggx","kd":0.05,"f0":[0.6,0.5,0.4],"alpha":0.2})");
  const ToolRun c = Run("convert " + Quote(dir_ / "g.json") + " --out " + Quote(dir_ / "luts") +
                        " --extrapolate auto --beyond clamp --formats ktx2,json --quiet");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const Json sidecar = Json::parse(ReadAll(dir_ / "luts" / "g.json"));
  ASSERT_EQ(sidecar["fitted_models"].size(), 1u);
  const Json& record = sidecar["fitted_models"][0];
  EXPECT_EQ(record["kind"], "extrapolation-auto");
  EXPECT_EQ(sidecar["extrapolation"]["p"], record["p"]);
  EXPECT_EQ(sidecar["extrapolation"]["l"], record["l"]);
  EXPECT_DOUBLE_EQ(record["theta_b_deg"].get<double>(), 75.0);
  EXPECT_LT(record["band_rmse"].get<double>(), record["band_rmse_clamp"].get<double>());
  const double f0[] = {0.6, 0.5, 0.4};
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(record["ggx_fit"]["alpha"][ch].get<double>(), 0.2, 0.002) << ch;
    EXPECT_NEAR(record["ggx_fit"]["f0"][ch].get<double>(), f0[ch], 0.01 * f0[ch]) << ch;
  }
  EXPECT_EQ(record["ggx_fit"]["fit"]["status"], "converged");

  // The band of the written LUT. The curve's f(75°, φ) is the material's: the LUT interpolates
  // a 1° capture of it, which for this α = 0.2 lobe is within 1 % of the formula at 75°.
  const double p = record["p"].get<double>(), l = record["l"].get<double>();
  const Analytic truth{"ggx", {0.05, 0.05, 0.05}, {0.6, 0.5, 0.4}, 0.2};
  const Texture3d lut = ReadKtx2Layout(dir_ / "luts" / "g.ktx2");
  ASSERT_EQ(lut.width, 361u);
  ASSERT_EQ(lut.height, 181u);
  ASSERT_EQ(lut.depth, 4u);
  const double theta_in[] = {0, 20, 40, 60};
  std::size_t checked = 0, bad = 0;
  double worst = 0;
  for (std::uint32_t k = 0; k < 4; ++k)
    for (int j = 0; j <= 180; j += 2)
      for (int i = 0; i <= 360; i += 3) {
        const auto d = TexelDirection(theta_in[k], i, j);
        if (d[0] <= 75.5 || d[0] > 170) continue;
        const double alpha = BezierByBisection(std::min((d[0] - 75.0) / 15.0, 1.0), l);
        const double factor = (1 - alpha) + alpha * p;
        const auto f = truth.FAngles(theta_in[k], 75.0, d[1]);
        const auto got = DecodeRgb9e5Word(lut.Word(i, j, k));
        const double step = Rgb9e5Step(factor * std::max({f[0], f[1], f[2]}));
        for (int ch = 0; ch < 3; ++ch) {
          const double want = factor * f[ch], err = std::fabs(got[ch] - want);
          worst = std::max(worst, err / want);
          if (err > 0.5 * step + 0.01 * want && ++bad <= 5)
            ADD_FAILURE() << "texel (" << i << ", " << j << ", " << k << ") θout " << d[0]
                          << " φout " << d[1] << " channel " << ch << ": LUT " << got[ch]
                          << ", §6 curve with p " << p << ", l " << l << ": " << want;
        }
        ++checked;
      }
  EXPECT_EQ(bad, 0u) << "of " << checked << " band texels";
  EXPECT_GT(checked, 10000u);
  RecordProperty("band_worst_relative_error", std::to_string(worst));

  const ToolRun a = Run("atlas " + Quote(dir_ / "g.json") + " --out " +
                        Quote(dir_ / "atlas" / "lib") + " --extrapolate auto --quiet");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const Json entry = Json::parse(ReadAll(dir_ / "atlas" / "lib.json"))["materials"][0];
  ASSERT_TRUE(entry.contains("extrapolation")) << entry.dump();
  ASSERT_TRUE(entry.contains("fitted_models")) << entry.dump();
  EXPECT_EQ(entry["extrapolation"]["p"], record["p"]);
  EXPECT_EQ(entry["extrapolation"]["l"], record["l"]);
  EXPECT_EQ(entry["fitted_models"][0]["p"], record["p"]);
  EXPECT_NEAR(entry["fitted_models"][0]["ggx_fit"]["alpha"][0].get<double>(), 0.2, 0.002);

  // A material with its own "extrapolate" keeps it (it comes before the command line): no fit
  // is made or recorded.
  WriteText(dir_ / "own.json",
            R"({"model":"ggx","kd":0.05,"f0":0.6,"alpha":0.2,"extrapolate":{"p":0.3,"l":0.7}})");
  ASSERT_EQ(Run("convert " + Quote(dir_ / "own.json") + " --out " + Quote(dir_ / "luts") +
                " --extrapolate auto --formats json --quiet")
                .exit_code,
            0);
  const Json own = Json::parse(ReadAll(dir_ / "luts" / "own.json"));
  EXPECT_EQ(own["extrapolation"]["p"], 0.3);
  EXPECT_EQ(own["extrapolation"]["l"], 0.7);
  EXPECT_TRUE(own["fitted_models"].empty()) << own["fitted_models"].dump();
}

// Any BRDF the toolchain reads is fitted: an exported LUT (sampled as a GPU samples it) and a
// CSV point cloud (`brdf export-csv` of a noise-free capture) of a GGX material file give the
// file's parameters back within 1 % (the CSV keeps every sample's value; the LUT's RGB9E5 steps,
// at most 2⁻⁸ of a texel's largest channel, and its 1° grid move them by about 0.2 % for this
// broad lobe). Two inputs of one name would write the same results: both are refused, nothing
// is fitted.
TEST_F(FitCommand, ExportedLutsAndCsvTablesAreFittedAndNameCollisionsRefused) {
  WriteText(dir_ / "g.json", R"({"model":"ggx","kd":[0.3,0.2,0.1],"f0":0.05,"alpha":0.2})");
  ASSERT_EQ(Run("convert " + Quote(dir_ / "g.json") + " --out " + Quote(dir_ / "luts") +
                " --formats ktx2,json --quiet")
                .exit_code,
            0);
  ASSERT_EQ(Run("capture --device sim --material " + Quote(dir_ / "g.json") +
                " --noise 0 --sample g --quiet --out " + Quote(dir_ / "g.bpc"))
                .exit_code,
            0);
  fs::create_directories(dir_ / "csv");
  ASSERT_EQ(Run("export-csv " + Quote(dir_ / "g.bpc") + " --out " + Quote(dir_ / "csv" / "g.csv"))
                .exit_code,
            0);

  const ToolRun both = Run("fit " + Quote(dir_ / "luts" / "g.ktx2") + " " +
                           Quote(dir_ / "csv" / "g.csv") + " --out " + Quote(dir_ / "fits"));
  EXPECT_EQ(both.exit_code, 1);
  EXPECT_NE(both.out.find("fitted 0 of 2"), std::string::npos) << both.out;
  EXPECT_NE(both.err.find("would also be written for"), std::string::npos) << both.err;
  // A result that would replace an input (g.lambert.json beside g.json) is refused.
  fs::create_directories(dir_ / "own");
  WriteText(dir_ / "own" / "g.json", ReadAll(dir_ / "g.json"));
  WriteText(dir_ / "own" / "g.lambert.json", R"({"model":"lambert","rho":0.5})");
  const ToolRun own =
      Run("fit " + Quote(dir_ / "own") + " --model lambert --out " + Quote(dir_ / "own"));
  EXPECT_NE(own.exit_code, 0);
  EXPECT_NE(own.err.find("would overwrite an input"), std::string::npos) << own.err;
  EXPECT_EQ(ReadAll(dir_ / "own" / "g.lambert.json"), R"({"model":"lambert","rho":0.5})");

  const double kd[] = {0.3, 0.2, 0.1};
  for (const fs::path& input : {dir_ / "luts" / "g.ktx2", dir_ / "csv" / "g.csv"}) {
    SCOPED_TRACE(input.string());
    const fs::path out = dir_ / (input.extension().string().substr(1) + ".json");
    const ToolRun r = Run("fit " + Quote(input) + " --out " + Quote(out));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Json j = Json::parse(ReadAll(out));
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(j["kd"][c].get<double>(), kd[c], 0.01 * kd[c]) << c;
      EXPECT_NEAR(j["f0"][c].get<double>(), 0.05, 0.01 * 0.05) << c;
      EXPECT_NEAR(j["alpha"][c].get<double>(), 0.2, 0.01 * 0.2) << c;
    }
  }
}

}  // namespace
}  // namespace brdf::tooltest

namespace brdf::tooltest {
namespace {

// A fit the solver cannot carry out (one sample at −1e30 makes ln(1 + f cos) undefined under
// --loss log): one line naming the file, exit code 1, no material file written, and none of the
// solver library's own log lines on the terminal. Since −1e30 is a value no surface has
// (docs/design.md §4), the capture is refused before any solver runs, by the rule every reader
// applies: the line names the slice and the sample instead of the model.
TEST_F(FitCommand, AFailedFitWritesNothingAndExitsOne) {
  Measurement m = CaptureOf(Ggx03(), {0, 20, 40, 60});
  m.slices[1].samples[7].rgb[0] = -1e30f;
  const fs::path bad = dir_ / "bad.bpc", out = dir_ / "bad.ggx.json";
  WriteBpc(bad.string(), m);
  const ToolRun r =
      RunTool("fit " + Quote(bad) + " --model ggx --loss log --out " + Quote(out), dir_);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_FALSE(fs::exists(out)) << "a failed fit is not a material file";
  for (const char* glog : {"InitGoogleLogging", "trust_region", ".cc:", "Jacobian"}) {
    EXPECT_EQ(r.err.find(glog), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find(glog), std::string::npos) << r.out;
  }
  const std::vector<std::string> lines = r.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind(bad.string() + ": ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find("slice 1"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("sample 7"), std::string::npos) << lines[0];
}

}  // namespace
}  // namespace brdf::tooltest

namespace brdf::tooltest {
namespace {

// A fit is a function of its input and options: `--jobs 1` and `--jobs 2` write the same bytes,
// and so do two runs (no wall time in the result). Engine (joint channels) and legacy (per
// channel) models both.
TEST_F(FitCommand, ResultsDoNotDependOnJobsOrOnTheRun) {
  const fs::path cap = dir_ / "cap.bpc";
  WriteBpc(cap.string(), CaptureOf(Ggx03(), {0, 20, 40, 60}));
  for (const char* model : {"ggx", "unity-hdrp-lit"}) {
    SCOPED_TRACE(model);
    std::vector<std::string> files;
    for (const char* jobs : {"1", "2", "2"}) {
      const fs::path out = dir_ / (std::string("fit") + std::to_string(files.size()) + ".json");
      const ToolRun r = RunTool("fit " + Quote(cap) + " --model " + model + " --jobs " + jobs +
                                    " --out " + Quote(out) + " --quiet",
                                dir_);
      ASSERT_EQ(r.exit_code, 0) << r.err;
      files.push_back(ReadAll(out));
      fs::remove(out);
    }
    EXPECT_EQ(files[0], files[1]) << "--jobs 1 and --jobs 2 differ";
    EXPECT_EQ(files[1], files[2]) << "two runs differ";
    EXPECT_EQ(files[0].find("\"seconds\""), std::string::npos) << files[0];
  }
}

}  // namespace
}  // namespace brdf::tooltest
