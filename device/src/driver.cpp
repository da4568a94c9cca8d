#include "brdf/device/driver.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>

#if defined(__x86_64__) || defined(__SSE2__)
#include <immintrin.h>
#endif

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/text_format.h"
#include "brdf/device/cancel.h"

namespace brdf::device {
namespace {

constexpr double kThetaMatchDeg = 1e-4;

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string Triple(const std::array<double, 3>& v, const char* format = "%.9g") {
  return Fmt(format, v[0]) + " " + Fmt(format, v[1]) + " " + Fmt(format, v[2]);
}

// One row segment calibrated channel by channel (the formula in MeasureSlice) over arrays of
// the longest segment, so that each loop has a fixed length the compiler turns into vector
// code: a shorter segment's tail is computed from finite leftovers and never read.
struct RowBuffers {
  static constexpr std::size_t kN = kMaxSamplesPerRowFrame;
  std::array<std::array<float, kN>, 3> counts{};  // the instrument's readings, C_s
  std::array<std::array<double, kN>, 3> signal{}, f{};
  std::array<std::array<double, kN>, 3> sigma_f{};  // σf², then σf

  void Calibrate(int c, double dark, double gain, double gain2, double c0, double c1, double c2,
                 double c3) {
    const std::array<float, kN>& in = counts[c];
    std::array<double, kN>& s = signal[c];
    std::array<double, kN>& out = f[c];
    std::array<double, kN>& var = sigma_f[c];
    for (std::size_t i = 0; i < kN; ++i) s[i] = static_cast<double>(in[i]) - dark;
    for (std::size_t i = 0; i < kN; ++i) out[i] = gain * s[i];
    for (std::size_t i = 0; i < kN; ++i) {
      const double positive = s[i] > 0 ? s[i] : 0.0;
      var[i] = gain2 * (c0 + c1 * positive + s[i] * (c2 + c3 * s[i]));
    }
  }
};

// v[i] = √v[i] for non-negative v: four at a time with AVX where the processor has it, two
// with SSE2 otherwise. Every path rounds correctly (IEEE 754 square root), so all give the same
// bits as std::sqrt.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("avx"))) std::size_t SqrtAvx(std::span<double> v) {
  std::size_t i = 0;
  for (; i + 4 <= v.size(); i += 4) _mm256_storeu_pd(&v[i], _mm256_sqrt_pd(_mm256_loadu_pd(&v[i])));
  return i;
}

bool HaveAvx() {
  static const bool have = __builtin_cpu_supports("avx");
  return have;
}
#endif

void SqrtInPlace(std::span<double> v) {
  std::size_t i = 0;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (HaveAvx()) i = SqrtAvx(v);
#endif
#if defined(__SSE2__)
  for (; i + 2 <= v.size(); i += 2) _mm_storeu_pd(&v[i], _mm_sqrt_pd(_mm_loadu_pd(&v[i])));
#endif
  for (; i < v.size(); ++i) v[i] = std::sqrt(v[i]);
}

}  // namespace

Driver::Driver(Transport& transport, DriverOptions options)
    : transport_(transport), options_(std::move(options)) {}

void Driver::SetCancelFlag(const CancelSignal* cancel) {
  cancel_ = cancel;
  transport_.SetCancel(cancel);
}

bool Driver::cancelled() const { return cancel_ != nullptr && cancel_->raised(); }

Driver::~Driver() {
  if (cancel_ != nullptr) transport_.SetCancel(nullptr);
}

// While ABORT's acknowledgement is awaited (Abort, Recover) a raised cancel is not acted on
// again, and the transport's reads wait their whole timeout: the acknowledgement is what a
// cancel waits for.
class Driver::AbortScope {
 public:
  explicit AbortScope(Driver& d) : d_(d), old_(d.aborting_) {
    d_.aborting_ = true;
    if (d_.cancel_ != nullptr) d_.transport_.SetCancel(nullptr);
  }
  ~AbortScope() {
    d_.aborting_ = old_;
    if (!old_ && d_.cancel_ != nullptr) d_.transport_.SetCancel(d_.cancel_);
  }
  AbortScope(const AbortScope&) = delete;
  AbortScope& operator=(const AbortScope&) = delete;

