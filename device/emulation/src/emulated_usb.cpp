// umockdev glue: a UMockdevIoctlBase whose "handle-ioctl" signal answers usbdevfs requests
// for one emulated device node with a SimulatedFirmware (emulated_usb.h).
//
// <sys/ioctl.h> must come before <linux/usbdevice_fs.h> (docs/design.md §3, known snags).
#include <sys/ioctl.h>
#include <sys/stat.h>
// clang-format off
#include <linux/usbdevice_fs.h>
// clang-format on
#include "brdf/device_emulation/emulated_usb.h"

#include <umockdev.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/device/usb_transport.h"

namespace brdf::device {
namespace {

// One interrupt IN report per millisecond (bInterval 1 at full speed; see the header).
constexpr int kHidReportIntervalUs = 1000;

constexpr std::uint8_t kDescDevice = 0x01, kDescConfig = 0x02, kDescString = 0x03,
                       kDescHidReport = 0x22;

// A HID report descriptor for one vendor-defined 64-byte input and output report.
std::vector<std::uint8_t> HidReportDescriptor(std::size_t report_bytes) {
  const auto n = static_cast<std::uint8_t>(report_bytes);
  return {
      0x06, 0x00, 0xFF,  // usage page: vendor defined 0xFF00
      0x09, 0x01,        // usage 1
      0xA1, 0x01,        // collection: application
      0x09, 0x02, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, n, 0x81, 0x02,  // input: n bytes
      0x09, 0x03, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, n, 0x91, 0x02,  // output: n bytes
      0xC0};
}

void Put16(std::vector<std::uint8_t>& v, std::size_t n) {
  v.push_back(static_cast<std::uint8_t>(n & 0xff));
  v.push_back(static_cast<std::uint8_t>(n >> 8));
}

// Device descriptor followed by the configuration descriptor (what sysfs "descriptors" holds).
std::vector<std::uint8_t> Descriptors(const UsbModel& m, UsbPersonality p,
                                      std::vector<std::uint8_t>* config_only) {
  std::vector<std::uint8_t> d = {18,   kDescDevice, 0x00, 0x02,  // USB 2.00
                                 0x00, 0x00,        0x00, 64};   // class per interface, EP0 64
  Put16(d, m.vendor_id);
  Put16(d, p == UsbPersonality::kBulk ? m.bulk_product_id : m.hid_product_id);
  Put16(d, 0x0100);                 // bcdDevice
  d.insert(d.end(), {1, 2, 3, 1});  // manufacturer, product, serial strings; one configuration
  std::vector<std::uint8_t> c;
  const bool hid = p == UsbPersonality::kHid;
  const std::size_t total = 9 + 9 + (hid ? 9 : 0) + 7 + 7;
  c.insert(c.end(), {9, kDescConfig});
  Put16(c, total);
  c.insert(c.end(), {1, 1, 0, 0x80, 50});  // one interface, config 1, bus powered, 100 mA
  c.insert(c.end(), {9, 0x04, m.interface_number, 0, 2,
                     static_cast<std::uint8_t>(hid ? 0x03 : 0xFF), 0, 0, 0});
  if (hid) {
    const std::size_t report = HidReportDescriptor(m.hid_report_bytes).size();
    c.insert(c.end(), {9, 0x21, 0x11, 0x01, 0, 1, kDescHidReport});
    Put16(c, report);
    c.insert(c.end(), {7, 0x05, m.hid_in_endpoint, 0x03});
    Put16(c, m.hid_report_bytes);
    c.push_back(1);  // bInterval 1: every frame (1 ms at full speed)
    c.insert(c.end(), {7, 0x05, m.hid_out_endpoint, 0x03});
    Put16(c, m.hid_report_bytes);
    c.push_back(1);
  } else {
    c.insert(c.end(), {7, 0x05, m.bulk_out_endpoint, 0x02});
    Put16(c, m.bulk_packet_bytes);
    c.push_back(0);
    c.insert(c.end(), {7, 0x05, m.bulk_in_endpoint, 0x02});
    Put16(c, m.bulk_packet_bytes);
    c.push_back(0);
  }
  if (config_only) *config_only = c;
  d.insert(d.end(), c.begin(), c.end());
  return d;
}

std::vector<std::uint8_t> StringDescriptor(const std::string& s) {
  std::vector<std::uint8_t> d = {static_cast<std::uint8_t>(2 + 2 * s.size()), kDescString};
  for (char ch : s) {
    d.push_back(static_cast<std::uint8_t>(ch));
    d.push_back(0);
  }
  return d;
}

std::string Hex(const std::vector<std::uint8_t>& bytes) {
  std::string s;
  char b[4];
  for (std::uint8_t x : bytes) {
    std::snprintf(b, sizeof b, "%02x", x);
    s += b;
  }
  return s;
}

}  // namespace

bool UmockdevAvailable() {
  // umockdev_in_mock_environment() answers false under umockdev-wrapper in umockdev 0.17, so
  // look for the preload library among the mapped objects instead.
  std::FILE* maps = std::fopen("/proc/self/maps", "r");
  if (maps == nullptr) return false;
  char line[4096];
  bool found = false;
  while (!found && std::fgets(line, sizeof line, maps) != nullptr)
    found = std::strstr(line, "libumockdev-preload") != nullptr;
  std::fclose(maps);
  return found;
}

struct EmulatedUsbInstrument::Impl {
  struct Urb {
    UMockdevIoctlData* data = nullptr;  // the resolved usbdevfs_urb (one reference held)
    usbdevfs_urb* urb() const { return reinterpret_cast<usbdevfs_urb*>(data->data); }
  };

