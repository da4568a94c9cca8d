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
  const ToolRun r = RunTool(
      "fit " + Quote(dir_ / "red.json") + " --model all --out " + Quote(dir_ / "fits") + " --quiet",
      dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* m :
       {"lambert", "lafortune", "ggx", "blinn-phong", "ward", "unreal-defaultlit", "unity-hdrp-lit",
        "unity-hdrp-lit-specular", "unity-urp-lit", "unity-urp-lit-specular"}) {
    const fs::path f = dir_ / "fits" / (std::string("red.") + m + ".json");
    ASSERT_TRUE(fs::exists(f)) << f;
    EXPECT_EQ(Json::parse(ReadAll(f))["model"], m);
  }
  EXPECT_NE(r.out.find("Unreal Engine: Base Color "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Unity HDRP: Base Map "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Unity URP: Base Map "), std::string::npos) << r.out;
}

TEST_F(FitCommand, BadInputsAreReportedAndSkipped) {
  WriteText(dir_ / "good.json", R"({"model":"lambert","rho":0.5})");
  WriteText(dir_ / "bad.json", R"({"model":"lambert","rho":-0.5})");
  const ToolRun r = RunTool("fit " + Quote(dir_ / "good.json") + " " + Quote(dir_ / "bad.json") +
                                " --model lambert --out " + Quote(dir_ / "out") + " --quiet",
                            dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "good.lambert.json"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "bad.lambert.json"));
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'rho'"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("fitted 1 of 2"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace brdf::tooltest
