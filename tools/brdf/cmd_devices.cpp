// `brdf devices`: the instruments on USB and HID, one line each (or JSON).
#include <cstdio>
#include <string>

#include "brdf/device/usb_models.h"
#include "brdf/device/usb_transport.h"
#include "commands.h"

namespace brdf::cli {
namespace {

std::string Hex4(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v);
  return buf;
}

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

const char* ProblemName(device::AccessProblem p) {
  switch (p) {
    case device::AccessProblem::kNone:
      return "";
    case device::AccessProblem::kPermission:
      return "permission denied";
    case device::AccessProblem::kBusy:
      return "in use";
    case device::AccessProblem::kOther:
      return "not answering";
  }
  return "";
}

}  // namespace

int RunDevices(const DevicesOptions& o) {
  const std::vector<device::FoundInstrument> found = device::ListInstruments(/*identify=*/true);
  std::string looked;
  for (const device::UsbModel& m : device::UsbModels())
    looked += (looked.empty() ? "" : ", ") + std::string(m.model) + " (USB " + Hex4(m.vendor_id) +
              ":" + Hex4(m.bulk_product_id) + ", HID " + Hex4(m.vendor_id) + ":" +
              Hex4(m.hid_product_id) + ")";
  if (o.json) {
    std::printf("{\n  \"instruments\": [");
    for (std::size_t i = 0; i < found.size(); ++i) {
      const device::FoundInstrument& f = found[i];
      std::printf(
          "%s\n    {\"interface\": %s, \"vendor_id\": \"%s\", \"product_id\": \"%s\", "
          "\"model\": %s, \"serial\": %s, \"firmware\": %s, \"path\": %s, \"node\": %s, "
          "\"problem\": %s, \"detail\": %s}",
          i == 0 ? "" : ",", f.kind == device::DeviceSpec::Kind::kUsb ? "\"usb\"" : "\"hid\"",
          Hex4(f.vendor_id).c_str(), Hex4(f.product_id).c_str(), JsonString(f.model).c_str(),
          JsonString(f.serial).c_str(), JsonString(f.firmware_version).c_str(),
          JsonString(f.bus_path).c_str(), JsonString(f.device_node).c_str(),
          JsonString(ProblemName(f.problem)).c_str(), JsonString(f.problem_detail).c_str());
    }
    std::printf("%s]\n}\n", found.empty() ? "" : "\n  ");
    return 0;
  }
  if (found.empty()) {
    std::printf("no instruments found (looked for %s)\n", looked.c_str());
    return 0;
  }
  for (const device::FoundInstrument& f : found) {
    const bool usb = f.kind == device::DeviceSpec::Kind::kUsb;
    std::string line = std::string(usb ? "usb" : "hid") + ":" + Hex4(f.vendor_id) + ":" +
                       Hex4(f.product_id) + (f.serial.empty() ? "" : ":" + f.serial) + "  " +
                       f.model;
    if (!f.firmware_version.empty()) line += ", firmware " + f.firmware_version;
    line += ", " + f.bus_path;
    if (!f.device_node.empty()) line += " (" + f.device_node + ")";
    // For a permission problem the library's detail is the whole clause: cause, node, remedy.
    if (f.problem == device::AccessProblem::kPermission)
      line += " — " + f.problem_detail;
    else if (f.problem != device::AccessProblem::kNone)
      line += std::string(" — ") + ProblemName(f.problem) +
              (f.problem_detail.empty() ? "" : " (" + f.problem_detail + ")");
    std::printf("%s\n", line.c_str());
  }
  return 0;
}

}  // namespace brdf::cli