  SimulatorConfig config;
  UsbPersonality personality;
  UsbModel model;
  std::string devnode, syspath;
  std::mutex mutex;  // the handler runs on umockdev's thread; getters on the caller's
  SimulatedFirmware firmware;
  UMockdevTestbed* testbed = nullptr;
  UMockdevIoctlBase* handler = nullptr;
  std::deque<Urb> pending_in;  // IN URBs waiting for firmware bytes
  std::deque<Urb> done;        // URBs ready to be reaped
  std::atomic<std::uint64_t> halts_cleared{0}, in_transfers{0}, frames_sent{0};
  std::uint64_t in_completions = 0;  // counts IN transfers for FaultType::kEndpointHalt
  bool in_halted = false;
  std::vector<std::uint8_t> carry;  // bytes of a stalled transfer, delivered next
  std::atomic<bool> unplugged{false};
  std::chrono::steady_clock::time_point last_in{};

  Impl(SimulatorConfig c, UsbPersonality p, const UsbModel& m)
      : config(c), personality(p), model(m), firmware(std::move(c)) {}

  bool Gone() const { return unplugged.load() || !firmware.link_up(); }

  static void Release(Urb& u) {
    if (u.data) umockdev_ioctl_data_unref(u.data);
    u.data = nullptr;
  }

  std::vector<std::uint8_t> ControlReply(const std::uint8_t* setup, bool* stall) {
    const std::uint8_t request_type = setup[0], request = setup[1];
    const std::uint16_t value = static_cast<std::uint16_t>(setup[2] | (setup[3] << 8));
    *stall = false;
    if (request == 0x06 && (request_type & 0x80)) {  // GET_DESCRIPTOR
      const std::uint8_t type = static_cast<std::uint8_t>(value >> 8), index = value & 0xff;
      std::vector<std::uint8_t> config_only;
      const std::vector<std::uint8_t> all = Descriptors(model, personality, &config_only);
      if (type == kDescDevice) return {all.begin(), all.begin() + 18};
      if (type == kDescConfig) return config_only;
      if (type == kDescString) {
        if (index == 0) return {4, kDescString, 0x09, 0x04};  // English (US)
        if (index == 1) return StringDescriptor("brdf-toolchain");
        if (index == 2) return StringDescriptor(config.model.model);
        if (index == 3) return StringDescriptor(config.serial);
      }
      if (type == kDescHidReport && personality == UsbPersonality::kHid)
        return HidReportDescriptor(model.hid_report_bytes);
      *stall = true;
      return {};
    }
    if ((request_type & 0x60) == 0x20) return {};  // class requests (SET_IDLE…): accepted
    if (request == 0x09 || request == 0x0B || request == 0x01) return {};  // SET_CONFIG/IFACE
    *stall = true;
    return {};
  }

  // Bytes for the host: those a stalled transfer kept first, then the firmware's.
  std::size_t Pull(std::span<std::uint8_t> out) {
    const std::size_t c = std::min(out.size(), carry.size());
    std::copy_n(carry.begin(), c, out.begin());
    carry.erase(carry.begin(), carry.begin() + static_cast<std::ptrdiff_t>(c));
    return c + (c < out.size() ? firmware.Transmit(out.subspan(c)) : 0);
  }

