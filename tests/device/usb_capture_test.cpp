// Real libusb and real hidapi (its libusb backend) talking to the simulated firmware through
// umockdev: enumerate by VID:PID and serial, open, identify, calibrate, capture. The oracle is
// the same capture over the in-process loopback (same seed), value for value, and for faults
// the uninterrupted capture. Runs under umockdev-wrapper (ctest label "usb"); a process where
// umockdev is not active FAILS rather than skipping.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/device/capture_session.h"
#include "brdf/device/emulated_usb.h"
#include "brdf/device/usb_transport.h"
#include "device_test_support.h"

namespace brdf::device {
namespace {

using testing::Config;
using testing::LibraryMaterial;

std::unique_ptr<Transport> Open(const EmulatedUsbInstrument& emu) {
  const DeviceSpec spec = emu.Spec();
  return spec.kind == DeviceSpec::Kind::kUsb ? OpenUsbTransport(spec) : OpenHidTransport(spec);
}

std::vector<Slice> CaptureOver(Transport& link, DriverOptions options = {}) {
  Driver driver(link, options);
  CapturePlan plan;
  plan.theta_in_deg = {0, 20, 40, 60};
  std::vector<Slice> slices;
  CaptureCallbacks callbacks;
  callbacks.on_slice = [&](const Slice& s, const SliceReport&) { slices.push_back(s); };
  Capture(driver, plan, callbacks);
  return slices;
}

void ExpectSameValues(const std::vector<Slice>& a, const std::vector<Slice>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].samples.size(), b[k].samples.size());
    for (std::size_t i = 0; i < a[k].samples.size(); ++i) {
      const Sample &x = a[k].samples[i], &y = b[k].samples[i];
      ASSERT_EQ(x.rgb, y.rgb) << "slice " << k << " sample " << i;
      ASSERT_EQ(x.sigma, y.sigma);
      ASSERT_EQ(x.flags, y.flags);
      ASSERT_EQ(x.theta_out_deg, y.theta_out_deg);
      ASSERT_EQ(x.phi_out_deg, y.phi_out_deg);
    }
  }
}

class UsbCapture : public ::testing::TestWithParam<UsbPersonality> {
 protected:
  void SetUp() override {
    ASSERT_TRUE(UmockdevAvailable())
        << "umockdev is not active: run this test under umockdev-wrapper (ctest does)";
  }
};

TEST_P(UsbCapture, WholeCaptureEqualsTheLoopbackCaptureValueForValue) {
  const SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 5, 5, /*seed=*/7);
  SimulatedFirmware reference_fw(c);
  LoopbackTransport loop(reference_fw);
  const std::vector<Slice> reference = CaptureOver(loop);

  EmulatedUsbInstrument emu(c, GetParam());
  std::unique_ptr<Transport> link = Open(emu);
  EXPECT_NE(link->Description().find(c.serial), std::string::npos) << link->Description();
  const std::vector<Slice> got = CaptureOver(*link);
  ExpectSameValues(got, reference);
  EXPECT_GT(emu.in_transfers(), 10u);
}

INSTANTIATE_TEST_SUITE_P(Transports, UsbCapture,
                         ::testing::Values(UsbPersonality::kBulk, UsbPersonality::kHid),
                         [](const auto& param_info) {
                           return param_info.param == UsbPersonality::kBulk ? "Libusb"
                                                                            : "Hidapi";
                         });

}  // namespace
}  // namespace brdf::device
