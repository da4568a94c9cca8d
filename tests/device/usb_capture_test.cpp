// Real libusb and real hidapi (its libusb backend) talking to the simulated firmware through
// umockdev: enumerate by VID:PID and serial, open, identify, calibrate, capture. The oracle is
// the same capture over the in-process loopback (same seed), value for value, and for faults
// the uninterrupted capture. Runs under umockdev-wrapper (ctest label "usb"); a process where
// umockdev is not active FAILS rather than skipping.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/device/cancel.h"
#include "brdf/device/capture_session.h"
#include "brdf/device/usb_transport.h"
#include "brdf/device_emulation/emulated_usb.h"
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
                           return param_info.param == UsbPersonality::kBulk ? "Libusb" : "Hidapi";
                         });

// ---- The tool against an emulated instrument -------------------------------------------
// The emulated device lives in this process; the brdf child process inherits umockdev's
// environment (preload library and testbed), so it finds the device on "its" USB bus.

// `prefix` goes before the tool (e.g. a command that drops privileges).
std::string RunTool(const std::string& args, int* exit_code, const std::string& prefix = "",
                    const std::string& tool = BRDF_TOOL) {
  std::string out;
  std::FILE* pipe = ::popen((prefix + tool + " " + args + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return out;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  const int status = ::pclose(pipe);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

// `capture --device sim --transport usb|hid` opens the simulated firmware behind real libusb or
// hidapi (brdf::device_emulation's link, in the tool's own process): the file holds the values
// of the same capture over the in-process loopback.
TEST_P(UsbCapture, ToolCaptureOverTheEmulatedTransportEqualsTheLoopbackCapture) {
  char tmpl[] = "/tmp/brdf_usb_sim_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  const std::string common =
      " --device sim --material gold --sample g --theta-in 20,60 --theta-out-step 15 "
      "--phi-out-step 15 --seed 3 --quiet --out ";
  const std::string transport = GetParam() == UsbPersonality::kBulk ? "usb" : "hid";
  int code = -1;
  const std::string loop_log = RunTool("capture" + common + dir + "/loop.bpc", &code);
  ASSERT_EQ(code, 0) << loop_log;
  const std::string emulated_log =
      RunTool("capture --transport " + transport + common + dir + "/emulated.bpc", &code);
  ASSERT_EQ(code, 0) << emulated_log;
  const Measurement loop = LoadBpc(dir + "/loop.bpc");
  const Measurement emulated = LoadBpc(dir + "/emulated.bpc");
  ASSERT_EQ(emulated.slices.size(), 2u);
  ExpectSameValues(emulated.slices, loop.slices);
  EXPECT_EQ(emulated.metadata.instrument_serial, loop.metadata.instrument_serial);
  std::filesystem::remove_all(dir);
}

TEST_P(UsbCapture, DevicesListsTheInstrumentAndCaptureOpensItByVidPidSerial) {
  int code = -1;
  EXPECT_NE(RunTool("devices", &code).find("no instruments found"), std::string::npos);
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 15, 15);
  c.serial = "SN-4711";
  EmulatedUsbInstrument emu(c, GetParam());
  const bool usb = GetParam() == UsbPersonality::kBulk;
  const std::string json = RunTool("devices --json", &code);
  EXPECT_EQ(code, 0) << json;
  EXPECT_NE(json.find(usb ? "\"interface\": \"usb\"" : "\"interface\": \"hid\""), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"serial\": \"SN-4711\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"firmware\": \"" + c.model.firmware_version + "\""), std::string::npos)
      << json;
  const std::string text = RunTool("devices", &code);
  EXPECT_NE(
      text.find(std::string(usb ? "usb" : "hid") + ":1209:" + (usb ? "b7d1" : "b7d2") + ":SN-4711"),
      std::string::npos)
      << text;

  char tmpl[] = "/tmp/brdf_usb_cli_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const std::string out = std::string(tmpl) + "/real.bpc";
  const std::string spec =
      std::string(usb ? "usb" : "hid") + ":1209:" + (usb ? "b7d1" : "b7d2") + ":SN-4711";
  const std::string wrong =
      RunTool("capture --device " + spec + "0 --sample s --out " + out, &code);
  EXPECT_EQ(code, 1) << wrong;
  EXPECT_NE(wrong.find("SN-47110"), std::string::npos) << wrong;
  const std::string log = RunTool("capture --device " + spec + " --sample s --out " + out, &code);
  EXPECT_EQ(code, 0) << log;
  const Measurement m = LoadBpc(out);
  EXPECT_EQ(m.metadata.instrument_serial, "SN-4711");
  EXPECT_EQ(m.slices.size(), 4u);
  std::filesystem::remove_all(tmpl);
}

// Root opens any node (CAP_DAC_OVERRIDE), so as root the tool runs with that capability
// dropped (setpriv): the prefix RunTool puts before the tool.
std::string AsUser() {
  return ::geteuid() == 0 ? "setpriv --bounding-set -dac_override,-dac_read_search " : "";
}

TEST_P(UsbCapture, PermissionDeniedIsOneLineNamingTheNodeTheCauseAndTheUdevRule) {
  // The emulated node with mode 000, as without the udev rule.
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 15, 15);
  EmulatedUsbInstrument emu(c, GetParam());
  emu.SetNodeMode(0);
  const std::string as_user = AsUser();
  const bool usb = GetParam() == UsbPersonality::kBulk;
  const std::string spec = std::string(usb ? "usb" : "hid") + ":1209:" + (usb ? "b7d1" : "b7d2");
  // The device (its IDs and node), the cause, and the remedy: the shipped rule, where it is
  // installed and where udev reads it, the reload, the replug.
  const std::vector<std::string> wanted = {spec.substr(4),      emu.DeviceNode(),
                                           "permission denied", "70-brdf-scatterometer.rules",
                                           "/lib/udev/rules.d", "/etc/udev/rules.d",
                                           "udevadm",           "plug the instrument in again"};
  int code = -1;
  const std::string listed = RunTool("devices", &code, as_user);
  EXPECT_EQ(code, 0) << listed;
  const auto line_with = [](const std::string& text, const std::string& what) {
    const std::size_t at = text.find(what);
    if (at == std::string::npos) return std::string();
    const std::size_t begin = text.rfind('\n', at), end = text.find('\n', at);
    return text.substr(begin == std::string::npos ? 0 : begin + 1,
                       end == std::string::npos ? std::string::npos : end - begin - 1);
  };
  const std::string device_line = line_with(listed, spec);
  EXPECT_EQ(std::count(listed.begin(), listed.end(), '\n'), 1) << listed;
  for (const std::string& w : wanted)
    EXPECT_NE(device_line.find(w), std::string::npos) << "'" << w << "' in: " << listed;

  char tmpl[] = "/tmp/brdf_usb_denied_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl), nullptr);
  const std::string out = std::string(tmpl) + "/c.bpc";
  const std::string refused =
      RunTool("capture --device " + spec + " --sample s --out " + out + " --quiet", &code, as_user);
  EXPECT_EQ(code, 1) << refused;
  EXPECT_EQ(std::count(refused.begin(), refused.end(), '\n'), 1) << refused;
  for (const std::string& w : wanted)
    EXPECT_NE(refused.find(w), std::string::npos) << "'" << w << "' in: " << refused;
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(tmpl);
}

