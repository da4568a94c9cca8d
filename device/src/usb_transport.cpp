// libusb and hidapi transports (usb_transport.h). The only translation unit that includes
// libusb.h and hidapi.h.
#include "brdf/device/usb_transport.h"

#include <hidapi/hidapi.h>
#include <libusb-1.0/libusb.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cwchar>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "brdf/core/error.h"
#include "brdf/device/cancel.h"
#include "brdf/device/driver.h"

namespace brdf::device {
namespace {

std::string Hex4(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v);
  return buf;
}

std::string Narrow(const wchar_t* w) {
  std::string s;
  if (w == nullptr) return s;
  for (; *w != 0; ++w) s += (*w >= 32 && *w < 127) ? static_cast<char>(*w) : '?';
  return s;
}

std::string LookedFor(const DeviceSpec& spec, const char* kind) {
  std::string s = std::string(kind) + " instrument";
  if (spec.vendor_id) s += " " + Hex4(*spec.vendor_id) + ":" + Hex4(*spec.product_id);
  if (!spec.serial.empty()) s += " with serial " + spec.serial;
  return s;
}

bool Matches(const DeviceSpec& spec, std::uint16_t vid, std::uint16_t pid, bool hid) {
  if (spec.vendor_id) return *spec.vendor_id == vid && *spec.product_id == pid;
  const std::optional<UsbModel> m = FindUsbModel(vid, pid);
  return m && (hid ? m->hid_product_id : m->bulk_product_id) == pid;
}

class CountingTransport : public Transport {
 public:
  TransportStats stats;
  void SetCancel(const CancelSignal* cancel) override { cancel_ = cancel; }

 protected:
  // Runs `attempt(wait_ms)` (one transfer waiting at most wait_ms; true when it ended with
  // bytes, an error or anything but a plain timeout) until it does so or `timeout_ms` passed:
  // in one wait without a cancel, in steps of at most kCancelStepMs with one, stopping at the
  // first step that ends with the cancel raised (usb_transport.h).
  template <class Attempt>
  void WaitInSteps(int timeout_ms, Attempt attempt) const {
    if (cancel_ == nullptr || timeout_ms <= kCancelStepMs) {
      attempt(timeout_ms);
      return;
    }
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      const int wait = static_cast<int>(std::clamp<long long>(left, 1, kCancelStepMs));
      if (attempt(wait) || cancel_->raised() || left <= kCancelStepMs) return;
    }
  }

 private:
  const CancelSignal* cancel_ = nullptr;
};

// ---- libusb ----------------------------------------------------------------------------

struct LibusbContext {
  libusb_context* ctx = nullptr;
  LibusbContext() {
    const int r = libusb_init(&ctx);
    if (r != 0) throw DeviceError(std::string("USB: cannot start libusb: ") + libusb_strerror(r));
  }
  ~LibusbContext() { libusb_exit(ctx); }
  LibusbContext(const LibusbContext&) = delete;
  LibusbContext& operator=(const LibusbContext&) = delete;
};

AccessProblem ProblemOf(int libusb_error) {
  switch (libusb_error) {
    case LIBUSB_ERROR_ACCESS:
      return AccessProblem::kPermission;
    case LIBUSB_ERROR_BUSY:
      return AccessProblem::kBusy;
    default:
      return AccessProblem::kOther;
  }
}

// "/dev/bus/usb/001/002": the node libusb opens for a device (Linux usbfs).
std::string UsbNode(libusb_device* dev) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "/dev/bus/usb/%03d/%03d", libusb_get_bus_number(dev),
                libusb_get_device_address(dev));
  return buf;
}

// One clause for the log line and the error message: the cause, the node, what to do.
std::string AccessText(AccessProblem p, const std::string& node, const std::string& detail) {
  switch (p) {
    case AccessProblem::kNone:
      return detail;
    case AccessProblem::kPermission:
      return "permission denied: this user may not open " +
             (node.empty() ? "its device node" : node) + "; " + UdevRemedy();
    case AccessProblem::kBusy:
      return "in use by another program (" + detail + ")";
    case AccessProblem::kOther:
      return detail;
  }
  return detail;
}