 private:
  Driver& d_;
  bool old_;
};

void Driver::Fail(FaultKind kind, const std::string& what) const {
  throw DriverFault(kind, transport_.Description() + ": " + what);
}

void Driver::Send(MessageType type, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> bytes;
  AppendFrame(bytes, static_cast<std::uint8_t>(type), host_sequence_++, payload);
  try {
    transport_.Write(bytes);
  } catch (const DriverFault&) {
    throw;
  } catch (const DeviceError& e) {
    throw DriverFault(FaultKind::kDisconnected, e.what());
  }
}

Frame Driver::NextFrame(std::string_view waiting_for, bool check_sequence) {
  std::array<std::uint8_t, 4096> buffer{};
  for (;;) {
    DecodeResult r = reader_.Next();
    if (r.status == DecodeStatus::kComplete) {
      // A duplicated transfer repeats a frame bit for bit, sequence number included: drop it.
      // Same type, sequence, length and CRC-32 identify the repeat (a different frame with all
      // four equal has a chance of 2^-32, and would be a lost frame the next sequence shows).
      if (have_device_sequence_ && r.frame.sequence == device_sequence_ &&
          r.frame.type == last_frame_type_ && r.crc == last_frame_crc_ &&
          r.frame.payload.size() == last_frame_size_) {
        ++duplicates_dropped_;
        continue;
      }
      const std::uint8_t expected = static_cast<std::uint8_t>(device_sequence_ + 1);
      if (check_sequence && have_device_sequence_ && r.frame.sequence != expected)
        Fail(FaultKind::kOutOfSequence,
             "frame lost or out of order while waiting for " + std::string(waiting_for) +
                 ": expected sequence " + std::to_string(expected) + ", got " +
                 std::to_string(r.frame.sequence) +
                 (last_damage_.empty() ? "" : " (damaged frame: " + last_damage_ + ")"));
      have_device_sequence_ = true;
      device_sequence_ = r.frame.sequence;
      last_frame_type_ = r.frame.type;
      last_frame_crc_ = r.crc;
      last_frame_size_ = r.frame.payload.size();
      last_damage_.clear();
      return std::move(r.frame);
    }
    if (r.status == DecodeStatus::kInvalid) {
      // Noise between frames is skipped; a damaged frame is remembered: if it was a real frame
      // the next sequence number jumps and the loss is reported with this reason. The first
      // damage after the last good frame is kept: what follows it is usually the damaged
      // frame's own payload being searched for a frame start.
      if (r.corrupt && last_damage_.empty()) last_damage_ = r.reason;
      continue;
    }
    std::size_t n = 0;
    try {
      n = transport_.Read(buffer, options_.timeout_ms);
    } catch (const DriverFault&) {
      throw;
    } catch (const DeviceError& e) {
      throw DriverFault(FaultKind::kDisconnected, e.what());
    }
    if (n == 0) {
      // A read that ended early for the cancel (or timed out after it): stop the scan.
      if (cancelled() && !aborting_) {
        Abort();
        Fail(FaultKind::kCancelled, "capture cancelled while waiting for " +
                                        std::string(waiting_for) + "; the scan was stopped");
      }
      if (!last_damage_.empty())
        Fail(FaultKind::kDamagedFrame,
             "damaged frame while waiting for " + std::string(waiting_for) + ": " + last_damage_);
      Fail(FaultKind::kTimeout, "timeout: no answer within " + std::to_string(options_.timeout_ms) +
                                    " ms while waiting for " + std::string(waiting_for));
    }
    reader_.Append(std::span<const std::uint8_t>(buffer.data(), n));
  }
}

void Driver::ThrowInstrumentError(const Frame& frame, MessageType request) const {
  const std::string request_name = MessageTypeName(static_cast<std::uint8_t>(request));
  if (frame.type == static_cast<std::uint8_t>(MessageType::kError)) {
    const ErrorReply e = DecodeError(frame.payload);
    throw DriverFault(FaultKind::kInstrumentError,
                      transport_.Description() + ": the instrument refused " + request_name + ": " +
                          e.message + " (error code " + std::to_string(static_cast<int>(e.code)) +
                          ")",
                      e.code);
  }
  Fail(FaultKind::kProtocol,
       "unexpected " + MessageTypeName(frame.type) + " in answer to " + request_name);
}

