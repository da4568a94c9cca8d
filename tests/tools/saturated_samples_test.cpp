// `brdf convert` and `brdf atlas` report the samples a capture flagged saturated, per
// slice, on stderr and in the sidecar / atlas manifest. The capture is written here with flags
// set on chosen samples, so the expected counts are the ones this test put in.
#include <nlohmann/json.hpp>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

using Json = nlohmann::json;

const std::vector<double> kThetaIn = {0, 20, 40, 60};
// Saturated samples per slice written into the capture.
const std::vector<std::uint64_t> kSaturated = {0, 12, 0, 5};

class SaturatedSamples : public ToolTest {
 protected:
  // A Lambertian capture; slice k gets kSaturated[k] saturated samples spread over the slice
  // (some also flagged interpolated), plus samples with other flags only, which must not count.
  fs::path WriteFlaggedCapture(const std::string& name, bool flag) {
    Measurement m = CaptureOf(Lambertian(), kThetaIn, 75, 3, 3);
    for (std::size_t k = 0; flag && k < m.slices.size(); ++k) {
      std::vector<Sample>& s = m.slices[k].samples;
      for (std::uint64_t n = 0; n < kSaturated[k]; ++n)
        s[n * 37].flags = kFlagSaturated | (n % 2 ? kFlagInterpolated : 0);
      for (std::size_t n = 0; n < 4; ++n) s[n * 37 + 11].flags = kFlagBelowNoiseFloor;
      s[5].flags |= kFlagInterpolated;
    }
    fs::create_directories(dir_ / "in");
    const fs::path p = dir_ / "in" / (name + ".bpc");
    WriteBpc(p.string(), m);
    return p;
  }
  static void ExpectCounts(const Json& counts, const std::vector<std::uint64_t>& expected) {
    ASSERT_TRUE(counts.is_array()) << counts.dump();
    ASSERT_EQ(counts.size(), kThetaIn.size()) << counts.dump();
    for (std::size_t k = 0; k < kThetaIn.size(); ++k) {
      EXPECT_EQ(counts[k]["theta_in_deg"].get<double>(), kThetaIn[k]);
      EXPECT_EQ(counts[k]["count"].get<std::uint64_t>(), expected[k]) << "θin " << kThetaIn[k];
    }
  }
  static std::size_t Occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
  }
};

const char kLine[] =
    ": 17 saturated samples (θin 0°: 0, 20°: 12, 40°: 0, 60°: 5); their values "
    "are clipped\n";

TEST_F(SaturatedSamples, ConvertReportsAndRecordsCounts) {
  const fs::path bpc = WriteFlaggedCapture("sat", true);
  const ToolRun r = RunTool("convert " + Quote(bpc) + " --out " + Quote(dir_ / "out"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(Occurrences(r.err, bpc.string() + kLine), 1u) << r.err;
  EXPECT_EQ(Occurrences(r.err, "saturated"), 1u) << r.err;
  const Json sidecar = Json::parse(ReadAll(dir_ / "out" / "sat.json"));
  ExpectCounts(sidecar["saturated_samples"], kSaturated);

  // The exported LUT as an input (`brdf atlas` accepts them) carries the counts over from its
  // embedded sidecar.
  const fs::path ktx2 = dir_ / "out" / "sat.ktx2";
  const ToolRun again =
      RunTool("atlas " + Quote(ktx2) + " --out " + Quote(dir_ / "again" / "atlas"), dir_);
  ASSERT_EQ(again.exit_code, 0) << again.out << again.err;
  EXPECT_EQ(Occurrences(again.err, ktx2.string() + kLine), 1u) << again.err;
  const Json manifest = Json::parse(ReadAll(dir_ / "again" / "atlas.json"));
  ASSERT_EQ(manifest["materials"].size(), 1u);
  ExpectCounts(manifest["materials"][0]["saturated_samples"], kSaturated);
}

TEST_F(SaturatedSamples, CleanCaptureRecordsZerosAndPrintsNothing) {
  const fs::path bpc = WriteFlaggedCapture("clean", false);
  const ToolRun r = RunTool("convert " + Quote(bpc) + " --out " + Quote(dir_ / "out"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(Occurrences(r.err, "saturated"), 0u) << r.err;
  ExpectCounts(Json::parse(ReadAll(dir_ / "out" / "clean.json"))["saturated_samples"],
               {0, 0, 0, 0});
}

TEST_F(SaturatedSamples, AtlasReportsAndRecordsPerMaterial) {
  const fs::path sat = WriteFlaggedCapture("sat", true);
  const fs::path clean = WriteFlaggedCapture("clean", false);
  const ToolRun r = RunTool(
      "atlas " + Quote(sat) + " " + Quote(clean) + " --out " + Quote(dir_ / "out" / "atlas"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(Occurrences(r.err, sat.string() + kLine), 1u) << r.err;
  EXPECT_EQ(Occurrences(r.err, "saturated"), 1u) << r.err;
  const Json manifest = Json::parse(ReadAll(dir_ / "out" / "atlas.json"));
  ASSERT_EQ(manifest["materials"].size(), 2u);
  for (const Json& m : manifest["materials"])
    ExpectCounts(m["saturated_samples"],
                 m["name"] == "sat" ? kSaturated : std::vector<std::uint64_t>{0, 0, 0, 0});
}

}  // namespace
}  // namespace brdf::tooltest
