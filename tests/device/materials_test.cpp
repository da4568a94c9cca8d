// The virtual sample library (data-samples/materials): every file parses, is physically
// plausible, and the metal and dielectric Fresnel terms follow from the published optical
// constants written out below.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "brdf/core/models.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

std::string LibraryDir() { return std::string(BRDF_SOURCE_DIR) + "/data-samples/materials"; }

std::map<std::string, Material> LoadLibrary() {
  std::map<std::string, Material> out;
  for (const auto& entry : fs::directory_iterator(LibraryDir()))
    if (entry.path().extension() == ".json")
      out[entry.path().stem().string()] = LoadMaterialFile(entry.path().string());
  return out;
}

TEST(MaterialLibrary, EveryFileParsesAndIsPhysicallyPlausible) {
  const auto library = LoadLibrary();
  ASSERT_GE(library.size(), 15u);
  for (const auto& [stem, m] : library) {
    EXPECT_EQ(m.name, stem) << "the name member matches the file name";
    EXPECT_FALSE(m.description.empty()) << stem;
    EXPECT_TRUE(PhysicalProblems(m).empty()) << stem << ": " << PhysicalProblems(m).front();
  }
}

TEST(MaterialLibrary, CoversTheClassicSwatchSet) {
  const auto library = LoadLibrary();
  for (const char* name : {"copper", "gold", "silver", "aluminium", "glass_on_black",
                           "diamond_on_black", "white_reference", "paper_white"})
    EXPECT_EQ(library.count(name), 1u) << name;
  int woods = 0, matte = 0, glossy = 0;
  std::set<std::string> models;
  for (const auto& [stem, m] : library) {
    woods += stem.rfind("wood_", 0) == 0;
    matte += stem.rfind("plastic_matte_", 0) == 0;
    glossy += stem.rfind("plastic_glossy_", 0) == 0;
    models.insert(std::string(ModelName(m.model)));
  }
  EXPECT_GE(woods, 2);
  EXPECT_GE(matte, 3);
  EXPECT_GE(glossy, 3);
  EXPECT_EQ(models.size(), 5u) << "every analytic model is exercised by some sample";
}

// Published n, k at the tabulated wavelengths nearest 650/550/450 nm: Johnson & Christy,
// Phys. Rev. B 6, 4370 (1972) rows at 659.5, 548.6, 450.9 nm for Cu, Au, Ag; Rakić,
// Appl. Opt. 34, 4755 (1995) rows at 652.25, 563.57, 442.80 nm for Al (as tabulated in the
// refractiveindex.info database).
struct Metal {
  const char* name;
  double n[3], k[3];
};
constexpr Metal kMetals[] = {
    {"copper", {0.22, 1.02, 1.24}, {3.747, 2.577, 2.397}},
    {"gold", {0.14, 0.43, 1.38}, {3.697, 2.455, 1.914}},
    {"silver", {0.05, 0.06, 0.04}, {4.483, 3.586, 2.657}},
    {"aluminium", {1.5724, 1.0728, 0.6079}, {7.7354, 6.7839, 5.3676}},
};

TEST(MaterialLibrary, MetalF0FollowsFromPublishedOpticalConstants) {
  const auto library = LoadLibrary();
  for (const Metal& metal : kMetals) {
    const Material& m = library.at(metal.name);
    EXPECT_EQ(m.model, Model::kGgx) << metal.name;
    const auto extra = nlohmann::json::parse(m.extra_json);
    for (int c = 0; c < 3; ++c) {
      const double n = metal.n[c], k = metal.k[c];
      const double f0 = ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
      EXPECT_NEAR(m.Parameter(1)[c], f0, 5e-7) << metal.name << " channel " << c;
      EXPECT_EQ(m.Parameter(0)[c], 0.0) << metal.name;
      EXPECT_DOUBLE_EQ(extra.at("source").at("n").at(c).get<double>(), n) << metal.name;
      EXPECT_DOUBLE_EQ(extra.at("source").at("k").at(c).get<double>(), k) << metal.name;
    }
  }
}

TEST(MaterialLibrary, DielectricsOnBlackHaveFresnelF0OfTheirIndex) {
  const auto library = LoadLibrary();
  for (const auto& [name, ior] : {std::pair{"glass_on_black", 1.5}, {"diamond_on_black", 2.42}}) {
    const Material& m = library.at(name);
    const double f0 = ((ior - 1) / (ior + 1)) * ((ior - 1) / (ior + 1));
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(m.Parameter(1)[c], f0, 5e-7) << name;
      EXPECT_EQ(m.Parameter(0)[c], 0.0) << name << ": the black backing reflects nothing";
    }
  }
}

}  // namespace
}  // namespace brdf
