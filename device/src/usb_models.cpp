#include "brdf/device/usb_models.h"

#include <cctype>

#include "brdf/core/error.h"

namespace brdf::device {
namespace {

constexpr UsbModel kModels[] = {
    {.model = "BRDF-SIM MD2",
     .vendor_id = 0x1209,
     .bulk_product_id = 0xB7D1,
     .hid_product_id = 0xB7D2},
};

std::optional<std::uint16_t> ParseHex16(std::string_view text) {
  if (text.empty() || text.size() > 4) return std::nullopt;
  std::uint16_t v = 0;
  for (char c : text) {
    const int d = std::isdigit(static_cast<unsigned char>(c))
                      ? c - '0'
                      : (std::isxdigit(static_cast<unsigned char>(c))
                             ? std::tolower(static_cast<unsigned char>(c)) - 'a' + 10
                             : -1);
    if (d < 0) return std::nullopt;
    v = static_cast<std::uint16_t>(v * 16 + d);
  }
  return v;
}

}  // namespace

std::span<const UsbModel> UsbModels() { return kModels; }

std::optional<UsbModel> FindUsbModel(std::uint16_t vendor_id, std::uint16_t product_id) {
  for (const UsbModel& m : kModels)
    if (m.vendor_id == vendor_id &&
        (m.bulk_product_id == product_id || m.hid_product_id == product_id))
      return m;
  return std::nullopt;
}

const UsbModel& UsbModelNamed(std::string_view model) {
  std::string names;
  for (const UsbModel& m : kModels) {
    if (m.model == model) return m;
    names += (names.empty() ? "" : ", ") + std::string(m.model);
  }
  throw InvalidArgument("no USB identity known for instrument model '" + std::string(model) +
                        "' (known: " + names + ")");
}

DeviceSpec ParseDeviceSpec(std::string_view text) {
  const std::string expected =
      "expected sim, usb[:VID:PID[:SERIAL]] or hid[:VID:PID[:SERIAL]] (IDs in hexadecimal)";
  DeviceSpec spec;
  const std::size_t colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  if (kind == "sim")
    spec.kind = DeviceSpec::Kind::kSim;
  else if (kind == "usb")
    spec.kind = DeviceSpec::Kind::kUsb;
  else if (kind == "hid")
    spec.kind = DeviceSpec::Kind::kHid;
  else
    throw InvalidArgument(expected + ", got '" + std::string(text) + "'");
  if (colon == std::string_view::npos) return spec;
  if (spec.kind == DeviceSpec::Kind::kSim)
    throw InvalidArgument("the simulated instrument takes no IDs: " + expected + ", got '" +
                          std::string(text) + "'");
  const std::string_view rest = text.substr(colon + 1);
  const std::size_t c2 = rest.find(':');
  if (c2 == std::string_view::npos)
    throw InvalidArgument(expected + ", got '" + std::string(text) + "' (a VID needs its PID)");
  const std::string_view vid = rest.substr(0, c2);
  const std::string_view after = rest.substr(c2 + 1);
  const std::size_t c3 = after.find(':');
  const std::string_view pid = after.substr(0, c3);
  spec.vendor_id = ParseHex16(vid);
  spec.product_id = ParseHex16(pid);
  if (!spec.vendor_id || !spec.product_id)
    throw InvalidArgument(expected + ", got '" + std::string(text) +
                          "' (VID and PID are 1 to 4 hexadecimal digits)");
  if (c3 != std::string_view::npos) {
    spec.serial = std::string(after.substr(c3 + 1));
    if (spec.serial.empty())
      throw InvalidArgument(expected + ", got '" + std::string(text) + "' (empty serial)");
  }
  return spec;
}

}  // namespace brdf::device