std::string SerialOf(libusb_device_handle* h, const libusb_device_descriptor& d) {
  if (d.iSerialNumber == 0) return {};
  unsigned char buf[128] = {};
  const int n = libusb_get_string_descriptor_ascii(h, d.iSerialNumber, buf, sizeof buf - 1);
  return n > 0 ? std::string(reinterpret_cast<char*>(buf), static_cast<std::size_t>(n))
               : std::string();
}

// Bytes one transfer delivered, handed out to Read calls until used up: both transports receive
// in units (bulk transfers, HID reports) larger than what the codec asks for at a time.
class Inbox {
 public:
  bool Empty() const { return start_ == bytes_.size(); }
  // Empties the inbox and returns its storage, to be filled by the next transfer.
  std::vector<std::uint8_t>& Refill() {
    bytes_.clear();
    start_ = 0;
    return bytes_;
  }
  // Copies as many waiting bytes as fit into `buffer`; returns how many.
  std::size_t Drain(std::span<std::uint8_t> buffer) {
    const std::size_t n = std::min(buffer.size(), bytes_.size() - start_);
    std::memcpy(buffer.data(), bytes_.data() + start_, n);
    start_ += n;
    return n;
  }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t start_ = 0;
};

class LibusbTransport final : public CountingTransport {
 public:
  LibusbTransport(std::unique_ptr<LibusbContext> ctx, libusb_device_handle* handle, UsbModel model,
                  std::string description)
      : ctx_(std::move(ctx)), handle_(handle), model_(model), description_(std::move(description)) {
    inbox_.Refill().reserve(model_.bulk_read_bytes);
  }
  ~LibusbTransport() override {
    libusb_release_interface(handle_, model_.interface_number);
    libusb_close(handle_);
  }

  void Write(std::span<const std::uint8_t> bytes) override {
    std::size_t done = 0;
    int halts = 0;
    while (done < bytes.size()) {
      int sent = 0;
      const int len = static_cast<int>(std::min<std::size_t>(bytes.size() - done, 1 << 16));
      const int r = libusb_bulk_transfer(handle_, model_.bulk_out_endpoint,
                                         const_cast<unsigned char*>(bytes.data() + done), len,
                                         &sent, model_.reply_timeout_ms);
      ++stats.transfers_out;
      done += static_cast<std::size_t>(std::max(sent, 0));
      if (r == 0 || (r == LIBUSB_ERROR_TIMEOUT && sent > 0)) continue;
      if (r == LIBUSB_ERROR_PIPE && halts++ < kMaxHaltRetries) {
        ClearHalt(model_.bulk_out_endpoint);
        continue;
      }
      Throw(r, "write");
    }
  }

  std::size_t Read(std::span<std::uint8_t> buffer, int timeout_ms) override {
    if (inbox_.Empty()) {
      std::vector<std::uint8_t>& bytes = inbox_.Refill();
      bytes.resize(model_.bulk_read_bytes);
      int got = 0, halts = 0;
      WaitInSteps(timeout_ms, [&](int wait_ms) {
        for (;;) {
          const int r = libusb_bulk_transfer(handle_, model_.bulk_in_endpoint, bytes.data(),
                                             static_cast<int>(bytes.size()), &got, wait_ms);
          ++stats.transfers_in;
          if (r == 0) return true;
          if (r == LIBUSB_ERROR_TIMEOUT) return got > 0;
          if (r == LIBUSB_ERROR_PIPE && halts++ < kMaxHaltRetries) {
            ClearHalt(model_.bulk_in_endpoint);
            continue;
          }
          bytes.clear();
          Throw(r, "read");
        }
      });
      bytes.resize(static_cast<std::size_t>(std::max(got, 0)));
      if (bytes.empty()) return 0;
    }
    return inbox_.Drain(buffer);
  }

