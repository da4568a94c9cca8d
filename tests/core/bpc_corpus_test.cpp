// The seed corpus of the .bpc fuzzer (fuzz/corpus/bpc/, written by fuzz/make_bpc_corpus.py from
// docs/formats/bpc.md) is what its file names say, read by the C++ reader: the seeds stay valid
// starting points when the format or the reader changes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string>

#include "brdf/core/bpc.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(BRDF_SOURCE_DIR) / "fuzz" / "corpus" / "bpc";

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

TEST(BpcFuzzCorpus, EverySeedReadsAsItsNameSays) {
  std::map<std::string, int> kinds;
  for (const auto& entry : fs::directory_iterator(kCorpus)) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    const BpcReadResult r = ReadBpc(entry.path().string());
    if (StartsWith(name, "finished_")) {
      EXPECT_TRUE(r.finished);
      EXPECT_TRUE(r.problems.empty());
    } else if (StartsWith(name, "unfinished_")) {
      EXPECT_FALSE(r.finished);
      EXPECT_TRUE(r.problems.empty());
    } else if (StartsWith(name, "truncated_")) {
      EXPECT_FALSE(r.finished);
      ASSERT_EQ(r.problems.size(), 1u);
      EXPECT_EQ(r.problems[0].kind, BpcProblemKind::kTruncated);
      EXPECT_EQ(r.problems[0].offset + r.problems[0].size, fs::file_size(entry.path()));
    } else if (StartsWith(name, "corrupt_")) {
      ASSERT_FALSE(r.problems.empty());
      EXPECT_EQ(r.problems[0].kind, BpcProblemKind::kCorrupt);
      EXPECT_TRUE(r.intact_data_after_damage);
    } else if (StartsWith(name, "trailing_")) {
      EXPECT_TRUE(r.finished);
      ASSERT_EQ(r.problems.size(), 1u);
      EXPECT_EQ(r.problems[0].kind, BpcProblemKind::kTrailingData);
    } else {
      ADD_FAILURE() << "a seed whose name says nothing about what it is";
    }
    ++kinds[name.substr(0, name.find('_'))];
  }
  for (const char* kind : {"finished", "unfinished", "truncated", "corrupt", "trailing"})
    EXPECT_GE(kinds[kind], 1) << "no " << kind << " seed in " << kCorpus;
}

// The values make_bpc_corpus.py writes into its finished two-slice seed, floats a lossless
// format must keep bit for bit.
TEST(BpcFuzzCorpus, FinishedSeedHoldsTheScriptsValues) {
  const BpcReadResult r = ReadBpc((kCorpus / "finished_two_slices.bpc").string());
  ASSERT_EQ(r.measurement.slices.size(), 2u);
  const Slice& plain = r.measurement.slices[0];
  ASSERT_EQ(plain.samples.size(), 3u);
  EXPECT_FALSE(plain.has_sigma);
  EXPECT_EQ(plain.samples[1].theta_out_deg, 30.0f);
  EXPECT_EQ(plain.samples[1].rgb[2], 0.125f);
  EXPECT_EQ(plain.samples[2].flags, 8);
  const Slice& awkward = r.measurement.slices[1];
  ASSERT_EQ(awkward.samples.size(), 2u);
  EXPECT_TRUE(awkward.has_sigma);
  EXPECT_TRUE(SameBits(awkward.samples[0].rgb[0], -0.0f));
  EXPECT_TRUE(SameBits(awkward.samples[0].rgb[1], 1e-40f));
  EXPECT_EQ(awkward.samples[0].rgb[2], std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(awkward.samples[1].rgb[0]));
  EXPECT_EQ(awkward.samples[0].sigma[2], std::numeric_limits<float>::denorm_min());
  EXPECT_EQ(r.measurement.metadata.sample_name, "seed tile");
  EXPECT_EQ(r.measurement.metadata.capture_end, "2026-11-22T10:01:00Z");
}

}  // namespace
}  // namespace brdf