  // Fills the first pending IN URB from the firmware, if the firmware has bytes.
  bool CompleteOneIn() {
    if (pending_in.empty()) return false;
    Urb& u = pending_in.front();
    usbdevfs_urb* urb = u.urb();
    const bool hid = personality == UsbPersonality::kHid;
    const auto now = std::chrono::steady_clock::now();
    if (hid && now - last_in < std::chrono::microseconds(kHidReportIntervalUs)) return false;
    if (in_halted) {
      if (hid) in_halted = false;  // the interrupt endpoint recovers by itself (see header)
      urb->status = -EPIPE;
      urb->actual_length = 0;
      done.push_back(u);
      pending_in.pop_front();
      return true;
    }
    auto* buffer = static_cast<std::uint8_t*>(urb->buffer);
    std::size_t n = 0;
    if (hid) {
      const std::size_t report = std::min<std::size_t>(
          model.hid_report_bytes, static_cast<std::size_t>(urb->buffer_length));
      n = Pull(std::span<std::uint8_t>(buffer + 1, report - 1));
      if (n == 0) return false;
      buffer[0] = static_cast<std::uint8_t>(n);
      std::fill(buffer + 1 + n, buffer + report, 0);
    } else {
      n = Pull(std::span<std::uint8_t>(buffer, static_cast<std::size_t>(urb->buffer_length)));
      if (n == 0) return false;
    }
    ++in_completions;
    if (config.faults.Has(FaultType::kEndpointHalt, in_completions)) {
      // The transfer stalls and delivers nothing; the device keeps the bytes for the transfer
      // after the halt is cleared, so clear-halt-and-retry loses nothing.
      carry.insert(carry.begin(), buffer + (hid ? 1 : 0), buffer + (hid ? 1 : 0) + n);
      in_halted = !hid;
      urb->status = -EPIPE;
      urb->actual_length = 0;
    } else {
      urb->status = 0;
      urb->actual_length =
          static_cast<int>(hid ? std::min<std::size_t>(model.hid_report_bytes,
                                                       static_cast<std::size_t>(urb->buffer_length))
                               : n);
      ++in_transfers;
    }
    last_in = now;
    frames_sent = firmware.frames_sent();
    done.push_back(u);
    pending_in.pop_front();
    return true;
  }

