// Every file of tests/export/corpus (written by make_corpus.py from the specifications, not
// by our writers) goes through the readers: valid-* files must parse to the texels the script
// put in them, broken-* files must fail with a FormatError naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "brdf/core/error.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/rgb9e5.h"
#include "export_test_util.h"

namespace brdf::exporter {
namespace {

const std::filesystem::path kCorpus =
    std::filesystem::path(BRDF_SOURCE_DIR) / "tests/export/corpus";

std::vector<std::filesystem::path> CorpusFiles(const std::string& prefix) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(kCorpus)) {
    const std::string name = e.path().filename().string();
    const std::string ext = e.path().extension().string();
    if (name.rfind(prefix, 0) == 0 && (ext == ".ktx2" || ext == ".dds")) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

LoadedTexture Parse(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = test::ReadAll(path.string());
  const std::string name = path.filename().string();
  if (path.extension() == ".ktx2") return ParseKtx2(bytes.data(), bytes.size(), name);
  return ParseDds(bytes.data(), bytes.size(), name);
}

TEST(ReaderCorpus, ValidFilesCraftedFromTheSpecificationsParse) {
  const auto files = CorpusFiles("valid-");
  ASSERT_EQ(files.size(), 3u);
  for (const auto& path : files) {
    SCOPED_TRACE(path.filename().string());
    const LoadedTexture t = Parse(path);
    ASSERT_EQ(t.volume.width, 3);
    ASSERT_EQ(t.volume.height, 2);
    ASSERT_EQ(t.volume.depth, 2);
    // make_corpus.py: texel (x, y, z) = (x + 1, y + 2, z + 3).
    for (int z = 0; z < 2; ++z)
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) {
          const auto rgb = DecodeRgb9e5(t.volume.words[t.volume.Index(x, y, z)]);
          EXPECT_EQ(rgb[0], x + 1.0f);
          EXPECT_EQ(rgb[1], y + 2.0f);
          EXPECT_EQ(rgb[2], z + 3.0f);
        }
  }
}

TEST(ReaderCorpus, EveryBrokenFileFailsWithAFormatErrorNamingIt) {
  const auto files = CorpusFiles("broken-");
  ASSERT_GE(files.size(), 60u);
  for (const auto& path : files) {
    const std::string name = path.filename().string();
    try {
      Parse(path);
      ADD_FAILURE() << name << " was accepted";
    } catch (const FormatError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(name, 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("expected"), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << name << ": not a FormatError: " << e.what();
    }
  }
}

}  // namespace
}  // namespace brdf::exporter