Frame Driver::Expect(MessageType request, MessageType reply) {
  Frame f = NextFrame(MessageTypeName(static_cast<std::uint8_t>(reply)));
  if (f.type != static_cast<std::uint8_t>(reply)) ThrowInstrumentError(f, request);
  return f;
}

const InstrumentInfo& Driver::Connect() {
  Send(MessageType::kIdentify, {});
  info_.identity = DecodeIdentity(Expect(MessageType::kIdentify, MessageType::kIdentity).payload);
  if (info_.identity.protocol_major != kProtocolMajor)
    Fail(FaultKind::kProtocol,
         "instrument speaks protocol " + std::to_string(info_.identity.protocol_major) + "." +
             std::to_string(info_.identity.protocol_minor) + ", this driver " +
             std::to_string(kProtocolMajor) + ".x (update the toolchain or firmware)");
  Send(MessageType::kGetGeometry, {});
  info_.geometry =
      DecodeGeometry(Expect(MessageType::kGetGeometry, MessageType::kGeometry).payload);
  const std::size_t per_slice = std::size_t{info_.geometry.rows} * info_.geometry.columns;
  if (per_slice == 0 || per_slice > kMaxSamplesPerSlice)
    Fail(FaultKind::kProtocol, "geometry of " + std::to_string(info_.geometry.rows) + " × " +
                                   std::to_string(info_.geometry.columns) +
                                   " samples per slice is outside 1 … " +
                                   std::to_string(kMaxSamplesPerSlice));
  connected_ = true;
  have_dark_ = false;
  whites_.clear();
  return info_;
}

void Driver::SetExposure(const ExposureSetting& setting) {
  Send(MessageType::kSetExposure, EncodeExposure(setting));
  const std::uint8_t acked =
      DecodeAck(Expect(MessageType::kSetExposure, MessageType::kAck).payload);
  if (acked != static_cast<std::uint8_t>(MessageType::kSetExposure))
    Fail(FaultKind::kProtocol, "SET_EXPOSURE acknowledged as " + MessageTypeName(acked));
  exposure_ = setting;
}

const DarkCalibration& Driver::MeasureDark() {
  Send(MessageType::kMeasureDark, {});
  const DarkReading d = DecodeDark(Expect(MessageType::kMeasureDark, MessageType::kDark).payload);
  for (int c = 0; c < 3; ++c) {
    dark_.mean_counts[c] = d.mean_counts[c];
    dark_.read_noise_counts[c] = d.read_noise_counts[c];
  }
  dark_.frames = d.frames;
  dark_.time = UtcNowIso8601();
  have_dark_ = true;
  return dark_;
}

const WhiteCalibration* Driver::FindWhite(double theta_in_deg) const {
  for (const WhiteCalibration& w : whites_)
    if (std::fabs(w.theta_in_deg - theta_in_deg) <= kThetaMatchDeg) return &w;
  return nullptr;
}

const WhiteCalibration& Driver::MeasureWhite(double theta_in_deg) {
  if (!have_dark_) throw InvalidArgument("MeasureWhite: measure the dark signal first");
  Send(MessageType::kMeasureWhite, EncodeThetaIn(static_cast<float>(theta_in_deg)));
  const WhiteReading r =
      DecodeWhite(Expect(MessageType::kMeasureWhite, MessageType::kWhite).payload);
  if (r.clipped_channels != 0)
    Fail(FaultKind::kInstrumentError,
         "white reference at θin " + ShortNumberText(theta_in_deg) + "° saturated (clip bits " +
             std::to_string(r.clipped_channels) + "); cannot calibrate");
  WhiteCalibration w;
  w.theta_in_deg = r.theta_in_deg;
  w.exposure_ms = r.exposure_ms;
  if (r.nd_index >= info_.geometry.nd_transmittance.size())
    Fail(FaultKind::kProtocol, "WHITE names ND filter " + std::to_string(r.nd_index) +
                                   ", the instrument has " +
                                   std::to_string(info_.geometry.nd_transmittance.size()));
  w.nd_transmittance = info_.geometry.nd_transmittance[r.nd_index];
  for (int c = 0; c < 3; ++c) {
    w.counts[c] = r.counts[c];
    if (!(w.counts[c] - dark_.mean_counts[c] > 0))
      Fail(FaultKind::kInstrumentError,
           "white reference at θin " + ShortNumberText(theta_in_deg) +
               "° gives no signal above dark in channel " + std::to_string(c) + " (" +
               ShortNumberText(w.counts[c]) + " counts, dark " +
               ShortNumberText(dark_.mean_counts[c]) + "); is the panel in place?");
  }
  w.frames = r.frames;
  w.time = UtcNowIso8601();
  std::erase_if(whites_, [&](const WhiteCalibration& old) {
    return std::fabs(old.theta_in_deg - w.theta_in_deg) <= kThetaMatchDeg;
  });
  whites_.push_back(std::move(w));
  return *FindWhite(r.theta_in_deg);
}