// An installed tree (the Debian package under /usr, a moved prefix) names its own copy of the
// rule in the remedy, found from the executable's folder, not the configured prefix's.
TEST_P(UsbCapture, PermissionDeniedNamesTheRuleOfTheInstalledTree) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 15, 15);
  EmulatedUsbInstrument emu(c, GetParam());
  emu.SetNodeMode(0);
  // <tree>/bin/brdf (a hard link: /proc/self/exe is then this path) and
  // <tree>/lib/udev/rules.d/70-brdf-scatterometer.rules, the layout `cmake --install` makes.
  std::string tmpl = std::string(BRDF_BINARY_DIR) + "/brdf_udev_tree_XXXXXX";
  ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
  const std::filesystem::path tree = tmpl;
  std::filesystem::create_directories(tree / "bin");
  std::filesystem::create_directories(tree / "lib/udev/rules.d");
  std::filesystem::create_hard_link(BRDF_TOOL, tree / "bin/brdf");
  std::filesystem::copy_file(
      std::string(BRDF_SOURCE_DIR) + "/device/udev/70-brdf-scatterometer.rules",
      tree / "lib/udev/rules.d/70-brdf-scatterometer.rules");
  int code = -1;
  const std::string listed = RunTool("devices", &code, AsUser(), (tree / "bin/brdf").string());
  EXPECT_EQ(code, 0) << listed;
  EXPECT_NE(listed.find("permission denied"), std::string::npos) << listed;
  EXPECT_NE(listed.find("(installed in " + (tree / "lib/udev/rules.d").string() + ","),
            std::string::npos)
      << listed;
  std::filesystem::remove_all(tree);
}

