// A capture written slice by slice with BpcAppender survives a device fault: the completed
// slices read back bit-exact with ReadBpc, and resuming completes the file to the content of
// an uninterrupted capture (checked bit for bit).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <optional>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "device_test_support.h"
#include "test_support.h"

namespace brdf::device {
namespace {

namespace fs = std::filesystem;
using testing::Config;
using testing::LibraryMaterial;

class CaptureFile : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = brdf::test::ScopedTempDir::MakeTempDir("capture-file"); }
  void TearDown() override { fs::remove_all(dir_); }

  // Captures `theta_in` into `path` (created, or resumed when `resume`), the way
  // `brdf capture` does. Returns the number of slices delivered; rethrows DeviceError.
  static void CaptureToFile(SimulatedFirmware& fw, const std::string& path,
                            std::vector<double> theta_in, bool resume) {
    LoopbackTransport link(fw);
    Driver driver(link);
    CapturePlan plan;
    plan.theta_in_deg = std::move(theta_in);
    plan.metadata.sample_name = "tile";
    std::optional<BpcAppender> appender;
    if (resume) appender.emplace(BpcAppender::Resume(path, nullptr));
    CaptureCallbacks callbacks;
    callbacks.on_calibrated = [&](const Metadata& header) {
      if (!appender) appender.emplace(BpcAppender::Create(path, header));
    };
    callbacks.on_slice = [&](const Slice& s, const SliceReport&) { appender->AppendSlice(s); };
    const Metadata final_metadata = Capture(driver, plan, callbacks);
    appender->Finish(final_metadata);
  }

  fs::path dir_;
};

void ExpectSameSlice(const Slice& a, const Slice& b) {
  EXPECT_EQ(a.theta_in_deg, b.theta_in_deg);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    const Sample &x = a.samples[i], &y = b.samples[i];
    ASSERT_EQ(std::memcmp(&x.theta_out_deg, &y.theta_out_deg, sizeof(float)), 0) << i;
    ASSERT_EQ(std::memcmp(&x.phi_out_deg, &y.phi_out_deg, sizeof(float)), 0) << i;
    ASSERT_EQ(std::memcmp(x.rgb.data(), y.rgb.data(), sizeof x.rgb), 0) << i;
    ASSERT_EQ(std::memcmp(x.sigma.data(), y.sigma.data(), sizeof x.sigma), 0) << i;
    ASSERT_EQ(x.flags, y.flags) << i;
  }
}

TEST_F(CaptureFile, FaultMidCaptureKeepsCompletedSlicesAndResumeCompletesThem) {
  for (double noise : {0.0, 1.0}) {
    const Material m = LibraryMaterial("plastic_glossy_red");
    const std::string whole = (dir_ / "whole.bpc").string();
    const std::string cut = (dir_ / "cut.bpc").string();
    {
      SimulatedFirmware fw(Config(m, noise, 5, 5));
      CaptureToFile(fw, whole, {0, 20, 40, 60}, false);
    }
    SimulatorConfig faulty = Config(m, noise, 5, 5);
    // 8 set-up frames, 18 per slice of 16 × 72: the link drops inside the third slice.
    faulty.faults.faults.push_back({FaultType::kDisconnect, (8 + 2 * 18 + 7) + 1});
    {
      SimulatedFirmware fw(faulty);
      EXPECT_THROW(CaptureToFile(fw, cut, {0, 20, 40, 60}, false), DeviceError);
    }
    const BpcReadResult partial = ReadBpc(cut);
    const Measurement reference = LoadBpc(whole);
    EXPECT_FALSE(partial.finished);
    EXPECT_TRUE(partial.problems.empty());
    ASSERT_EQ(partial.measurement.slices.size(), 2u);
    for (int k = 0; k < 2; ++k) ExpectSameSlice(partial.measurement.slices[k], reference.slices[k]);

    {
      SimulatedFirmware fw(Config(m, noise, 5, 5));
      CaptureToFile(fw, cut, {40, 60}, true);
    }
    const BpcReadResult resumed = ReadBpc(cut);
    EXPECT_TRUE(resumed.finished);
    EXPECT_TRUE(resumed.problems.empty());
    ASSERT_EQ(resumed.measurement.slices.size(), 4u);
    for (int k = 0; k < 4; ++k) ExpectSameSlice(resumed.measurement.slices[k], reference.slices[k]);
    if (noise == 0) {
      // And the content is the analytic truth.
      for (const Slice& s : resumed.measurement.slices)
        for (const Sample& x : s.samples) {
          const Rgb t = testing::Truth(m, x);
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(x.rgb[c], t[c], 1e-5 * t[c]);
        }
    }
  }
}

}  // namespace
}  // namespace brdf::device