Slice Driver::MeasureSlice(double theta_in_deg, SliceReport* report) {
  const auto start = std::chrono::steady_clock::now();
  if (!connected_) throw InvalidArgument("MeasureSlice: connect to the instrument first");
  if (!have_dark_) throw InvalidArgument("MeasureSlice: measure the dark signal first");
  const WhiteCalibration* white = FindWhite(theta_in_deg);
  if (white == nullptr)
    throw InvalidArgument("MeasureSlice: measure the white reference at θin " +
                          ShortNumberText(theta_in_deg) + "° first");
  const GeometryInfo& g = info_.geometry;

  Send(MessageType::kMeasureSlice, EncodeThetaIn(static_cast<float>(theta_in_deg)));
  const SliceBegin begin =
      DecodeSliceBegin(Expect(MessageType::kMeasureSlice, MessageType::kSliceBegin).payload);
  if (begin.rows != g.rows || begin.columns != g.columns)
    Fail(FaultKind::kProtocol, "slice of " + std::to_string(begin.rows) + " × " +
                                   std::to_string(begin.columns) +
                                   " samples announced, geometry says " + std::to_string(g.rows) +
                                   " × " + std::to_string(g.columns));

  // Per-channel constants of the calibration (the header's formula), fixed for the slice.
  // With s = C_s − D the sample's signal above dark, W = C_w − D the panel's, r = s/W and
  // g = ρ_w/π · t_w T_w / (W · t_s T_s) the gain of a row (t_s T_s may change from row to row):
  //   f   = g·s
  //   σf² = g² · [(σr² + k·max(0, s))/N + r²·σW² + (r − 1)²·σD²]
  //       = g² · [c0 + c1·max(0, s) + s·(c2 + c3·s)]
  // with c0 = σr²/N + σD², c1 = k/N, c2 = −2σD²/W, c3 = (σW² + σD²)/W². The expanded form
  // needs no division per sample (before, three per sample and channel and a square root were
  // most of the host's time in a capture) and runs as vector code (RowBuffers). Expanding
  // (r − 1)² costs at most a few double ulps of σr²/N + r²σW² + (1 + |r|)²σD², a small multiple
  // of σf²/g² itself, far below float resolution: driver_test recomputes f and σf in long
  // double from the raw readings and finds the driver's floats to be the exact values rounded.
  const double frames = info_.identity.frames_per_reading;
  const double shot = info_.identity.shot_variance_per_count;
  std::array<double, 3> dark{}, c0{}, c1{}, c2{}, c3{}, floor{}, scale{};
  for (int c = 0; c < 3; ++c) {
    const double sr = dark_.read_noise_counts[c];
    const double read_var = sr * sr;
    const double w_signal = white->counts[c] - dark_.mean_counts[c];
    const double var_w = (read_var + shot * w_signal) / white->frames;
    const double var_dark = read_var / dark_.frames;
    dark[c] = dark_.mean_counts[c];
    c0[c] = read_var / frames + var_dark;
    c1[c] = shot / frames;
    c2[c] = -2 * var_dark / w_signal;
    c3[c] = (var_w + var_dark) / (w_signal * w_signal);
    floor[c] = options_.noise_floor_sigmas * sr / std::sqrt(frames);
    scale[c] =
        options_.white.rho[c] * kInvPi * white->exposure_ms * white->nd_transmittance / w_signal;
  }
  const std::size_t total = static_cast<std::size_t>(g.rows) * g.columns;
  std::vector<float> phi_out_deg(g.columns);
  for (std::size_t column = 0; column < g.columns; ++column)
    phi_out_deg[column] = g.PhiOutDeg(column);

  Slice slice;
  slice.theta_in_deg = begin.theta_in_deg;
  slice.phi_in_deg = 0;
  slice.has_sigma = true;
  slice.complete = true;
  // Rows arrive in order (checked below), so samples are appended, never written twice.
  slice.samples.reserve(total);
  SliceReport rep;
  rep.theta_in_deg = slice.theta_in_deg;
  const auto buffers_storage = std::make_unique<RowBuffers>();  // 11 KB, off the stack
  RowBuffers& buffers = *buffers_storage;

  std::size_t next_row = 0, next_column = 0, received = 0;
  for (;;) {
    if (cancelled()) {
      Abort();
      Fail(FaultKind::kCancelled, "capture cancelled during the slice at θin " +
                                      ShortNumberText(theta_in_deg) + "°; the scan was stopped");
    }
    const Frame f = NextFrame("ROW_DATA");
    if (f.type == static_cast<std::uint8_t>(MessageType::kSliceEnd)) {
      const SliceEnd end = DecodeSliceEnd(f.payload);
      if (received != total || end.samples != total)
        Fail(FaultKind::kOutOfSequence, "slice θin " + ShortNumberText(theta_in_deg) +
                                            "° ended after " + std::to_string(received) + " of " +
                                            std::to_string(total) + " samples");
      break;
    }
    if (f.type != static_cast<std::uint8_t>(MessageType::kRowData))
      ThrowInstrumentError(f, MessageType::kMeasureSlice);
    const RowDataView row = DecodeRowDataView(f.payload);
    if (row.row != next_row || row.first_column != next_column ||
        next_column + row.size() > g.columns || row.size() == 0)
      Fail(FaultKind::kOutOfSequence,
           "ROW_DATA out of order: expected row " + std::to_string(next_row) + " column " +
               std::to_string(next_column) + ", got row " + std::to_string(row.row) + " columns " +
               std::to_string(row.first_column) + "+" + std::to_string(row.size()));
    if (!(row.exposure_ms > 0))
      Fail(FaultKind::kProtocol,
           "ROW_DATA with exposure " + ShortNumberText(row.exposure_ms) + " ms");
    const float theta_out = g.ThetaOutDeg(row.row);
    if (row.nd_index >= g.nd_transmittance.size())
      Fail(FaultKind::kProtocol, "ROW_DATA names ND filter " + std::to_string(row.nd_index) +
                                     ", the instrument has " +
                                     std::to_string(g.nd_transmittance.size()));
    // The light integrated: exposure × filter transmittance (both float32 from the wire).
    const double t_s = static_cast<double>(row.exposure_ms) *
                       static_cast<double>(g.nd_transmittance[row.nd_index]);
    std::array<double, 3> gain{}, gain2{};
    for (int c = 0; c < 3; ++c) {
      gain[c] = scale[c] / t_s;
      gain2[c] = gain[c] * gain[c];
    }
    const std::size_t n = row.size();
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) buffers.counts[c][i] = row.Counts(i, c);
    for (int c = 0; c < 3; ++c)
      buffers.Calibrate(c, dark[c], gain[c], gain2[c], c0[c], c1[c], c2[c], c3[c]);
    for (std::array<double, RowBuffers::kN>& v : buffers.sigma_f) SqrtInPlace(v);
    for (std::size_t i = 0; i < n; ++i) {
      Sample& s = slice.samples.emplace_back();
      s.theta_in_deg = begin.theta_in_deg;
      s.phi_in_deg = 0;
      s.theta_out_deg = theta_out;
      s.phi_out_deg = phi_out_deg[row.first_column + i];
      bool below = false;
      for (int c = 0; c < 3; ++c) {
        s.rgb[c] = static_cast<float>(buffers.f[c][i]);
        s.sigma[c] = static_cast<float>(buffers.sigma_f[c][i]);
        below = below || buffers.signal[c][i] < floor[c];
      }
      s.flags = 0;
      if (row.ClippedChannels(i) != 0) {
        s.flags |= kFlagSaturated;
        ++rep.saturated;
      }
      if (below) {
        s.flags |= kFlagBelowNoiseFloor;
        ++rep.below_noise_floor;
      }
    }
    received += n;
    next_column += n;
    if (next_column == g.columns) {
      next_column = 0;
      ++next_row;
    }
  }
  rep.samples = slice.samples.size();
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = rep;
  return slice;
}