// ---- Faults over every transport ---------------------------------------------------------

enum class Link { kLoopback, kLibusb, kHidapi };

// One instrument behind one transport, for a session.
struct Instrument {
  std::unique_ptr<SimulatedFirmware> firmware;  // loopback
  std::unique_ptr<LoopbackTransport> loop;
  std::unique_ptr<EmulatedUsbInstrument> emulated;  // usb, hid
  std::unique_ptr<Transport> usb;
  Transport& link() { return loop ? static_cast<Transport&>(*loop) : *usb; }
};

std::unique_ptr<Instrument> Make(Link kind, const SimulatorConfig& c) {
  auto i = std::make_unique<Instrument>();
  if (kind == Link::kLoopback) {
    i->firmware = std::make_unique<SimulatedFirmware>(c);
    i->loop = std::make_unique<LoopbackTransport>(*i->firmware);
  } else {
    i->emulated = std::make_unique<EmulatedUsbInstrument>(
        c, kind == Link::kLibusb ? UsbPersonality::kBulk : UsbPersonality::kHid);
    i->usb = Open(*i->emulated);
  }
  return i;
}

struct FaultCase {
  std::string name;
  FaultPlan plan;
  CaptureOutcome outcome;  // of the faulty run
  std::string message;     // in the message (kFailed) or in a retry notice (kFinished)
  InstrumentProblem problem = InstrumentProblem::kNone;
  bool usb_only = false;  // transport-level fault
  // A hold (FaultType::kHold) whose start raises the session's cancel: the user's Ctrl-C at a
  // chosen frame, with no race against real time.
  bool cancel_at_hold = false;
};

