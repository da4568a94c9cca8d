// `brdf convert` run in parallel: `--jobs 2` writes the same bytes as `--jobs 1` for
// every output file of a folder of captures and a material file, and two concurrent
// `convert --force` runs into one folder leave only intact files. The expected files are those of
// a single `--jobs 1` run; "intact" is read from the containers' own specifications (KTX2
// identifier, "DDS " magic, OpenEXR magic 20000630, PNG signature, JSON that parses).
#include <nlohmann/json.hpp>

#include <map>
#include <set>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

class ConvertJobs : public ToolTest {
 protected:
  // The three sample captures and one material file, copied into IN.
  fs::path Inputs() {
    const fs::path in = dir_ / "in";
    fs::create_directories(in);
    const fs::path samples = fs::path(BRDF_SOURCE_DIR) / "data-samples";
    for (const char* name : {"gold.bpc", "plastic_glossy_red.bpc", "wood_oak.bpc"})
      fs::copy_file(samples / "captures" / name, in / name);
    fs::copy_file(samples / "materials" / "aluminium.json", in / "aluminium.json");
    return in;
  }
  // Every regular file under `root` (relative path → bytes).
  static std::map<std::string, std::string> Files(const fs::path& root) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(root))
      if (e.is_regular_file()) files[fs::relative(e.path(), root).string()] = ReadAll(e.path());
    return files;
  }
};

std::set<std::string> Extensions(const std::map<std::string, std::string>& files) {
  std::set<std::string> ext;
  for (const auto& [name, bytes] : files) ext.insert(fs::path(name).extension().string());
  return ext;
}

// Whether `bytes` is a whole file of the container its name says, read from its specification.
std::string Defect(const std::string& name, const std::string& bytes) {
  const std::string ext = fs::path(name).extension().string();
  static const unsigned char kKtx2[12] = {0xAB, 'K',  'T',  'X',  ' ',  '2',
                                          '0',  0xBB, '\r', '\n', 0x1A, '\n'};
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  static const unsigned char kExr[4] = {0x76, 0x2f, 0x31, 0x01};
  if (ext == ".ktx2") {
    if (bytes.size() < 104 || std::memcmp(bytes.data(), kKtx2, 12) != 0)
      return "no KTX2 identifier";
    if (LoadU64(bytes, 80) + LoadU64(bytes, 88) > bytes.size()) return "KTX2 level 0 cut short";
  } else if (ext == ".dds") {
    if (bytes.size() < 148 || bytes.compare(0, 4, "DDS ") != 0) return "no DDS magic";
  } else if (ext == ".exr") {
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kExr, 4) != 0) return "no OpenEXR magic";
  } else if (ext == ".png") {
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kPng, 8) != 0) return "no PNG signature";
    if (bytes.size() < 12 || bytes.compare(bytes.size() - 8, 4, "IEND") != 0)
      return "PNG without IEND";
  } else if (ext == ".json") {
    if (!nlohmann::json::accept(bytes)) return "JSON that does not parse";
  }
  return "";
}

TEST_F(ConvertJobs, TwoJobsWriteTheSameBytesAsOneForEveryOutputFile) {
  const fs::path in = Inputs();
  const ToolRun one =
      Run("convert " + Quote(in) + " --out " + Quote(dir_ / "jobs1") + " --jobs 1 --quiet");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const ToolRun two =
      Run("convert " + Quote(in) + " --out " + Quote(dir_ / "jobs2") + " --jobs 2 --quiet");
  ASSERT_EQ(two.exit_code, 0) << two.err;
  const auto a = Files(dir_ / "jobs1"), b = Files(dir_ / "jobs2");
  // Four inputs, each with a LUT in every format and a sidecar.
  for (const char* ext : {".ktx2", ".dds", ".exr", ".png", ".json"})
    EXPECT_TRUE(Extensions(a).count(ext)) << "no " << ext << " output from --jobs 1";
  ASSERT_GE(a.size(), 4u * 5u);
  std::set<std::string> names_a, names_b;
  for (const auto& [n, bytes] : a) names_a.insert(n);
  for (const auto& [n, bytes] : b) names_b.insert(n);
  ASSERT_EQ(names_a, names_b);
  for (const auto& [name, bytes] : a) {
    const std::string& other = b.at(name);
    EXPECT_EQ(bytes.size(), other.size()) << name;
    if (bytes != other) {
      std::size_t at = 0;
      while (at < bytes.size() && at < other.size() && bytes[at] == other[at]) ++at;
      ADD_FAILURE() << name << ": --jobs 2 differs from --jobs 1 from byte " << at;
    }
  }
}

TEST_F(ConvertJobs, ConcurrentForcedRunsIntoOneFolderLeaveIntactFiles) {
  const fs::path in = Inputs();
  const ToolRun ref =
      Run("convert " + Quote(in) + " --out " + Quote(dir_ / "single") + " --jobs 1 --quiet");
  ASSERT_EQ(ref.exit_code, 0) << ref.err;
  const auto expected = Files(dir_ / "single");
  ASSERT_GE(expected.size(), 4u * 5u);
  const fs::path shared = dir_ / "shared";
  for (int round = 0; round < 3; ++round) {
    // Two runs started together, each with two jobs, both overwriting.
    std::string cmd;
    for (int k = 0; k < 2; ++k) {
      const std::string tag = std::to_string(k);
      cmd += "( " + std::string(BRDF_TOOL) + " convert " + Quote(in) + " --out " + Quote(shared) +
             " --jobs 2 --quiet --force >" + Quote(dir_ / ("out" + tag)) + " 2>" +
             Quote(dir_ / ("err" + tag)) + "; echo $? >" + Quote(dir_ / ("rc" + tag)) + " ) & ";
    }
    cmd += "wait";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    for (int k = 0; k < 2; ++k) {
      const std::string tag = std::to_string(k);
      EXPECT_EQ(ReadAll(dir_ / ("rc" + tag)), "0\n")
          << "round " << round << ", run " << k << ": " << ReadAll(dir_ / ("err" + tag));
    }
    const auto got = Files(shared);
    std::set<std::string> want_names, got_names;
    for (const auto& [n, bytes] : expected) want_names.insert(n);
    for (const auto& [n, bytes] : got) got_names.insert(n);
    EXPECT_EQ(got_names, want_names) << "round " << round << ": leftover or missing files";
    for (const auto& [name, bytes] : got) {
      EXPECT_EQ(Defect(name, bytes), "") << "round " << round << ": " << name;
      const auto it = expected.find(name);
      if (it == expected.end()) continue;
      EXPECT_EQ(bytes.size(), it->second.size()) << "round " << round << ": " << name;
      EXPECT_TRUE(bytes == it->second)
          << "round " << round << ": " << name << " differs from the single run's file";
    }
  }
}

}  // namespace
}  // namespace brdf::tooltest