  std::string Description() const override { return description_; }

 private:
  void ClearHalt(unsigned char endpoint) {
    const int r = libusb_clear_halt(handle_, endpoint);
    if (r != 0) Throw(r, "clear the halt of");
    ++stats.halts_cleared;
  }
  [[noreturn]] void Throw(int r, const char* what) const {
    if (r == LIBUSB_ERROR_NO_DEVICE)
      throw DeviceError(description_ + ": the instrument disconnected (" + what + " failed)");
    if (r == LIBUSB_ERROR_PIPE)
      throw DeviceError(description_ + ": the endpoint stays stalled after " +
                        std::to_string(kMaxHaltRetries) + " clear-halt attempts (" + what + ")");
    throw DeviceError(description_ + ": USB " + what + " failed: " + libusb_strerror(r));
  }

  std::unique_ptr<LibusbContext> ctx_;
  libusb_device_handle* handle_;
  UsbModel model_;
  std::string description_;
  Inbox inbox_;
};

// ---- hidapi ----------------------------------------------------------------------------

// hid_init/hid_exit are process wide; reference-count them.
std::mutex g_hid_mutex;
int g_hid_users = 0;

struct HidLibrary {
  HidLibrary() {
    std::lock_guard lock(g_hid_mutex);
    if (g_hid_users++ == 0 && hid_init() != 0) {
      --g_hid_users;
      throw DeviceError("HID: cannot start hidapi");
    }
  }
  ~HidLibrary() {
    std::lock_guard lock(g_hid_mutex);
    if (--g_hid_users == 0) hid_exit();
  }
  HidLibrary(const HidLibrary&) = delete;
  HidLibrary& operator=(const HidLibrary&) = delete;
};

class HidTransport final : public CountingTransport {
 public:
  HidTransport(std::unique_ptr<HidLibrary> lib, hid_device* dev, UsbModel model,
               std::string description)
      : lib_(std::move(lib)), dev_(dev), model_(model), description_(std::move(description)) {}
  ~HidTransport() override { hid_close(dev_); }

  // Each output report: a count byte, then up to report_bytes − 1 stream bytes (PROTOCOL.md).
  void Write(std::span<const std::uint8_t> bytes) override {
    const std::size_t per_report = model_.hid_report_bytes - 1;
    std::vector<unsigned char> report(model_.hid_report_bytes + 1);
    for (std::size_t done = 0; done < bytes.size();) {
      const std::size_t n = std::min(per_report, bytes.size() - done);
      std::fill(report.begin(), report.end(), 0);
      report[0] = 0;  // no report IDs
      report[1] = static_cast<unsigned char>(n);
      std::memcpy(report.data() + 2, bytes.data() + done, n);
      const int r = hid_write(dev_, report.data(), report.size());
      ++stats.transfers_out;
      if (r < 0)
        throw DeviceError(description_ + ": the instrument disconnected (write failed: " +
                          Narrow(hid_error(dev_)) + ")");
      done += n;
    }
  }

  std::size_t Read(std::span<std::uint8_t> buffer, int timeout_ms) override {
    if (inbox_.Empty()) {
      std::vector<std::uint8_t>& bytes = inbox_.Refill();
      report_.resize(model_.hid_report_bytes);
      int r = 0;
      WaitInSteps(timeout_ms, [&](int wait_ms) {
        r = hid_read_timeout(dev_, report_.data(), report_.size(), wait_ms);
        ++stats.transfers_in;
        return r != 0;
      });
      if (r < 0)
        throw DeviceError(description_ + ": the instrument disconnected (read failed: " +
                          Narrow(hid_error(dev_)) + ")");
      if (r == 0) return 0;
      const std::size_t count = report_[0];
      if (count > static_cast<std::size_t>(r) - 1)
        throw DeviceError(description_ + ": HID report says " + std::to_string(count) +
                          " stream bytes, the report holds " + std::to_string(r - 1));
      bytes.assign(report_.begin() + 1, report_.begin() + 1 + static_cast<std::ptrdiff_t>(count));
      if (bytes.empty()) return 0;
    }
    return inbox_.Drain(buffer);
  }

