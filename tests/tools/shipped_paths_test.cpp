// Files that are shipped or shared (captures, sidecars, engine manifests and everything else
// `brdf convert --engine all` writes) never record the converting machine's folders: a source is
// recorded by its file name (docs/robustness.md, "No machine's paths in shipped files").
#include <nlohmann/json.hpp>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

// Every string anywhere in a JSON document, with its JSON pointer.
void CollectStrings(const nlohmann::json& j, const std::string& where,
                    std::vector<std::pair<std::string, std::string>>* out) {
  if (j.is_string()) {
    out->emplace_back(where, j.get<std::string>());
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) CollectStrings(*it, where + "/" + it.key(), out);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      CollectStrings(j[i], where + "/" + std::to_string(i), out);
  }
}

class ShippedPaths : public ToolTest {};

TEST_F(ShippedPaths, CaptureAndConvertedFilesRecordFileNamesOnly) {
  // The library material is resolved to an absolute path inside the build's material folder;
  // the capture must record only its file name.
  const fs::path capture = dir_ / "in" / "cap.bpc";
  fs::create_directories(capture.parent_path());
  ASSERT_TRUE(capture.is_absolute());
  const ToolRun c = RunTool(
      "capture --device sim --material plastic_glossy_red --sample tile --out " + Quote(capture) +
          " --theta-in 0,20,40,60 --noise 0 --theta-out-step 5 "
          "--phi-out-step 5 --quiet",
      dir_);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const BpcReadResult file = ReadBpc(capture.string());
  const auto& extra = file.measurement.metadata.extra;
  ASSERT_TRUE(extra.count("material_file")) << "the capture names its material";
  EXPECT_EQ(extra.at("material_file"), "plastic_glossy_red.json");
  for (const auto& [key, value] : extra) {
    EXPECT_FALSE(!value.empty() && value.front() == '/') << key << " = " << value;
    EXPECT_EQ(value.find(dir_.string()), std::string::npos) << key << " = " << value;
  }

  const fs::path out = dir_ / "out";
  const ToolRun r =
      RunTool("convert " + Quote(capture) + " --out " + Quote(out) + " --engine all --quiet", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int json_files = 0, sources = 0;
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    if (!entry.is_regular_file()) continue;
    const std::string bytes = ReadAll(entry.path());
    EXPECT_EQ(bytes.find(dir_.string()), std::string::npos)
        << entry.path() << " holds the converting machine's folder " << dir_;
    if (entry.path().extension() != ".json") continue;
    ++json_files;
    std::vector<std::pair<std::string, std::string>> strings;
    CollectStrings(nlohmann::json::parse(bytes), "", &strings);
    for (const auto& [where, value] : strings) {
      EXPECT_FALSE(!value.empty() && value.front() == '/')
          << entry.path() << " " << where << " = " << value;
      if (where.size() >= 7 && where.substr(where.size() - 7) == "/source") {
        ++sources;
        EXPECT_EQ(value, "cap.bpc") << entry.path() << " " << where;
      }
    }
  }
  // The sidecar and the four engine manifests each name their source.
  EXPECT_GE(json_files, 5);
  EXPECT_GE(sources, 5);
}

}  // namespace
}  // namespace brdf::tooltest
