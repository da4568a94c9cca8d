// The capture session in-process (loopback): the existing-file rule, resume re-identifying
// the instrument (serial and geometry), reuse of the file's references, and the argument
// parsers of --device and --sim-fault. Oracles: the uninterrupted capture's values; the
// documented grammar.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/device/capture_session.h"
#include "brdf/device/usb_models.h"
#include "device_test_support.h"

namespace brdf::device {
namespace {

using testing::Config;
using testing::LibraryMaterial;

class Session : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/brdf_capture_session_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  CaptureRequest Request(const std::string& name) const {
    CaptureRequest r;
    r.out_path = dir_ + "/" + name;
    r.theta_in_deg = {0, 20, 40, 60};
    r.sample_name = "s";
    return r;
  }
  static CaptureSessionResult Run(const CaptureRequest& r, const SimulatorConfig& c) {
    SimulatedFirmware fw(c);
    LoopbackTransport link(fw);
    return RunCaptureSession(r, link);
  }
  std::string dir_;
};

TEST_F(Session, ExistingFileFollowsTheOverwriteRuleAndNonBpcNamesAreRefused) {
  const SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 15, 15);
  EXPECT_THROW(Run(Request("cap.txt"), c), InvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/cap.txt"));
  ASSERT_EQ(Run(Request("a.bpc"), c).outcome, CaptureOutcome::kFinished);
  // The overwrite rule of every writing command (CheckWritableOutput): the existing file is
  // named, and a folder is refused even with force.
  try {
    Run(Request("a.bpc"), c);
    ADD_FAILURE() << "an existing capture was overwritten without force";
  } catch (const OutputExistsError& e) {
    EXPECT_EQ(e.paths(), std::vector<std::string>{dir_ + "/a.bpc"});
  }
  std::filesystem::create_directory(dir_ + "/folder.bpc");
  CaptureRequest into_folder = Request("folder.bpc");
  into_folder.force = true;
  EXPECT_THROW(Run(into_folder, c), IoError);
  into_folder.resume = true;
  EXPECT_THROW(Run(into_folder, c), IoError);
  CaptureRequest forced = Request("a.bpc");
  forced.force = true;
  EXPECT_EQ(Run(forced, c).outcome, CaptureOutcome::kFinished);
  CaptureRequest resume = Request("a.bpc");
  resume.resume = true;
  EXPECT_EQ(Run(resume, c).outcome, CaptureOutcome::kNothingToResume);
}

TEST_F(Session, ResumeReidentifiesTheInstrumentAndReusesTheFilesReferences) {
  const SimulatorConfig clean = Config(LibraryMaterial("gold"), 1, 5, 5, 9);
  ASSERT_EQ(Run(Request("whole.bpc"), clean).outcome, CaptureOutcome::kFinished);
  const Measurement whole = LoadBpc(dir_ + "/whole.bpc");

  SimulatorConfig broken = clean;
  broken.faults = ParseFaultPlan("disconnect:40");
  const CaptureSessionResult cut = Run(Request("cut.bpc"), broken);
  ASSERT_EQ(cut.outcome, CaptureOutcome::kFailed);
  EXPECT_EQ(cut.next, NextStep::kResume);

  CaptureRequest resume = Request("cut.bpc");
  resume.resume = true;
  // Another serial number: refused, nothing measured, the file untouched.
  SimulatorConfig other = clean;
  other.serial = "SIM-000099";
  const CaptureSessionResult refused = Run(resume, other);
  EXPECT_EQ(refused.outcome, CaptureOutcome::kRefused);
  EXPECT_EQ(refused.next, NextStep::kAcceptInstrument);
  EXPECT_NE(refused.message.find("SIM-000099"), std::string::npos) << refused.message;
  // Another geometry (same serial): refused too.
  SimulatorConfig coarser = clean;
  coarser.model.phi_out_step_deg = 10;
  const CaptureSessionResult refused2 = Run(resume, coarser);
  EXPECT_EQ(refused2.outcome, CaptureOutcome::kRefused);
  EXPECT_NE(refused2.message.find("geometry"), std::string::npos) << refused2.message;
  EXPECT_EQ(ReadBpc(dir_ + "/cut.bpc").measurement.slices.size(), 1u);

  // The original instrument: the references recorded in the file are reused (the firmware is
  // asked for no dark or white reading), and the result equals the uninterrupted capture.
  bool measured = true;
  SessionEvents events;
  events.on_calibrated = [&](const Metadata&, bool m) { measured = m; };
  SimulatedFirmware fw(clean);
  LoopbackTransport link(fw);
  const CaptureSessionResult done = RunCaptureSession(resume, link, events);
  ASSERT_EQ(done.outcome, CaptureOutcome::kFinished) << done.message;
  EXPECT_FALSE(measured);
  // 2 identify frames + ACK, then 3 slices of 18 frames: no DARK or WHITE was sent.
  EXPECT_EQ(fw.frames_sent(), 3u + 3 * 18);
  const Measurement got = LoadBpc(dir_ + "/cut.bpc");
  ASSERT_EQ(got.slices.size(), 4u);
  for (int k = 0; k < 4; ++k)
    for (std::size_t i = 0; i < got.slices[k].samples.size(); ++i) {
      ASSERT_EQ(got.slices[k].samples[i].rgb, whole.slices[k].samples[i].rgb);
      ASSERT_EQ(got.slices[k].samples[i].sigma, whole.slices[k].samples[i].sigma);
    }
  EXPECT_EQ(got.metadata.extra.at("resumed_theta_in_deg"), "20,40,60");
}

TEST_F(Session, ForceAcceptsADifferentInstrumentOnResume) {
  const SimulatorConfig clean = Config(LibraryMaterial("gold"), 1, 15, 15);
  SimulatorConfig broken = clean;
  broken.faults = ParseFaultPlan("disconnect:20");
  ASSERT_EQ(Run(Request("f.bpc"), broken).outcome, CaptureOutcome::kFailed);
  CaptureRequest resume = Request("f.bpc");
  resume.resume = true;
  resume.force = true;
  resume.calibrate = true;
  SimulatorConfig other = clean;
  other.serial = "SIM-000042";
  EXPECT_EQ(Run(resume, other).outcome, CaptureOutcome::kFinished);
}

TEST(DeviceSpecGrammar, ParsesEveryDocumentedFormAndRefusesTheRest) {
  EXPECT_EQ(ParseDeviceSpec("sim").kind, DeviceSpec::Kind::kSim);
  const DeviceSpec usb = ParseDeviceSpec("usb");
  EXPECT_EQ(usb.kind, DeviceSpec::Kind::kUsb);
  EXPECT_FALSE(usb.vendor_id.has_value());
  const DeviceSpec hid = ParseDeviceSpec("hid:1209:B7d2:SN-1");
  EXPECT_EQ(hid.kind, DeviceSpec::Kind::kHid);
  EXPECT_EQ(*hid.vendor_id, 0x1209);
  EXPECT_EQ(*hid.product_id, 0xB7D2);
  EXPECT_EQ(hid.serial, "SN-1");
  for (const char* bad : {"", "serial", "usb:", "usb:1209", "usb:12345:1", "usb:zz:1",
                          "hid:1209:b7d2:", "sim:1209:b7d1"})
    EXPECT_THROW(ParseDeviceSpec(bad), InvalidArgument) << bad;
}

TEST(FaultPlanGrammar, EveryListedFaultIsKept) {
  const FaultPlan p = ParseFaultPlan("corrupt:3,corrupt:9,lamp:20,halt:4");
  ASSERT_EQ(p.faults.size(), 4u);
  EXPECT_TRUE(p.Has(FaultType::kCorrupt, 3));
  EXPECT_TRUE(p.Has(FaultType::kCorrupt, 9));
  EXPECT_TRUE(p.Has(FaultType::kLampFailure, 20));
  EXPECT_TRUE(p.Has(FaultType::kEndpointHalt, 4));
  EXPECT_TRUE(ParseFaultPlan("").empty());
  for (const char* bad : {"corrupt", "corrupt:0", "corrupt:-1", "corrupt:x", "explode:3",
                          "corrupt:3,", "corrupt:99999999999999999999"})
    EXPECT_THROW(ParseFaultPlan(bad), InvalidArgument) << bad;
}

}  // namespace
}  // namespace brdf::device
