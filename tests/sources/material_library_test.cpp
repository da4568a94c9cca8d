// The virtual sample library in-process (brdf/sources/material_library.h): which folder serves
// it ($BRDF_MATERIALS_DIR, else the source tree for a build-tree run), how a name becomes a file,
// and that a file of the same name wins. Values are checked against the materials' own
// formulas (docs/design.md §9, written out in tests/tools/tool_test_util.h) with the parameters
// the files hold.
#include "brdf/sources/material_library.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/sources/open.h"
#include "tools/tool_test_util.h"

namespace brdf::sources {
namespace {

namespace fs = std::filesystem;
using tooltest::WriteText;

// Sets or unsets BRDF_MATERIALS_DIR for one test and restores what was there.
class MaterialLibrary : public tooltest::ToolTest {
 protected:
  void SetUp() override {
    ToolTest::SetUp();
    if (const char* old = std::getenv(kMaterialsDirVariable)) saved_ = old;
    ::unsetenv(kMaterialsDirVariable);
  }
  void TearDown() override {
    if (saved_)
      ::setenv(kMaterialsDirVariable, saved_->c_str(), 1);
    else
      ::unsetenv(kMaterialsDirVariable);
    ToolTest::TearDown();
  }
  // A library of two materials and a file that is not one.
  fs::path MakeLibrary() {
    const fs::path lib = dir_ / "lib";
    fs::create_directories(lib);
    WriteText(lib / "shiny.json", tooltest::Ggx03().Json());
    WriteText(lib / "dull.json", tooltest::Lambertian().Json());
    WriteText(lib / "README.txt", "not a material\n");
    return lib;
  }
  std::optional<std::string> saved_;
};

void ExpectValue(const BrdfSource& brdf, const tooltest::Analytic& m) {
  const Rgb f = brdf.Eval(SphericalDirectionDeg(30, 0), SphericalDirectionDeg(25, 170));
  const std::array<double, 3> want = m.FAngles(30, 25, 170);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], want[c], 1e-12 * std::max(1.0, want[c]));
}

TEST_F(MaterialLibrary, TheEnvironmentVariableNamesTheFolder) {
  const fs::path lib = MakeLibrary();
  ::setenv(kMaterialsDirVariable, lib.c_str(), 1);
  EXPECT_EQ(MaterialLibraryDir(), lib.string());
  EXPECT_EQ(MaterialLibraryNames(), (std::vector<std::string>{"dull", "shiny"}));
  EXPECT_EQ(MaterialLibraryFiles(), (std::vector<std::string>{(lib / "dull.json").string(),
                                                              (lib / "shiny.json").string()}));
  EXPECT_EQ(FindLibraryMaterial("shiny"), (lib / "shiny.json").string());
  EXPECT_EQ(FindLibraryMaterial("README"), std::nullopt);
  EXPECT_EQ(FindLibraryMaterial("lib/shiny"), std::nullopt);
  // Every opener takes the name.
  ExpectValue(*OpenBrdf("shiny").brdf, tooltest::Ggx03());
  ExpectValue(*OpenForView("dull").brdf, tooltest::Lambertian());
  EXPECT_EQ(OpenForView("dull").path, (lib / "dull.json").string());
}

TEST_F(MaterialLibrary, AnUnknownNameListsTheLibrary) {
  ::setenv(kMaterialsDirVariable, MakeLibrary().c_str(), 1);
  try {
    ResolveSource("velvet");
    ADD_FAILURE() << "an unknown name resolved";
  } catch (const IoError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("velvet: no such file, and no library material of that name", 0), 0u) << m;
    EXPECT_NE(m.find("dull, shiny"), std::string::npos) << m;
  }
  // A path that is not a bare name is left for the reader to report.
  EXPECT_EQ(ResolveSource("no/such/velvet"), "no/such/velvet");
  EXPECT_EQ(ResolveSource("velvet.json"), "velvet.json");
  // A folder that is not there: the listing says which and how to choose another.
  ::setenv(kMaterialsDirVariable, (dir_ / "none").c_str(), 1);
  try {
    MaterialLibraryFiles();
    ADD_FAILURE() << "a missing library folder listed";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(kMaterialsDirVariable), std::string::npos) << e.what();
  }
}

TEST_F(MaterialLibrary, AFileOfTheSameNameWinsOverTheLibrary) {
  ::setenv(kMaterialsDirVariable, MakeLibrary().c_str(), 1);
  const fs::path work = dir_ / "work";
  fs::create_directories(work);
  // ./shiny holds a Lambertian material, the library's shiny a GGX one.
  WriteText(work / "shiny", tooltest::Lambertian().Json());
  const fs::path before = fs::current_path();
  fs::current_path(work);
  const std::string resolved = ResolveSource("shiny");
  const OpenedSource opened = OpenBrdf("shiny");
  fs::current_path(before);
  EXPECT_EQ(resolved, "shiny");
  ExpectValue(*opened.brdf, tooltest::Lambertian());
}

// A test program runs from the build tree, where no installed share/brdf-toolchain/materials
// sits beside it: the source tree's library serves, with the materials the README lists.
TEST_F(MaterialLibrary, ABuildTreeRunUsesTheSourceTreesLibrary) {
  EXPECT_EQ(fs::path(MaterialLibraryDir()),
            (fs::path(BRDF_SOURCE_DIR) / "data-samples" / "materials").lexically_normal());
  const std::vector<std::string> names = MaterialLibraryNames();
  for (const char* expected : {"gold", "paper_white", "wood_oak", "plastic_glossy_red"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  // gold.json: GGX, kd 0, f0 (0.962585, 0.786916, 0.40822), α 0.15 (its own numbers).
  ExpectValue(*OpenBrdf("gold").brdf,
              tooltest::Analytic{"ggx", {0, 0, 0}, {0.962585, 0.786916, 0.40822}, 0.15});
}

}  // namespace
}  // namespace brdf::sources