void Driver::Abort() {
  const AbortScope aborting(*this);
  Send(MessageType::kAbort, {});
  for (;;) {
    const Frame f = NextFrame("ACK of ABORT");
    const auto type = static_cast<MessageType>(f.type);
    if (type != MessageType::kAck && type != MessageType::kError)
      continue;  // the rest of a stream, or a reply, that was already on its way
    if (type != MessageType::kAck) ThrowInstrumentError(f, MessageType::kAbort);
    return;
  }
}

void Driver::Recover() {
  // Whatever was in flight is suspect: forget the buffered bytes and the sequence, then wait
  // for the acknowledgement of a fresh ABORT, skipping anything else (the tail of a stream, a
  // late reply, an error about the damaged request).
  const AbortScope aborting(*this);
  reader_.Clear();
  last_damage_.clear();
  Send(MessageType::kAbort, {});
  have_device_sequence_ = false;
  for (;;) {
    Frame f;
    try {
      f = NextFrame("ACK of ABORT", /*check_sequence=*/false);
    } catch (const DriverFault& e) {
      if (e.kind() == FaultKind::kTimeout || e.kind() == FaultKind::kDamagedFrame)
        Fail(FaultKind::kNotAnswering,
             "the instrument stopped answering (no acknowledgement of ABORT within " +
                 std::to_string(options_.timeout_ms) + " ms)");
      throw;
    }
    if (f.type == static_cast<std::uint8_t>(MessageType::kAck) && !f.payload.empty() &&
        f.payload[0] == static_cast<std::uint8_t>(MessageType::kAbort))
      return;
  }
}

