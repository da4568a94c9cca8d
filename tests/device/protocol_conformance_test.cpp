// device/PROTOCOL.md is complete enough to write firmware from: tests/python/protocol_encoder.py
// encodes an instrument's replies from the page alone (struct + zlib, no code shared with the
// codec), with noise bytes, a damaged header and sequence numbers wrapping past 255, and
// computes the calibrated values with the page's formula (§9). The driver must accept the
// stream, in any chunking, and produce those values and flags.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "brdf/core/file_util.h"
#include "brdf/device/driver.h"
#include "brdf/device/white_reference.h"

namespace brdf::device {
namespace {

// Serves recorded instrument bytes in small chunks; what the host writes is ignored.
class ReplayTransport final : public Transport {
 public:
  ReplayTransport(std::vector<std::uint8_t> bytes, std::size_t chunk)
      : bytes_(std::move(bytes)), chunk_(chunk) {}
  void Write(std::span<const std::uint8_t>) override {}
  std::size_t Read(std::span<std::uint8_t> buffer, int) override {
    const std::size_t n = std::min({buffer.size(), chunk_, bytes_.size() - at_});
    std::copy_n(bytes_.begin() + static_cast<std::ptrdiff_t>(at_), n, buffer.begin());
    at_ += n;
    return n;
  }
  std::string Description() const override { return "replay of protocol_encoder.py"; }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t chunk_, at_ = 0;
};

TEST(ProtocolConformance, DriverAcceptsFramesOfAnEncoderWrittenFromThePage) {
  char tmpl[] = "/tmp/brdf_protocol_conformance_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  const WhiteReference& w = SpectralonWhiteReference();
  char cmd[1024];
  std::snprintf(cmd, sizeof cmd, "%s %s/tests/python/protocol_encoder.py %s %.17g %.17g %.17g",
                BRDF_PYTHON3, BRDF_SOURCE_DIR, dir.c_str(), w.rho[0], w.rho[1], w.rho[2]);
  ASSERT_EQ(std::system(cmd), 0) << cmd;
  const std::string raw = ReadFileText(dir + "/replies.bin", 1 << 20);
  const std::vector<std::uint8_t> bytes(raw.begin(), raw.end());

  struct Expected {
    int row, column;
    double f[3];
    int saturated, below;
  };
  std::vector<Expected> expected;
  std::ifstream in(dir + "/expected.txt");
  for (Expected e; in >> e.row >> e.column >> e.f[0] >> e.f[1] >> e.f[2] >> e.saturated >> e.below;)
    expected.push_back(e);
  ASSERT_EQ(expected.size(), 9u);

  for (std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{64}, std::size_t{4096}}) {
    SCOPED_TRACE(chunk);
    ReplayTransport link(bytes, chunk);
    Driver driver(link);
    const InstrumentInfo& info = driver.Connect();
    EXPECT_EQ(info.identity.model, "PY-ENC 1");
    EXPECT_EQ(info.identity.serial, "PY-0001");
    EXPECT_EQ(info.identity.protocol_minor, 1);
    ASSERT_EQ(info.geometry.nd_transmittance.size(), 2u);
    EXPECT_EQ(info.geometry.nd_transmittance[1], 0.1f);
    EXPECT_EQ(info.geometry.rows, 3);
    driver.SetExposure({});
    driver.MeasureDark();
    driver.MeasureWhite(30);
    SliceReport report;
    const Slice slice = driver.MeasureSlice(30, &report);
    ASSERT_EQ(slice.samples.size(), 9u);
    for (const Expected& e : expected) {
      const Sample& s = slice.samples[static_cast<std::size_t>(e.row * 3 + e.column)];
      EXPECT_EQ(s.theta_out_deg, 5.0f * e.row);
      EXPECT_EQ(s.phi_out_deg, 120.0f * e.column);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(s.rgb[c], e.f[c], 1e-6 * std::fabs(e.f[c])) << e.row << "," << e.column;
      EXPECT_EQ((s.flags & kFlagSaturated) != 0, e.saturated != 0) << e.row << "," << e.column;
      EXPECT_EQ((s.flags & kFlagBelowNoiseFloor) != 0, e.below != 0) << e.row << "," << e.column;
    }
    EXPECT_EQ(report.saturated, 1u);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace brdf::device