// Each firmware fault is placed at the 4th frame of the stream at θin 20° (its SLICE_BEGIN is the
// 1st): a ROW_DATA of the second slice, frame 30 of an undisturbed capture on the coarse 5° grid
// (8 set-up frames, 18 per slice). Counted within that stream, not from the first frame, the
// place does not move when a loaded machine makes an earlier step be measured again (a HID
// report hidapi dropped, a reply later than the timeout): such a retry sends frames of its own.
std::vector<FaultCase> FaultCases() {
  auto plan = [](FaultType t, std::uint64_t n) {
    Fault f{t, n};
    if (t != FaultType::kEndpointHalt) f = Fault{t, 4, 20.0f};
    return FaultPlan{{f}};
  };
  using O = CaptureOutcome;
  return {
      {"corrupt", plan(FaultType::kCorrupt, 30), O::kFinished, "CRC-32"},
      {"timeout", plan(FaultType::kTimeout, 30), O::kFinished, "timeout"},
      {"duplicate", plan(FaultType::kDuplicate, 30), O::kFinished, ""},
      {"reorder", plan(FaultType::kReorder, 30), O::kFinished, "out of order"},
      {"halt", plan(FaultType::kEndpointHalt, 12), O::kFinished, "", InstrumentProblem::kNone,
       true},
      {"disconnect", plan(FaultType::kDisconnect, 30), O::kFailed, "disconnected"},
      {"stall", plan(FaultType::kStall, 30), O::kFailed, "stopped answering"},
      {"lamp", plan(FaultType::kLampFailure, 30), O::kFailed, "lamp",
       InstrumentProblem::kLampFailure},
      {"contact", plan(FaultType::kSampleContact, 30), O::kFailed, "contact",
       InstrumentProblem::kSampleNotInContact},
      {"overtemp", plan(FaultType::kOverTemperature, 30), O::kFailed, "temperature",
       InstrumentProblem::kOverTemperature},
      {"cancel", plan(FaultType::kHold, 30), O::kInterrupted, "cancelled", InstrumentProblem::kNone,
       false, true},
  };
}