  std::string Description() const override { return description_; }

 private:
  std::unique_ptr<HidLibrary> lib_;
  hid_device* dev_;
  UsbModel model_;
  std::string description_;
  std::vector<unsigned char> report_;  // one HID report, reused by every Read
  Inbox inbox_;
};

struct HidCandidate {
  std::string path, serial;
  std::uint16_t vid = 0, pid = 0;
};

std::vector<HidCandidate> EnumerateHid(const DeviceSpec* spec) {
  std::vector<HidCandidate> out;
  hid_device_info* list = hid_enumerate(0, 0);
  for (hid_device_info* d = list; d != nullptr; d = d->next) {
    const bool match =
        spec ? Matches(*spec, d->vendor_id, d->product_id, true)
             : (FindUsbModel(d->vendor_id, d->product_id) &&
                FindUsbModel(d->vendor_id, d->product_id)->hid_product_id == d->product_id);
    if (!match) continue;
    HidCandidate c{d->path ? d->path : "", Narrow(d->serial_number), d->vendor_id, d->product_id};
    if (spec && !spec->serial.empty() && c.serial != spec->serial) continue;
    out.push_back(std::move(c));
  }
  hid_free_enumeration(list);
  return out;
}

struct HidOpenFailure {
  AccessProblem problem = AccessProblem::kOther;
  std::string node, detail;
};

// hidapi says only that hid_open_path failed. Its hidraw backend (the field) opens the path
// itself, so access(2) tells why; its libusb backend (the tests) names the device by bus and
// port chain ("1-1:1.0"), whose usbfs node libusb_open tries.
HidOpenFailure WhyHidOpenFailed(const HidCandidate& c) {
  HidOpenFailure f;
  f.detail = "hidapi cannot open " + c.path;
  if (c.path.rfind("/dev/", 0) == 0) {
    f.node = c.path;
    if (::access(c.path.c_str(), R_OK | W_OK) != 0) {
      f.problem = errno == EACCES ? AccessProblem::kPermission : AccessProblem::kOther;
      f.detail += std::string(": ") + std::strerror(errno);
    } else {
      f.problem = AccessProblem::kBusy;
    }
    return f;
  }
  const std::string ports = c.path.substr(0, c.path.find(':'));
  LibusbContext ctx;
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx.ctx, &list);
  for (ssize_t i = 0; i < n; ++i) {
    std::uint8_t chain[8];
    const int depth = libusb_get_port_numbers(list[i], chain, sizeof chain);
    std::string name = std::to_string(libusb_get_bus_number(list[i]));
    for (int k = 0; k < depth; ++k) name += (k == 0 ? "-" : ".") + std::to_string(chain[k]);
    if (depth <= 0 || name != ports) continue;
    f.node = UsbNode(list[i]);
    libusb_device_handle* h = nullptr;
    const int r = libusb_open(list[i], &h);
    if (r == 0) {
      libusb_close(h);
      f.problem = AccessProblem::kBusy;
    } else {
      f.problem = ProblemOf(r);
      f.detail += std::string(": ") + libusb_strerror(r);
    }
    break;
  }
  libusb_free_device_list(list, 1);
  return f;
}

UsbModel ModelFor(std::uint16_t vid, std::uint16_t pid) {
  const std::optional<UsbModel> m = FindUsbModel(vid, pid);
  if (m) return *m;
  UsbModel generic = UsbModels().front();  // an explicit VID:PID of an unlisted model
  generic.vendor_id = vid;
  generic.bulk_product_id = generic.hid_product_id = pid;
  return generic;
}

}  // namespace

