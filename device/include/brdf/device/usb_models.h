// The USB identity of each instrument model: table data, so a new model is a new row.
//
// Every model offers the same protocol (protocol.h) over two USB personalities:
//   - vendor-specific interface (class 0xFF) with one bulk OUT and one bulk IN endpoint of a
//     USB 2.0 high-speed packet size (512 bytes), driven with libusb;
//   - HID interface (class 0x03) with interrupt IN and OUT endpoints carrying fixed-size
//     reports, driven with hidapi (hidraw in the field, its libusb backend in tests). Each
//     report carries a count byte and up to report_bytes − 1 stream bytes (PROTOCOL.md §2).
// The vendor and product IDs below are placeholders from the pid.codes open-source range
// (0x1209) until the instrument maker assigns its own; the udev rule
// (device/udev/70-brdf-scatterometer.rules) lists the same numbers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace brdf::device {

struct UsbModel {
  std::string_view model;  // as IDENTIFY reports it
  std::uint16_t vendor_id = 0;
  std::uint16_t bulk_product_id = 0;  // the vendor-interface personality
  std::uint16_t hid_product_id = 0;   // the HID personality
  std::uint8_t interface_number = 0;
  std::uint8_t bulk_out_endpoint = 0x01;
  std::uint8_t bulk_in_endpoint = 0x81;
  std::size_t bulk_packet_bytes = 512;  // wMaxPacketSize of both bulk endpoints (high speed)
  std::uint8_t hid_out_endpoint = 0x02;
  std::uint8_t hid_in_endpoint = 0x82;
  std::size_t hid_report_bytes = 64;  // wMaxPacketSize of both interrupt endpoints
  // Longest wait for the first byte of a reply: the longest exposure (2 s) plus readout.
  int reply_timeout_ms = 5000;
  // Transfers of one bulk IN request: a multiple of the packet size, so a read never
  // overflows (the host always asks for whole packets).
  std::size_t bulk_read_bytes = 16384;
};

std::span<const UsbModel> UsbModels();
// The model whose vendor ID and (bulk or HID) product ID these are, or nullopt.
std::optional<UsbModel> FindUsbModel(std::uint16_t vendor_id, std::uint16_t product_id);
// The model of this IDENTIFY name; throws InvalidArgument listing the known names.
const UsbModel& UsbModelNamed(std::string_view model);

// What `--device` names: the simulated instrument or a real one over USB or HID, optionally
// narrowed to one vendor/product ID and serial number.
struct DeviceSpec {
  enum class Kind { kSim, kUsb, kHid };
  Kind kind = Kind::kSim;
  std::optional<std::uint16_t> vendor_id, product_id;
  std::string serial;  // empty: any
};

// "sim", "usb", "usb:1209:B7D1", "hid:1209:B7D2:SN123" (IDs in hexadecimal). Throws
// InvalidArgument naming what was expected.
DeviceSpec ParseDeviceSpec(std::string_view text);

}  // namespace brdf::device