class FaultsOver : public ::testing::TestWithParam<Link> {
 protected:
  void SetUp() override {
    if (GetParam() != Link::kLoopback) {
      ASSERT_TRUE(UmockdevAvailable())
          << "umockdev is not active: run this test under umockdev-wrapper (ctest does)";
    }
    char tmpl[] = "/tmp/brdf_usb_faults_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Real time for USB and HID: a short reply timeout keeps the cases quick whose instrument goes
  // silent (timeout, stall), the driver's default (5 s) the others, so that on a loaded machine
  // a late reply is not taken for a fault.
  CaptureRequest Request(const std::string& name, int timeout_ms = 5000) const {
    CaptureRequest r;
    r.out_path = dir_ + "/" + name + ".bpc";
    r.theta_in_deg = {0, 20, 40, 60};
    r.sample_name = "gold";
    r.settings["seed"] = "11";
    r.driver.timeout_ms = timeout_ms;
    // hidapi keeps 30 input reports and drops the oldest when a loaded host falls behind: the
    // driver measures the step again, which must not use up the retries a fault case counts on.
    if (GetParam() == Link::kHidapi) r.driver.retries = 8;
    return r;
  }

  std::string dir_;
};

TEST_P(FaultsOver, EveryFaultGivesItsOutcomeAndResumeGivesTheUninterruptedCapture) {
  const SimulatorConfig clean = Config(LibraryMaterial("gold"), 1, 5, 5, /*seed=*/11);
  // The oracle: the same capture, undisturbed, over the loopback.
  const CaptureRequest whole = Request("whole");
  {
    SimulatedFirmware fw(clean);
    LoopbackTransport loop(fw);
    ASSERT_EQ(RunCaptureSession(whole, loop).outcome, CaptureOutcome::kFinished);
  }
  const Measurement expected = LoadBpc(whole.out_path);

  for (const FaultCase& k : FaultCases()) {
    if (k.usb_only && GetParam() == Link::kLoopback) continue;
    SCOPED_TRACE(k.name);
    SimulatorConfig faulty = clean;
    faulty.faults = k.plan;
    CancelSignal cancel;
    std::atomic<bool> released{false};
    if (k.cancel_at_hold) {
      faulty.on_hold = [&](std::uint64_t) { cancel.Raise(); };
      faulty.on_hold_released = [&] { released.store(true); };
    }
    const bool silent = k.name == "timeout" || k.name == "stall";
    const CaptureRequest request = Request(k.name, silent ? 400 : 5000);
    std::vector<std::string> retries;
    SessionEvents events;
    events.on_retry = [&](const std::string& m) { retries.push_back(m); };
    CaptureSessionResult r;
    std::uint64_t halts = 0;
    {
      std::unique_ptr<Instrument> inst = Make(GetParam(), faulty);
      r = RunCaptureSession(request, inst->link(), events, &cancel);
      if (inst->emulated) halts = inst->emulated->halts_cleared();
    }
    EXPECT_EQ(r.outcome, k.outcome) << r.message;
    EXPECT_EQ(r.problem, k.problem) << r.message;
    if (k.cancel_at_hold) {
      EXPECT_TRUE(cancel.raised());
      EXPECT_TRUE(released.load()) << "the cancel did not send ABORT to the instrument";
      if (GetParam() != Link::kHidapi) {
        EXPECT_TRUE(retries.empty()) << retries[0];
      }
    }
    if (k.outcome != CaptureOutcome::kFinished) {
      EXPECT_NE(r.message.find(k.message), std::string::npos) << r.message;
      EXPECT_EQ(r.next, NextStep::kResume);
      EXPECT_EQ(r.slices_saved, 1u) << r.message;
      // The file holds exactly the completed slice, never a partial one.
      const BpcReadResult partial = ReadBpc(request.out_path);
      EXPECT_FALSE(partial.finished);
      EXPECT_TRUE(partial.problems.empty());
      ASSERT_EQ(partial.measurement.slices.size(), 1u);
      // The fault fixed (a new instrument, same serial): resume completes the capture.
      CaptureRequest resume = request;
      resume.resume = true;
      std::unique_ptr<Instrument> fixed = Make(GetParam(), clean);
      const CaptureSessionResult rr = RunCaptureSession(resume, fixed->link());
      ASSERT_EQ(rr.outcome, CaptureOutcome::kFinished) << rr.message;
      EXPECT_TRUE(rr.resumed);
    } else {
      if (!k.message.empty()) {
        // The fault's own retry (after any a loaded machine caused before it).
        ASSERT_FALSE(retries.empty());
        EXPECT_TRUE(std::any_of(retries.begin(), retries.end(), [&](const std::string& m) {
          return m.find(k.message) != std::string::npos;
        })) << retries[0];
      }
      // A duplicated frame is dropped, not retried. (Over HID a retry can still happen on a
      // loaded machine: hidapi keeps only 30 input reports and drops the oldest when the host
      // falls behind, which the driver sees as a lost frame and measures again.)
      if (k.name == "duplicate" && GetParam() != Link::kHidapi) {
        EXPECT_TRUE(retries.empty()) << retries[0];
      }
      if (k.name == "halt" && GetParam() == Link::kLibusb) {
        EXPECT_EQ(halts, 1u);  // the transport cleared the halt and repeated the transfer
        EXPECT_TRUE(retries.empty()) << retries[0];
      }
    }
    const Measurement got = LoadBpc(request.out_path);
    ExpectSameValues(got.slices, expected.slices);
  }
}

// The bound of capture_session.h: a cancel ends a read waiting for a silent instrument within
// kCancelStepMs on USB and HID (at once on the loopback), not after the read's timeout, and the
// ABORT it sends reaches the instrument. The firmware holds its answer to IDENTIFY; the hold's
// start raises the cancel, so the read is waiting on a silent link when it is raised.
TEST_P(FaultsOver, ACancelEndsAReadOfASilentInstrumentWithinTheCancelStep) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 5, 5);
  c.faults = FaultPlan{{Fault{FaultType::kHold, 1}}};
  CancelSignal cancel;
  std::atomic<bool> released{false};
  c.on_hold = [&](std::uint64_t) { cancel.Raise(); };
  c.on_hold_released = [&] { released.store(true); };
  std::unique_ptr<Instrument> inst = Make(GetParam(), c);
  DriverOptions options;
  options.timeout_ms = 5000;
  Driver driver(inst->link(), options);
  driver.SetCancelFlag(&cancel);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    driver.Connect();
    ADD_FAILURE() << "Connect returned although the instrument holds its answer";
  } catch (const DriverFault& e) {
    EXPECT_EQ(e.kind(), FaultKind::kCancelled) << e.what();
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(released.load()) << "the cancel did not send ABORT to the instrument";
  // kCancelStepMs (50 ms) plus the ABORT's round trip; half the timeout leaves a loaded machine
  // its slack and still fails a read that waits out its 5 s.
  EXPECT_LT(ms, options.timeout_ms / 2.0);
  std::printf("cancel honoured after %.1f ms\n", ms);
}

