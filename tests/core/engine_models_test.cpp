// The engine shading models (unreal-defaultlit, unity-hdrp-lit[-specular],
// unity-urp-lit[-specular]) against an independent numpy transcription of the engines'
// published shader functions (tests/python/engine_brdf_oracle.py), for a few hundred direction
// pairs and several parameter sets each; and the material-file form of the new models.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/models.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "brdf_engine_models_XXXXXX").string();
    path = ::mkdtemp(pattern.data());
  }
  ~TempDir() { fs::remove_all(path); }
};

std::vector<Material> EngineMaterials() {
  using M = Material;
  return {
      M::Make(Model::kUnrealDefaultLit, {{0.9, 0.7, 0.3}, {1, 0, 0}, {0.5, 0, 0}, {0.3, 0, 0}}),
      M::Make(Model::kUnrealDefaultLit, {{0.2, 0.5, 0.3}, {0, 0, 0}, {0.2, 0, 0}, {0.8, 0, 0}}),
      // f0.g = 0.08·0.1 = 0.008 < 0.02: F90 = 50·f0.g < 1 (the saturate is active).
      M::Make(Model::kUnrealDefaultLit, {{0.5, 0.4, 0.3}, {0, 0, 0}, {0.1, 0, 0}, {0.05, 0, 0}}),
      M::Make(Model::kUnityHdrpLit, {{0.8, 0.3, 0.2}, {0.4, 0, 0}, {0.75, 0, 0}}),
      M::Make(Model::kUnityHdrpLit, {{0.1, 0.2, 0.9}, {0, 0, 0}, {0.1, 0, 0}}),
      M::Make(Model::kUnityHdrpLitSpecular, {{0.5, 0.4, 0.3}, {0.3, 0.2, 0.1}, {0.9, 0, 0}}),
      M::Make(Model::kUnityUrpLit, {{0.3, 0.6, 0.9}, {0.6, 0, 0}, {0.8, 0, 0}}),
      M::Make(Model::kUnityUrpLit, {{0.7, 0.7, 0.7}, {0, 0, 0}, {0.0, 0, 0}}),
      M::Make(Model::kUnityUrpLitSpecular, {{0.6, 0.5, 0.2}, {0.2, 0.3, 0.4}, {0.4, 0, 0}}),
      // Smoothness 1: URP's roughness floors HALF_MIN_SQRT and HALF_MIN are active.
      M::Make(Model::kUnityUrpLitSpecular, {{0.6, 0.5, 0.2}, {0.04, 0.04, 0.04}, {1.0, 0, 0}}),
  };
}

TEST(EngineModels, AgreeWithTheNumpyTranscriptionOfTheShaderFunctions) {
  TempDir dir;
  const fs::path input = dir.path / "pairs.txt";
  std::vector<std::pair<Material, std::pair<Vec3, Vec3>>> cases;
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> theta(0.5, 89.0), phi(0.0, 360.0);
  {
    std::ofstream out(input);
    out.precision(17);
    for (const Material& m : EngineMaterials()) {
      for (int k = 0; k < 300; ++k) {
        // A third of the pairs near the mirror direction, where the lobes are.
        const double ti = theta(rng), pi = phi(rng);
        double to = theta(rng), po = phi(rng);
        if (k % 3 == 0)
          to = std::clamp(ti + (theta(rng) - 45) / 20, 0.5, 89.0),
          po = pi + 180 + (phi(rng) - 180) / 40;
        const Vec3 l = SphericalDirectionDeg(ti, pi), v = SphericalDirectionDeg(to, po);
        out << ModelName(m.model);
        const ModelInfo& info = DescribeModel(m.model);
        for (int i = 0; i < info.value_count; ++i)
          out << ' ' << m.values[static_cast<std::size_t>(i)];
        out << " ; " << l.x << ' ' << l.y << ' ' << l.z << ' ' << v.x << ' ' << v.y << ' ' << v.z
            << '\n';
        cases.push_back({m, {l, v}});
      }
    }
  }
  const std::string cmd = std::string(BRDF_PYTHON3) + " " + BRDF_SOURCE_DIR +
                          "/tests/python/engine_brdf_oracle.py < '" + input.string() + "'";
  const brdf::test::CommandOutput oracle = brdf::test::RunCommand(cmd);
  ASSERT_EQ(oracle.status, 0) << cmd << "\n" << oracle.out.substr(0, 500);
  const std::string& text = oracle.out;
  std::istringstream lines(text);
  std::size_t i = 0;
  double worst = 0;
  for (std::string line; std::getline(lines, line); ++i) {
    ASSERT_LT(i, cases.size());
    std::istringstream fields(line);
    Rgb want{};
    fields >> want[0] >> want[1] >> want[2];
    const Rgb got = cases[i].first.Evaluate(cases[i].second.first, cases[i].second.second);
    for (int c = 0; c < 3; ++c) {
      const double err = std::fabs(got[c] - want[c]) / std::max(1e-6, std::fabs(want[c]));
      worst = std::max(worst, err);
      EXPECT_LE(err, 1e-9) << ModelName(cases[i].first.model) << " pair " << i << " channel " << c
                           << ": " << got[c] << " vs numpy " << want[c];
    }
  }
  EXPECT_EQ(i, cases.size());
  RecordProperty("worst_relative_error", std::to_string(worst));
}