std::string UdevRemedy() {
  // The rule of this executable's installed tree (a package under /usr, a moved prefix), else
  // where `cmake --install` puts it for the configured prefix.
  std::string installed = BRDF_UDEV_RULES_DIR;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path dir =
        (exe.parent_path() / BRDF_UDEV_RULES_DIR_FROM_EXE).lexically_normal();
    if (std::filesystem::is_regular_file(dir / "70-brdf-scatterometer.rules", ec))
      installed = dir.string();
  }
  return "copy the udev rule 70-brdf-scatterometer.rules (installed in " + installed +
         ", in the sources device/udev/) to /etc/udev/rules.d/, run 'sudo udevadm control "
         "--reload && sudo udevadm trigger' and plug the instrument in again";
}

std::unique_ptr<Transport> OpenUsbTransport(const DeviceSpec& spec) {
  if (spec.kind != DeviceSpec::Kind::kUsb)
    throw InvalidArgument("OpenUsbTransport: the device is not a USB instrument");
  auto ctx = std::make_unique<LibusbContext>();
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx->ctx, &list);
  std::string problems;
  std::unique_ptr<Transport> result;
  for (ssize_t i = 0; i < n && !result; ++i) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
    if (!Matches(spec, d.idVendor, d.idProduct, false)) continue;
    const std::string where = "USB bus " + std::to_string(libusb_get_bus_number(list[i])) +
                              " device " + std::to_string(libusb_get_device_address(list[i]));
    libusb_device_handle* h = nullptr;
    int r = libusb_open(list[i], &h);
    if (r != 0) {
      problems +=
          "; " + where + ": " + AccessText(ProblemOf(r), UsbNode(list[i]), libusb_strerror(r));
      continue;
    }
    const std::string serial = SerialOf(h, d);
    if (!spec.serial.empty() && serial != spec.serial) {
      libusb_close(h);
      continue;
    }
    const UsbModel model = ModelFor(d.idVendor, d.idProduct);
    libusb_set_auto_detach_kernel_driver(h, 1);
    r = libusb_claim_interface(h, model.interface_number);
    if (r != 0) {
      problems +=
          "; " + where + ": " + AccessText(ProblemOf(r), UsbNode(list[i]), libusb_strerror(r));
      libusb_close(h);
      continue;
    }
    result = std::make_unique<LibusbTransport>(std::move(ctx), h, model,
                                               "USB " + std::string(model.model) + " " +
                                                   (serial.empty() ? "(no serial)" : serial) +
                                                   " (" + where + ")");
  }
  libusb_free_device_list(list, 1);
  if (!result) {
    // A device that matched but could not be opened is the answer, not "not found".
    if (!problems.empty()) throw DeviceError(LookedFor(spec, "USB") + " on " + problems.substr(2));
    throw DeviceError("no " + LookedFor(spec, "USB") + " found");
  }
  return result;
}

std::unique_ptr<Transport> OpenHidTransport(const DeviceSpec& spec) {
  if (spec.kind != DeviceSpec::Kind::kHid)
    throw InvalidArgument("OpenHidTransport: the device is not a HID instrument");
  auto lib = std::make_unique<HidLibrary>();
  const std::vector<HidCandidate> found = EnumerateHid(&spec);
  std::string problems;
  for (const HidCandidate& c : found) {
    hid_device* dev = hid_open_path(c.path.c_str());
    if (dev == nullptr) {
      const HidOpenFailure why = WhyHidOpenFailed(c);
      problems += "; " + c.path + ": " + AccessText(why.problem, why.node, why.detail);
      continue;
    }
    const UsbModel model = ModelFor(c.vid, c.pid);
    return std::make_unique<HidTransport>(std::move(lib), dev, model,
                                          "HID " + std::string(model.model) + " " +
                                              (c.serial.empty() ? "(no serial)" : c.serial) + " (" +
                                              c.path + ")");
  }
  if (!problems.empty()) throw DeviceError(LookedFor(spec, "HID") + " on " + problems.substr(2));
  throw DeviceError("no " + LookedFor(spec, "HID") + " found");
}

