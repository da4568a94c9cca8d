// brdf::device's instrument factory (brdf/device/instrument_link.h) in process: the simulated
// instrument over the loopback, the emulated links only through the opener the caller hands in,
// and the refusals of configurations no link can run.
#include "brdf/device/instrument_link.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "brdf/core/error.h"
#include "brdf/device/driver.h"
#include "device_test_support.h"

namespace brdf::device {
namespace {

using testing::Config;
using testing::LibraryMaterial;

DeviceSpec SimSpec() { return ParseDeviceSpec("sim"); }

TEST(InstrumentLink, SimulatedInstrumentAnswersOverTheLoopback) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 0, 15, 15);
  c.serial = "SIM-LINK-1";
  const std::unique_ptr<InstrumentLink> link = OpenInstrumentLink(SimSpec(), c, SimLink::kLoopback);
  Driver driver(link->transport());
  const InstrumentInfo& info = driver.Connect();
  EXPECT_EQ(info.identity.serial, "SIM-LINK-1");
  EXPECT_EQ(info.geometry.theta_out_step_deg, 15.0f);
}

TEST(InstrumentLink, EmulatedLinkWithoutAnOpenerIsRefused) {
  const SimulatorConfig c = Config(LibraryMaterial("gold"), 0, 15, 15);
  for (SimLink l : {SimLink::kUsb, SimLink::kHid}) {
    try {
      OpenInstrumentLink(SimSpec(), c, l);
      ADD_FAILURE() << "an emulated link opened without an opener";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("built without"), std::string::npos) << e.what();
    }
  }
}

// What the factory handed to the opener (a plain function: EmulatedLinkOpener is a pointer).
SimLink g_opened_link = SimLink::kLoopback;
std::string g_opened_serial;

std::unique_ptr<InstrumentLink> RecordingOpener(const SimulatorConfig& sim, SimLink link) {
  g_opened_link = link;
  g_opened_serial = sim.serial;
  return OpenInstrumentLink(ParseDeviceSpec("sim"), sim, SimLink::kLoopback);
}

TEST(InstrumentLink, EmulatedLinksGoThroughTheOpenerWithTheSimulatorConfig) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 0, 15, 15);
  c.serial = "SIM-LINK-2";
  const auto link = OpenInstrumentLink(SimSpec(), c, SimLink::kHid, &RecordingOpener);
  EXPECT_EQ(g_opened_link, SimLink::kHid);
  EXPECT_EQ(g_opened_serial, "SIM-LINK-2");
  Driver driver(link->transport());
  EXPECT_EQ(driver.Connect().identity.serial, "SIM-LINK-2");
  // The loopback never asks the opener.
  g_opened_serial.clear();
  OpenInstrumentLink(SimSpec(), c, SimLink::kLoopback, &RecordingOpener);
  EXPECT_TRUE(g_opened_serial.empty());
}

TEST(InstrumentLink, EndpointHaltNeedsAnEndpoint) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 0, 15, 15);
  c.faults = ParseFaultPlan("halt:3");
  EXPECT_THROW(OpenInstrumentLink(SimSpec(), c, SimLink::kLoopback), InvalidArgument);
}

TEST(InstrumentLink, TransportNamesParseAndOthersAreRefused) {
  EXPECT_EQ(ParseSimLink("loopback"), SimLink::kLoopback);
  EXPECT_EQ(ParseSimLink("usb"), SimLink::kUsb);
  EXPECT_EQ(ParseSimLink("hid"), SimLink::kHid);
  EXPECT_THROW(ParseSimLink("USB"), InvalidArgument);
  EXPECT_THROW(ParseSimLink(""), InvalidArgument);
}

}  // namespace
}  // namespace brdf::device