// A cancel from another thread while the read waits on a held firmware: the read waits for it
// (it is not a timeout, so nothing is retried), and the ABORT it sends ends the hold. The hold's
// start is the one event the cancelling thread waits for; the 100 ms after it only make sure the
// read is already waiting (a read that did not wait would time out at once and retry).
TEST_P(FaultsOver, ACancelFromAnotherThreadEndsTheHoldWithoutARetry) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 5, 5, /*seed=*/11);
  c.faults = FaultPlan{{Fault{FaultType::kHold, 4, 20.0f}}};
  CancelSignal cancel;
  std::promise<void> hold_started;
  std::atomic<bool> released{false}, held{false};
  c.on_hold = [&](std::uint64_t) {
    held.store(true);
    hold_started.set_value();
  };
  c.on_hold_released = [&] { released.store(true); };
  std::thread canceller([&, started = hold_started.get_future()]() mutable {
    started.wait();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    cancel.Raise();
  });
  CaptureRequest request = Request("held");
  std::vector<std::string> retries;
  SessionEvents events;
  events.on_retry = [&](const std::string& m) { retries.push_back(m); };
  CaptureSessionResult r;
  {
    std::unique_ptr<Instrument> inst = Make(GetParam(), c);
    r = RunCaptureSession(request, inst->link(), events, &cancel);
  }
  if (!held.load()) hold_started.set_value();  // (a capture that never held: fails below)
  canceller.join();
  EXPECT_TRUE(held.load());
  EXPECT_EQ(r.outcome, CaptureOutcome::kInterrupted) << r.message;
  EXPECT_NE(r.message.find("cancelled"), std::string::npos) << r.message;
  // (Over HID a loaded host can lose a report, which is measured again: see the duplicate case.)
  if (GetParam() != Link::kHidapi) {
    EXPECT_TRUE(retries.empty()) << retries[0];
  }
  EXPECT_TRUE(released.load()) << "the cancel did not send ABORT to the instrument";
  EXPECT_EQ(r.slices_saved, 1u);
  EXPECT_EQ(ReadBpc(request.out_path).measurement.slices.size(), 1u);
}

// A silent instrument over real libusb and hidapi: the read returns nothing after the timeout
// (not before), and the driver reports a timeout. The firmware never answers IDENTIFY until
// ABORT, so nothing else can be late.
TEST_P(FaultsOver, ASilentInstrumentTimesOutAfterTheReplyTimeout) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 5, 5);
  c.faults = FaultPlan{{Fault{FaultType::kTimeout, 1}}};
  std::unique_ptr<Instrument> inst = Make(GetParam(), c);
  DriverOptions options;
  options.timeout_ms = 300;
  Driver driver(inst->link(), options);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    driver.Connect();
    ADD_FAILURE() << "Connect returned although the instrument is silent";
  } catch (const DriverFault& e) {
    EXPECT_EQ(e.kind(), FaultKind::kTimeout) << e.what();
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  // The loopback runs on virtual time; USB and HID wait the timeout out.
  if (GetParam() != Link::kLoopback) {
    EXPECT_GE(ms, options.timeout_ms - 1.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Links, FaultsOver,
                         ::testing::Values(Link::kLoopback, Link::kLibusb, Link::kHidapi),
                         [](const auto& param_info) {
                           switch (param_info.param) {
                             case Link::kLoopback:
                               return "Loopback";
                             case Link::kLibusb:
                               return "Libusb";
                             case Link::kHidapi:
                               return "Hidapi";
                           }
                           return "";
                         });

}  // namespace
}  // namespace brdf::device
