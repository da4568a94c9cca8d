// The seed corpus of the .brdfc fuzzer (fuzz/corpus/brdfc/, written by fuzz/make_brdfc_corpus.py
// from docs/formats/compact.md) is what its file names say, read by the C++ reader: valid seeds
// parse and decode by the format's reading rule, each bad_at<N>_ seed is refused with one
// message naming byte N. The seeds stay valid starting points when the format or reader changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/sidecar.h"

namespace brdf::exporter {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(BRDF_SOURCE_DIR) / "fuzz" / "corpus" / "brdfc";

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

TEST(BrdfcFuzzCorpus, EverySeedReadsAsItsNameSays) {
  std::map<std::string, int> kinds;
  for (const auto& entry : fs::directory_iterator(kCorpus)) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    if (StartsWith(name, "valid_")) {
      const LoadedCompact c = ReadCompactLutFile(entry.path().string());
      EXPECT_EQ(c.compact.PayloadBytes() + c.sidecar_json.size(), fs::file_size(entry.path()));
      if (!c.sidecar_json.empty()) {
        const SidecarInfo info = ParseSidecarJson(c.sidecar_json, name);
        EXPECT_EQ(info.theta_in_deg, c.compact.theta_in_deg);
        EXPECT_EQ(info.payload_crc32, CompactPayloadCrc32(c.compact));
      }
      ++kinds["valid"];
    } else if (StartsWith(name, "bad_at")) {
      const std::uint64_t at = std::stoull(name.substr(6));
      try {
        ReadCompactLutFile(entry.path().string());
        ADD_FAILURE() << "accepted";
      } catch (const FormatError& e) {
        EXPECT_EQ(e.position(), BytePosition(at)) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      }
      ++kinds["bad"];
    } else {
      ADD_FAILURE() << "a seed whose name says nothing about what it is";
    }
  }
  EXPECT_GE(kinds["valid"], 3);
  EXPECT_GE(kinds["bad"], 10);
}

// The smallest seed: S = 2, ε = 2^-10, one slice, rows {0, 180}, columns {0, 360}, g_R = 0, -1,
// -2, -3 at (0, 0), (0, 360), (180, 0), (180, 360), g_G = g_R / 2, g_B = g_R / 4. The format's
// rule: bilinear in g over the grid, then f = S·max(2^g − ε, 0).
TEST(BrdfcFuzzCorpus, MinimalSeedDecodesByTheFormatsRule) {
  const LoadedCompact c = ReadCompactLutFile((kCorpus / "valid_one_slice_minimal.brdfc").string());
  const CompactLut& lut = c.compact;
  ASSERT_EQ(lut.slices(), 1);
  EXPECT_FALSE(lut.mirrored);
  EXPECT_EQ(lut.scale, 2.0f);
  EXPECT_EQ(lut.epsilon, std::exp2(-10.0f));
  const double eps = std::exp2(-10.0);
  const auto f = [&](double g) { return 2.0 * std::max(std::exp2(g) - eps, 0.0); };
  struct Case {
    double theta_d, phi_d, g_r;
  };
  // Corners, the middle of each edge, the centre and (45°, 90°), a quarter along both axes:
  // top -0.25, bottom -2.25, g = -0.25 + (-2)·0.25 = -0.75.
  for (const Case& t :
       {Case{0, 0, 0.0}, Case{0, 360, -1.0}, Case{180, 0, -2.0}, Case{180, 360, -3.0},
        Case{0, 180, -0.5}, Case{90, 0, -1.0}, Case{90, 180, -1.5}, Case{45, 90, -0.75}}) {
    SCOPED_TRACE(testing::Message() << t.theta_d << ", " << t.phi_d);
    const std::array<float, 3> v = lut.SampleSlice(0, t.theta_d, t.phi_d);
    EXPECT_NEAR(v[0], f(t.g_r), 1e-6 * f(t.g_r) + 1e-7);
    EXPECT_NEAR(v[1], f(t.g_r / 2), 1e-6 * f(t.g_r / 2) + 1e-7);
    EXPECT_NEAR(v[2], f(t.g_r / 4), 1e-6 * f(t.g_r / 4) + 1e-7);
  }
}

}  // namespace
}  // namespace brdf::exporter
