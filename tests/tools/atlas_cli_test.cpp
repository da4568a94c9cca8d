// `brdf atlas` run as a user runs it. Each material's cell of the atlas texture must hold
// exactly the texels of that material's own LUT (both read back from their KTX2 files with the
// layout reader of tool_test_util.h); the cell positions follow docs/design.md §5, computed here.
#include <nlohmann/json.hpp>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

using Json = nlohmann::json;

class AtlasCommand : public ToolTest {};

TEST_F(AtlasCommand, EachCellEqualsThatMaterialsOwnLut) {
  fs::create_directories(dir_ / "mats");
  // Given in this order on the command line: lafortune, ggx, lambert.
  const std::vector<std::pair<std::string, Analytic>> mats = {
      {"lafortune", Lafortune20()}, {"ggx", Ggx03()}, {"lambert", Lambertian()}};
  std::string args;
  for (const auto& [name, m] : mats) {
    WriteText(dir_ / "mats" / (name + ".json"), m.Json());
    args += " " + Quote(dir_ / "mats" / (name + ".json"));
  }
  const ToolRun c =
      RunTool("convert" + args + " --out " + Quote(dir_ / "own") + " --formats ktx2 --quiet", dir_);
  ASSERT_EQ(c.exit_code, 0) << c.out << c.err;
  const ToolRun a =
      RunTool("atlas" + args + " --out " + Quote(dir_ / "out" / "atlas") + " --quiet", dir_);
  ASSERT_EQ(a.exit_code, 0) << a.out << a.err;
  for (const char* ext : {".ktx2", ".dds", ".exr", ".json"})
    EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / (std::string("atlas") + ext))) << ext;
  EXPECT_TRUE(FilesStartingWith(dir_ / "out", ".").empty()) << "temporary files left behind";

  // M = 3: Cm = ceil(√3) = 2 columns, Rm = ceil(3/2) = 2 rows of 361 × 181 cells. Both
  // commands fill the blind spots by default: θin 0, 10, …, 80°, K = 9 (docs/design.md §5).
  const Texture3d atlas = ReadKtx2Layout(dir_ / "out" / "atlas.ktx2");
  EXPECT_EQ(atlas.format, 123u);
  ASSERT_EQ(atlas.width, 2u * 361u);
  ASSERT_EQ(atlas.height, 2u * 181u);
  ASSERT_EQ(atlas.depth, 9u);
  EXPECT_EQ(atlas.payload.size(), 722u * 362u * 9u * 4u);
  EXPECT_TRUE(ReadDdsLayout(dir_ / "out" / "atlas.dds").payload == atlas.payload);

  const Json manifest = Json::parse(ReadAll(dir_ / "out" / "atlas.json"));
  ASSERT_EQ(manifest["materials"].size(), 3u);
  for (std::size_t m = 0; m < mats.size(); ++m) {
    SCOPED_TRACE(mats[m].first);
    EXPECT_EQ(manifest["materials"][m]["name"], mats[m].first);
    // The manifest records the fill as a sidecar does: the measured slices of the virtual
    // capture (docs/design.md §1), the ones past 60° that were filled, the method chosen.
    const Json& beyond = manifest["materials"][m]["beyond"];
    ASSERT_TRUE(beyond.is_object()) << manifest["materials"][m].dump();
    EXPECT_EQ(beyond["measured_theta_in"].get<std::vector<double>>(),
              (std::vector<double>{0, 20, 40, 60}));
    EXPECT_EQ(beyond["extrapolated_theta_in"].get<std::vector<double>>(),
              (std::vector<double>{70, 80}));
    EXPECT_EQ(beyond["inserted_theta_in"].get<std::vector<double>>(),
              (std::vector<double>{10, 30, 50}));
    EXPECT_TRUE(beyond["method"] == "model" || beyond["method"] == "hold") << beyond["method"];
    EXPECT_TRUE(beyond["leave_last_slice_out"].is_object());
    const Texture3d own = ReadKtx2Layout(dir_ / "own" / (mats[m].first + ".ktx2"));
    // One material's payload: 361 · 181 · 9 texels · 4 bytes = 2,352,276 (docs/design.md §5).
    EXPECT_EQ(own.payload.size(), 2352276u);
    const std::size_t x0 = (m % 2) * 361, y0 = (m / 2) * 181;
    std::size_t differing = 0;
    for (std::size_t k = 0; k < 9; ++k)
      for (std::size_t j = 0; j < 181; ++j)
        for (std::size_t i = 0; i < 361; ++i)
          differing += atlas.Word(x0 + i, y0 + j, k) != own.Word(i, j, k);
    EXPECT_EQ(differing, 0u);
  }
  // The same atlas from the exported LUTs instead of the material files: identical texels.
  std::string ktx2_args;
  for (const auto& [name, m] : mats) ktx2_args += " " + Quote(dir_ / "own" / (name + ".ktx2"));
  const ToolRun again =
      RunTool("atlas" + ktx2_args + " --out " + Quote(dir_ / "again" / "atlas") + " --quiet", dir_);
  ASSERT_EQ(again.exit_code, 0) << again.out << again.err;
  EXPECT_TRUE(ReadKtx2Layout(dir_ / "again" / "atlas.ktx2").payload == atlas.payload);

  // The fourth cell (column 1, row 1) is unused and zero.
  std::size_t non_zero = 0;
  for (std::size_t k = 0; k < 9; ++k)
    for (std::size_t j = 181; j < 362; ++j)
      for (std::size_t i = 361; i < 722; ++i) non_zero += atlas.Word(i, j, k) != 0;
  EXPECT_EQ(non_zero, 0u);
}

TEST_F(AtlasCommand, RefusesMaterialsWithDifferentThetaInSetsNamingBoth) {
  WriteBpc((dir_ / "tilted.bpc").string(), CaptureOf(Lafortune20(), {0, 30, 60}, 75, 5, 5));
  WriteText(dir_ / "gold.json", Ggx03().Json());
  const ToolRun r =
      RunTool("atlas " + Quote(dir_ / "gold.json") + " " + Quote(dir_ / "tilted.bpc") + " --out " +
                  Quote(dir_ / "out" / "atlas") + " --quiet",
              dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("'gold'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'tilted'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("θin"), std::string::npos) << r.err;
  EXPECT_TRUE(!fs::exists(dir_ / "out") || fs::is_empty(dir_ / "out"));
}

TEST_F(AtlasCommand, WritesNothingWhenAnInputFails) {
  WriteText(dir_ / "gold.json", Ggx03().Json());
  WriteText(dir_ / "broken.json", "{\"model\": \"ggx\", \"kd\": [0.1, 0.1]}");
  const ToolRun r =
      RunTool("atlas " + Quote(dir_ / "gold.json") + " " + Quote(dir_ / "broken.json") + " --out " +
                  Quote(dir_ / "out" / "atlas") + " --quiet",
              dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("atlas not written"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("broken.json ("), std::string::npos) << r.out;
  EXPECT_TRUE(!fs::exists(dir_ / "out") || fs::is_empty(dir_ / "out"));
}

}  // namespace
}  // namespace brdf::tooltest