TransportStats StatsOf(const Transport& transport) {
  const auto* counting = dynamic_cast<const CountingTransport*>(&transport);
  return counting ? counting->stats : TransportStats{};
}

std::vector<FoundInstrument> ListInstruments(bool identify) {
  std::vector<FoundInstrument> out;
  auto ask_identity = [&](FoundInstrument& f, Transport& t) {
    if (!identify) return;
    try {
      DriverOptions o;
      o.timeout_ms = 1000;
      Driver driver(t, o);
      const InstrumentInfo& info = driver.Connect();
      f.firmware_version = info.identity.firmware_version;
      if (f.serial.empty()) f.serial = info.identity.serial;
      f.model = info.identity.model;
    } catch (const Error& e) {
      f.problem = AccessProblem::kOther;
      f.problem_detail = std::string("does not answer IDENTIFY: ") + e.what();
    }
  };
  {
    LibusbContext ctx;
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(ctx.ctx, &list);
    for (ssize_t i = 0; i < n; ++i) {
      libusb_device_descriptor d{};
      if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
      const std::optional<UsbModel> m = FindUsbModel(d.idVendor, d.idProduct);
      if (!m || m->bulk_product_id != d.idProduct) continue;
      FoundInstrument f;
      f.kind = DeviceSpec::Kind::kUsb;
      f.vendor_id = d.idVendor;
      f.product_id = d.idProduct;
      f.model = std::string(m->model);
      char where[64];
      std::snprintf(where, sizeof where, "bus %03d device %03d", libusb_get_bus_number(list[i]),
                    libusb_get_device_address(list[i]));
      f.bus_path = where;
      f.device_node = UsbNode(list[i]);
      libusb_device_handle* h = nullptr;
      const int r = libusb_open(list[i], &h);
      if (r != 0) {
        f.problem = ProblemOf(r);
        f.problem_detail = f.problem == AccessProblem::kPermission
                               ? AccessText(f.problem, f.device_node, libusb_strerror(r))
                               : libusb_strerror(r);
      } else {
        f.serial = SerialOf(h, d);
        libusb_close(h);
      }
      out.push_back(f);
    }
    libusb_free_device_list(list, 1);
  }
  for (FoundInstrument& f : out) {
    if (f.problem != AccessProblem::kNone || !identify) continue;
    DeviceSpec spec;
    spec.kind = DeviceSpec::Kind::kUsb;
    spec.vendor_id = f.vendor_id;
    spec.product_id = f.product_id;
    spec.serial = f.serial;
    try {
      std::unique_ptr<Transport> t = OpenUsbTransport(spec);
      ask_identity(f, *t);
    } catch (const DeviceError& e) {
      f.problem = AccessProblem::kBusy;
      f.problem_detail = e.what();
    }
  }
  HidLibrary lib;
  for (const HidCandidate& c : EnumerateHid(nullptr)) {
    FoundInstrument f;
    f.kind = DeviceSpec::Kind::kHid;
    f.vendor_id = c.vid;
    f.product_id = c.pid;
    f.model = std::string(ModelFor(c.vid, c.pid).model);
    f.serial = c.serial;
    f.bus_path = c.path;
    hid_device* dev = hid_open_path(c.path.c_str());
    if (dev == nullptr) {
      const HidOpenFailure why = WhyHidOpenFailed(c);
      f.problem = why.problem;
      f.device_node = why.node;
      f.problem_detail = why.problem == AccessProblem::kPermission
                             ? AccessText(why.problem, why.node, why.detail)
                             : why.detail;
    } else if (identify) {
      HidTransport t(std::make_unique<HidLibrary>(), dev, ModelFor(c.vid, c.pid), "HID " + c.path);
      ask_identity(f, t);
    } else {
      hid_close(dev);
    }
    out.push_back(f);
  }
  return out;
}

}  // namespace brdf::device