  gboolean Handle(UMockdevIoctlClient* client) {
    std::lock_guard lock(mutex);
    const gulong request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    switch (request) {
      case USBDEVFS_GET_CAPABILITIES: {
        UMockdevIoctlData* d = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), nullptr);
        const guint32 caps = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_BULK_CONTINUATION |
                             USBDEVFS_CAP_NO_PACKET_SIZE_LIM | USBDEVFS_CAP_ZERO_PACKET |
                             USBDEVFS_CAP_REAP_AFTER_DISCONNECT;
        std::memcpy(d->data, &caps, sizeof caps);
        umockdev_ioctl_data_unref(d);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_CLAIMINTERFACE:
      case USBDEVFS_RELEASEINTERFACE:
      case USBDEVFS_DISCONNECT_CLAIM:
      case USBDEVFS_SETINTERFACE:
      case USBDEVFS_SETCONFIGURATION:
      case USBDEVFS_RESET:
      case USBDEVFS_RESETEP:
        umockdev_ioctl_client_complete(client, Gone() ? -1 : 0, Gone() ? ENODEV : 0);
        return TRUE;
      case USBDEVFS_GETDRIVER:
        umockdev_ioctl_client_complete(client, -1, ENODATA);  // no kernel driver bound
        return TRUE;
      case USBDEVFS_IOCTL:
        umockdev_ioctl_client_complete(client, -1, ENODATA);
        return TRUE;
      case USBDEVFS_CLEAR_HALT:
        in_halted = false;
        ++halts_cleared;
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      case USBDEVFS_GET_SPEED:
        umockdev_ioctl_client_complete(client, 3, 0);  // USB_SPEED_HIGH
        return TRUE;
      case USBDEVFS_SUBMITURB: {
        if (Gone()) {
          umockdev_ioctl_client_complete(client, -1, ENODEV);
          return TRUE;
        }
        Urb u;
        u.data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
        usbdevfs_urb* urb = u.urb();
        UMockdevIoctlData* buf =
            umockdev_ioctl_data_resolve(u.data, offsetof(usbdevfs_urb, buffer),
                                        static_cast<gsize>(urb->buffer_length), nullptr);
        if (buf) umockdev_ioctl_data_unref(buf);  // stays attached to u.data
        urb = u.urb();
        auto* bytes = static_cast<std::uint8_t*>(urb->buffer);
        if (urb->type == USBDEVFS_URB_TYPE_CONTROL) {
          bool stall = false;
          const std::uint16_t length = static_cast<std::uint16_t>(bytes[6] | (bytes[7] << 8));
          const std::vector<std::uint8_t> reply = ControlReply(bytes, &stall);
          const std::size_t n = std::min<std::size_t>(reply.size(), length);
          std::memcpy(bytes + 8, reply.data(), n);
          urb->actual_length = static_cast<int>(n);
          urb->status = stall ? -EPIPE : 0;
          done.push_back(u);
        } else if (urb->endpoint & 0x80) {
          pending_in.push_back(u);
        } else {
          // OUT: the bytes go to the firmware now (HID: a count byte, then the stream bytes).
          std::size_t offset = 0, n = static_cast<std::size_t>(urb->buffer_length);
          if (personality == UsbPersonality::kHid) {
            offset = 1;
            n = std::min<std::size_t>(n > 0 ? bytes[0] : 0, n > 0 ? n - 1 : 0);
          }
          try {
            firmware.Receive(std::span<const std::uint8_t>(bytes + offset, n));
            urb->status = 0;
            urb->actual_length = urb->buffer_length;
          } catch (const Error&) {
            urb->status = -ESHUTDOWN;
            urb->actual_length = 0;
          }
          done.push_back(u);
        }
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_REAPURB:
      case USBDEVFS_REAPURBNDELAY: {
        if (done.empty() && Gone() && !pending_in.empty()) {
          Urb u = pending_in.front();
          pending_in.pop_front();
          u.urb()->status = -ESHUTDOWN;
          u.urb()->actual_length = 0;
          done.push_back(u);
        }
        if (done.empty()) CompleteOneIn();
        if (done.empty()) {
          umockdev_ioctl_client_complete(client, -1, Gone() ? ENODEV : EAGAIN);
          return TRUE;
        }
        Urb u = done.front();
        done.pop_front();
        UMockdevIoctlData* ptr = umockdev_ioctl_data_resolve(arg, 0, sizeof(gpointer), nullptr);
        umockdev_ioctl_data_set_ptr(ptr, 0, u.data);
        umockdev_ioctl_data_unref(ptr);
        Release(u);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_DISCARDURB: {
        const gulong address = reinterpret_cast<gulong>(*reinterpret_cast<void**>(arg->data));
        auto it = std::find_if(pending_in.begin(), pending_in.end(),
                               [&](const Urb& u) { return u.data->client_addr == address; });
        if (it == pending_in.end()) {
          umockdev_ioctl_client_complete(client, -1, EINVAL);
          return TRUE;
        }
        Urb u = *it;
        pending_in.erase(it);
        u.urb()->status = -ENOENT;
        u.urb()->actual_length = 0;
        done.push_back(u);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      default:
        umockdev_ioctl_client_complete(client, -1, ENOTTY);
        return TRUE;
    }
  }

  static gboolean OnIoctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    return static_cast<Impl*>(self)->Handle(client);
  }
};

EmulatedUsbInstrument::EmulatedUsbInstrument(SimulatorConfig config, UsbPersonality personality,
                                             const UsbModel& model) {
  if (!UmockdevAvailable())
    throw DeviceError(
        "the emulated USB instrument needs umockdev: run the program under umockdev-wrapper "
        "(Debian package umockdev)");
  impl_ = std::make_unique<Impl>(std::move(config), personality, model);
  Impl& m = *impl_;
  // One device per testbed: bus 1, device 2, below a root hub's port 1.
  m.devnode = "/dev/bus/usb/001/002";
  m.testbed = umockdev_testbed_new();
  m.handler = umockdev_ioctl_base_new();
  g_signal_connect(m.handler, "handle-ioctl", G_CALLBACK(&Impl::OnIoctl), &m);
  GError* error = nullptr;
  if (!umockdev_testbed_attach_ioctl(m.testbed, m.devnode.c_str(), m.handler, &error)) {
    const std::string why = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    g_object_unref(m.handler);
    g_object_unref(m.testbed);
    throw DeviceError("umockdev: cannot emulate " + m.devnode + ": " + why);
  }
  const std::vector<std::uint8_t> descriptors = Descriptors(model, personality, nullptr);
  const std::string description =
      "P: /devices/pci0000:00/0000:00:14.0/usb1/1-1\n"
      "N: bus/usb/001/002\n"
      "E: SUBSYSTEM=usb\n"
      "E: DEVTYPE=usb_device\n"
      "E: DRIVER=usb\n"
      "E: BUSNUM=001\n"
      "E: DEVNUM=002\n"
      "E: DEVNAME=" +
      m.devnode +
      "\n"
      "A: busnum=1\\n\n"
      "A: devnum=2\\n\n"
      "A: speed=480\\n\n"
      "A: bConfigurationValue=1\\n\n"
      "A: serial=" +
      m.config.serial +
      "\\n\n"
      "H: descriptors=" +
      Hex(descriptors) + "\n";
  if (!umockdev_testbed_add_from_string(m.testbed, description.c_str(), &error)) {
    const std::string why = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    g_object_unref(m.handler);
    g_object_unref(m.testbed);
    throw DeviceError("umockdev: cannot add the emulated device: " + why);
  }
  m.syspath = "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-1";
}

EmulatedUsbInstrument::~EmulatedUsbInstrument() {
  if (!impl_) return;
  {
    std::lock_guard lock(impl_->mutex);
    for (auto& u : impl_->pending_in) Impl::Release(u);
    for (auto& u : impl_->done) Impl::Release(u);
    impl_->pending_in.clear();
    impl_->done.clear();
  }
  umockdev_testbed_detach_ioctl(impl_->testbed, impl_->devnode.c_str(), nullptr);
  g_object_unref(impl_->handler);
  g_object_unref(impl_->testbed);
}

DeviceSpec EmulatedUsbInstrument::Spec() const {
  DeviceSpec s;
  s.kind =
      impl_->personality == UsbPersonality::kBulk ? DeviceSpec::Kind::kUsb : DeviceSpec::Kind::kHid;
  s.vendor_id = impl_->model.vendor_id;
  s.product_id = impl_->personality == UsbPersonality::kBulk ? impl_->model.bulk_product_id
                                                             : impl_->model.hid_product_id;
  s.serial = impl_->config.serial;
  return s;
}

std::uint64_t EmulatedUsbInstrument::halts_cleared() const { return impl_->halts_cleared; }
std::uint64_t EmulatedUsbInstrument::in_transfers() const { return impl_->in_transfers; }
std::uint64_t EmulatedUsbInstrument::frames_sent() const { return impl_->frames_sent; }

bool EmulatedUsbInstrument::firmware_silent() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->firmware.silent();
}

void EmulatedUsbInstrument::Unplug() { impl_->unplugged = true; }

void EmulatedUsbInstrument::SetNodeMode(unsigned mode) {
  gchar* root = umockdev_testbed_get_root_dir(impl_->testbed);
  const std::string node = std::string(root) + impl_->devnode;
  g_free(root);
  if (::chmod(node.c_str(), static_cast<mode_t>(mode)) != 0)
    throw DeviceError("umockdev: cannot change the mode of " + node + ": " + std::strerror(errno));
}

std::string EmulatedUsbInstrument::DeviceNode() const { return impl_->devnode; }

namespace {

class EmulatedLink final : public InstrumentLink {
 public:
  EmulatedLink(const SimulatorConfig& c, UsbPersonality p) : emulated_(c, p) {
    const DeviceSpec spec = emulated_.Spec();
    transport_ = p == UsbPersonality::kBulk ? OpenUsbTransport(spec) : OpenHidTransport(spec);
  }
  Transport& transport() override { return *transport_; }

 private:
  EmulatedUsbInstrument emulated_;
  std::unique_ptr<Transport> transport_;  // closed before the emulated device goes
};

}  // namespace

std::unique_ptr<InstrumentLink> OpenEmulatedLink(const SimulatorConfig& sim, SimLink link) {
  if (link == SimLink::kLoopback)
    throw InvalidArgument("the loopback is not an emulated USB or HID link");
  return std::make_unique<EmulatedLink>(
      sim, link == SimLink::kUsb ? UsbPersonality::kBulk : UsbPersonality::kHid);
}

}  // namespace brdf::device