void Driver::RestoreCalibration(const DarkCalibration& dark, std::vector<WhiteCalibration> whites) {
  if (!connected_) throw InvalidArgument("RestoreCalibration: connect to the instrument first");
  dark_ = dark;
  have_dark_ = true;
  whites_ = std::move(whites);
}

Metadata Driver::CalibrationMetadata() const {
  Metadata m;
  const IdentityInfo& id = info_.identity;
  m.instrument_model = id.model;
  m.instrument_serial = id.serial;
  m.firmware_version = id.firmware_version;
  m.protocol_version = std::to_string(id.protocol_major) + "." + std::to_string(id.protocol_minor);
  const WhiteReference& w = options_.white;
  m.calibration_reference = std::string(w.name) + "; rho RGB " + Triple(w.rho, "%.6f") + " ± " +
                            Triple(w.rho_uncertainty, "%.4f") + " (" + std::string(w.provenance) +
                            ")";
  m.calibration_time = whites_.empty() ? dark_.time : whites_.front().time;
  m.software_version = SoftwareVersion();
  m.extra["exposure_mode"] = std::string(ExposureModeName(exposure_.mode));
  if (exposure_.mode == ExposureMode::kFixed)
    m.extra["exposure_ms"] = Fmt("%.9g", exposure_.exposure_ms);
  m.extra["frames_per_reading"] = std::to_string(id.frames_per_reading);
  m.extra["adc_full_scale_counts"] = Fmt("%.9g", id.adc_full_scale_counts);
  if (have_dark_) {
    m.extra["dark_counts"] = Triple(dark_.mean_counts);
    m.extra["read_noise_counts"] = Triple(dark_.read_noise_counts);
    m.extra["dark_frames"] = std::to_string(dark_.frames);
    m.extra["dark_time"] = dark_.time;
  }
  for (const WhiteCalibration& wc : whites_) {
    const std::string key = "white_theta_in_" + ShortNumberText(wc.theta_in_deg);
    m.extra[key + "_counts"] = Triple(wc.counts);
    m.extra[key + "_exposure_ms"] = Fmt("%.9g", wc.exposure_ms);
    if (wc.nd_transmittance != 1)
      m.extra[key + "_nd_transmittance"] = Fmt("%.9g", wc.nd_transmittance);
    m.extra[key + "_frames"] = std::to_string(wc.frames);
    m.extra[key + "_time"] = wc.time;
  }
  return m;
}