TEST(EngineModels, MaterialFilesRoundTripAndSayWhatToTypeWhere) {
  for (const Material& m : EngineMaterials()) {
    const Material again = ParseMaterialJson(MaterialToJson(m), "engine.json");
    EXPECT_EQ(again.model, m.model);
    EXPECT_EQ(again.values, m.values);
  }
  const Material ue = ParseMaterialJson(
      R"({"model":"unreal-defaultlit","base_color":[0.91,0.78,0.34],"metallic":1,"specular":0.5,"roughness":0.31})");
  EXPECT_EQ(EngineInstructions(ue),
            "Base Color 0.91 0.78 0.34, Metallic 1.00, Specular 0.50, Roughness 0.31");
  EXPECT_EQ(EngineInstructions(Material::Make(
                Model::kGgx, {{0.1, 0.1, 0.1}, {0.04, 0.04, 0.04}, {0.2, 0.2, 0.2}})),
            "");
}

// Validation on read: every value finite and inside its range, so nothing downstream sees NaN.
TEST(MaterialValidation, RefusesValuesOutsideThePhysicalRange) {
  const struct {
    const char* json;
    const char* member;
  } bad[] = {
      {R"({"model":"ggx","kd":0.1,"f0":0.04,"alpha":1e300})", "'alpha'"},
      {R"({"model":"ggx","kd":0.1,"f0":-0.04,"alpha":0.3})", "'f0'"},
      {R"({"model":"lambert","rho":[0.5,-0.1,0.5]})", "'rho'[1]"},
      {R"({"model":"ward","rho_d":0.1,"rho_s":0.1,"alpha":0})", "'alpha'"},
      {R"({"model":"lafortune","kd":0.1,"ks":0.1,"n":1e7})", "'n'"},
      {R"({"model":"unreal-defaultlit","base_color":0.5,"metallic":1.5,"specular":0.5,"roughness":0.3})",
       "'metallic'"},
      {R"({"model":"unity-hdrp-lit","base_color":0.5,"metallic":0,"smoothness":[0.1,0.2,0.3]})",
       "'smoothness'"},
  };
  for (const auto& b : bad) {
    try {
      ParseMaterialJson(b.json, "bad.json");
      ADD_FAILURE() << "accepted " << b.json;
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(b.member), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
    }
  }
  // JSON has no NaN; an overflowing literal is the way to smuggle an infinity in.
  EXPECT_THROW(ParseMaterialJson(R"({"model":"lambert","rho":1e400})"), FormatError);
}

TEST(MaterialValidation, TheSampleLibraryIsInRange) {
  for (const auto& e :
       fs::directory_iterator(std::string(BRDF_SOURCE_DIR) + "/data-samples/materials")) {
    if (e.path().extension() != ".json") continue;
    EXPECT_NO_THROW(LoadMaterialFile(e.path().string())) << e.path();
  }
}

}  // namespace
}  // namespace brdf