namespace {

// Runs `step` until it succeeds, recovering and trying again after a retryable fault.
template <class Step>
auto WithRetries(Driver& driver, const CaptureCallbacks& callbacks, Step step) {
  for (int attempt = 1;; ++attempt) {
    try {
      return step();
    } catch (const DriverFault& e) {
      if (!e.retryable() || attempt > driver.options().retries || driver.cancelled()) throw;
      if (callbacks.on_retry) callbacks.on_retry(e, attempt);
      driver.Recover();
    }
  }
}

}  // namespace

Metadata Capture(Driver& driver, const CapturePlan& plan, const CaptureCallbacks& callbacks) {
  const std::string start = UtcNowIso8601();
  const InstrumentInfo& info =
      WithRetries(driver, callbacks, [&]() -> const InstrumentInfo& { return driver.Connect(); });
  if (plan.theta_in_deg.empty()) throw InvalidArgument("capture plan has no incidence angle");
  for (std::size_t i = 0; i < plan.theta_in_deg.size(); ++i) {
    const double t = plan.theta_in_deg[i];
    bool offered = false;
    std::string list;
    for (float a : info.geometry.theta_in_deg) {
      offered = offered || std::fabs(a - t) <= kThetaMatchDeg;
      list += (list.empty() ? "" : ", ") + ShortNumberText(a);
    }
    if (!offered)
      throw InvalidArgument("θin " + ShortNumberText(t) + "° is not offered by " +
                            info.identity.model + " (it measures θin = " + list + "°)");
    for (std::size_t j = 0; j < i; ++j)
      if (std::fabs(plan.theta_in_deg[j] - t) <= kThetaMatchDeg)
        throw InvalidArgument("θin " + ShortNumberText(t) + "° is listed twice");
  }
  // A fixed exposure the instrument cannot take is the user's mistake, said before anything is
  // measured (the firmware would refuse it too, in its own words).
  const float lo = info.geometry.min_exposure_ms, hi = info.geometry.max_exposure_ms;
  if (plan.exposure.mode == ExposureMode::kFixed && hi > 0 &&
      !(plan.exposure.exposure_ms >= lo && plan.exposure.exposure_ms <= hi))
    throw InvalidArgument("exposure: expected a fixed time from " + ShortNumberText(lo) + " to " +
                          ShortNumberText(hi) + " ms (the range of " + info.identity.model +
                          "), got " + ShortNumberText(plan.exposure.exposure_ms) + " ms");
  if (callbacks.on_connected) callbacks.on_connected(info);
  WithRetries(driver, callbacks, [&] { driver.SetExposure(plan.exposure); });
  const bool restored = callbacks.restore_calibration && callbacks.restore_calibration(driver);
  if (!restored) {
    WithRetries(driver, callbacks, [&] { driver.MeasureDark(); });
    for (double t : plan.theta_in_deg)
      WithRetries(driver, callbacks, [&] { driver.MeasureWhite(t); });
  }

  auto merge = [&](Metadata m) {
    m.sample_name = plan.metadata.sample_name;
    m.operator_notes = plan.metadata.operator_notes;
    for (const auto& [key, value] : plan.metadata.extra) m.extra[key] = value;
    m.capture_start = start;
    return m;
  };
  if (callbacks.on_calibrated) callbacks.on_calibrated(merge(driver.CalibrationMetadata()));
  for (double t : plan.theta_in_deg) {
    if (driver.cancelled())
      throw DriverFault(FaultKind::kCancelled,
                        "capture cancelled before the slice at θin " + ShortNumberText(t) + "°");
    SliceReport report;
    Slice slice = WithRetries(driver, callbacks, [&] { return driver.MeasureSlice(t, &report); });
    if (callbacks.on_slice) callbacks.on_slice(std::move(slice), report);
  }
  Metadata final_metadata = merge(driver.CalibrationMetadata());
  final_metadata.capture_end = UtcNowIso8601();
  return final_metadata;
}

}  // namespace brdf::device
