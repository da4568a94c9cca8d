#include "brdf/device/protocol.h"

#include <cstdio>
#include <cstring>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"

namespace brdf::device {
namespace {

// Little-endian payload builder (the frame codec's own buffer type is a byte vector).
class PayloadWriter {
 public:
  void U8(std::uint8_t v) { bytes_.push_back(v); }
  void U16(std::uint16_t v) {
    U8(static_cast<std::uint8_t>(v & 0xff));
    U8(static_cast<std::uint8_t>(v >> 8));
  }
  void U32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) U8(static_cast<std::uint8_t>((v >> (8 * i)) & 0xff));
  }
  void F32(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    U32(bits);
  }
  // u8 length, then the bytes; longer strings are cut at 255 bytes.
  void String(std::string_view s) {
    const std::size_t n = s.size() > 255 ? 255 : s.size();
    U8(static_cast<std::uint8_t>(n));
    bytes_.insert(bytes_.end(), s.begin(), s.begin() + static_cast<std::ptrdiff_t>(n));
  }
  std::vector<std::uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

std::uint32_t LoadU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// Runs `parse` over a payload with a ByteReader named after the message, turning the reader's
// FormatError ("ROW_DATA payload: byte 9: expected 4 more bytes for exposure_ms, got …") into
// the DeviceError the driver reports.
template <class Parse>
auto ParsePayload(MessageType type, std::span<const std::uint8_t> payload, Parse parse) {
  ByteReader reader(payload.data(), payload.size(),
                    MessageTypeName(static_cast<std::uint8_t>(type)) + " payload");
  try {
    return parse(reader);
  } catch (const FormatError& e) {
    throw DeviceError(std::string("malformed message from the instrument: ") + e.what());
  }
}

std::string ReadString(ByteReader& r, std::string_view what) {
  const std::uint8_t n = r.U8(what);
  return r.String(n, what);
}

void WriteRgb(PayloadWriter& w, const std::array<float, 3>& v) {
  for (float x : v) w.F32(x);
}

std::array<float, 3> ReadRgb(ByteReader& r, std::string_view what) {
  std::array<float, 3> v{};
  for (float& x : v) x = r.F32(what);
  return v;
}

}  // namespace

std::string MessageTypeName(std::uint8_t type) {
  switch (static_cast<MessageType>(type)) {
    case MessageType::kIdentify:
      return "IDENTIFY";
    case MessageType::kGetGeometry:
      return "GET_GEOMETRY";
    case MessageType::kSetExposure:
      return "SET_EXPOSURE";
    case MessageType::kMeasureDark:
      return "MEASURE_DARK";
    case MessageType::kMeasureWhite:
      return "MEASURE_WHITE";
    case MessageType::kMeasureSlice:
      return "MEASURE_SLICE";
    case MessageType::kAbort:
      return "ABORT";
    case MessageType::kIdentity:
      return "IDENTITY";
    case MessageType::kGeometry:
      return "GEOMETRY";
    case MessageType::kAck:
      return "ACK";
    case MessageType::kDark:
      return "DARK";
    case MessageType::kWhite:
      return "WHITE";
    case MessageType::kSliceBegin:
      return "SLICE_BEGIN";
    case MessageType::kRowData:
      return "ROW_DATA";
    case MessageType::kSliceEnd:
      return "SLICE_END";
    case MessageType::kError:
      return "ERROR";
  }
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", type);
  return buf;
}

void AppendFrame(std::vector<std::uint8_t>& out, std::uint8_t type, std::uint8_t sequence,
                 std::span<const std::uint8_t> payload) {
  if (payload.size() > kMaxPayloadBytes)
    throw InvalidArgument("frame payload of " + std::to_string(payload.size()) +
                          " bytes exceeds the protocol limit of " +
                          std::to_string(kMaxPayloadBytes));
  const std::size_t start = out.size();
  const auto n = static_cast<std::uint16_t>(payload.size());
  out.push_back(kSync0);
  out.push_back(kSync1);
  out.push_back(type);
  out.push_back(sequence);
  out.push_back(static_cast<std::uint8_t>(n & 0xff));
  out.push_back(static_cast<std::uint8_t>(n >> 8));
  out.insert(out.end(), payload.begin(), payload.end());
  const std::uint32_t crc = Crc32(out.data() + start + 2, kFrameHeaderBytes - 2 + payload.size());
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>((crc >> (8 * i)) & 0xff));
}

std::vector<std::uint8_t> EncodeFrame(const Frame& frame) {
  std::vector<std::uint8_t> out;
  out.reserve(kFrameHeaderBytes + frame.payload.size() + kFrameCrcBytes);
  AppendFrame(out, frame.type, frame.sequence, frame.payload);
  return out;
}

DecodeResult DecodeFrame(std::span<const std::uint8_t> bytes) {
  DecodeResult result;
  if (bytes.empty()) return result;  // kNeedMore
  // Anything before a sync pair is noise between frames: skip to the next 0xB7.
  if (bytes[0] != kSync0 || (bytes.size() >= 2 && bytes[1] != kSync1)) {
    std::size_t skip = 1;
    while (skip < bytes.size() && bytes[skip] != kSync0) ++skip;
    result.status = DecodeStatus::kInvalid;
    result.consumed = skip;
    result.reason = "no frame start (sync 0xB7 0xDF): skipped " + std::to_string(skip) +
                    (skip == 1 ? " byte" : " bytes");
    return result;
  }
  if (bytes.size() < kFrameHeaderBytes) return result;
  const std::size_t length =
      static_cast<std::size_t>(bytes[4]) | (static_cast<std::size_t>(bytes[5]) << 8);
  if (length > kMaxPayloadBytes) {
    result.status = DecodeStatus::kInvalid;
    result.consumed = 1;
    result.corrupt = true;
    result.reason = "payload length " + std::to_string(length) + " exceeds the limit of " +
                    std::to_string(kMaxPayloadBytes) + " bytes";
    return result;
  }
  const std::size_t total = kFrameHeaderBytes + length + kFrameCrcBytes;
  if (bytes.size() < total) return result;
  const std::uint32_t stored = LoadU32(bytes.data() + kFrameHeaderBytes + length);
  const std::uint32_t computed = Crc32(bytes.data() + 2, kFrameHeaderBytes - 2 + length);
  if (stored != computed) {
    result.status = DecodeStatus::kInvalid;
    result.consumed = 1;
    result.corrupt = true;
    result.reason = MessageTypeName(bytes[2]) + " frame " + std::to_string(bytes[3]) +
                    ": CRC-32: expected " + Hex32Text(computed) + ", got " + Hex32Text(stored);
    return result;
  }
  result.status = DecodeStatus::kComplete;
  result.consumed = total;
  result.crc = stored;
  result.frame.type = bytes[2];
  result.frame.sequence = bytes[3];
  result.frame.payload.assign(
      bytes.begin() + kFrameHeaderBytes,
      bytes.begin() + static_cast<std::ptrdiff_t>(kFrameHeaderBytes + length));
  return result;
}

void FrameReader::Append(std::span<const std::uint8_t> bytes) {
  // Compact before growing so the buffer never holds consumed bytes plus new ones for long.
  if (start_ > 0 &&
      (start_ >= buffer_.size() / 2 || buffer_.size() + bytes.size() > 2 * kMaxFrameBytes)) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

DecodeResult FrameReader::Next() {
  DecodeResult r = DecodeFrame(std::span<const std::uint8_t>(buffer_).subspan(start_));
  start_ += r.consumed;
  if (start_ == buffer_.size()) Clear();
  return r;
}

void FrameReader::Clear() {
  buffer_.clear();
  start_ = 0;
}

float GeometryInfo::ThetaOutDeg(std::size_t row) const {
  return static_cast<float>(static_cast<double>(row) * static_cast<double>(theta_out_step_deg));
}

float GeometryInfo::PhiOutDeg(std::size_t column) const {
  return static_cast<float>(static_cast<double>(column) * static_cast<double>(phi_out_step_deg));
}

std::string_view ExposureModeName(ExposureMode mode) {
  switch (mode) {
    case ExposureMode::kAutoPerRow:
      return "auto-row";
    case ExposureMode::kAutoPerSlice:
      return "auto-slice";
    case ExposureMode::kFixed:
      return "fixed";
  }
  return "unknown";
}

std::vector<std::uint8_t> EncodeIdentity(const IdentityInfo& info) {
  PayloadWriter w;
  w.String(info.model);
  w.String(info.serial);
  w.String(info.firmware_version);
  w.U16(info.protocol_major);
  w.U16(info.protocol_minor);
  w.F32(info.adc_full_scale_counts);
  w.U16(info.frames_per_reading);
  w.F32(info.shot_variance_per_count);
  return w.Take();
}

IdentityInfo DecodeIdentity(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kIdentity, payload, [](ByteReader& r) {
    IdentityInfo info;
    info.model = ReadString(r, "model");
    info.serial = ReadString(r, "serial");
    info.firmware_version = ReadString(r, "firmware_version");
    info.protocol_major = r.U16("protocol_major");
    info.protocol_minor = r.U16("protocol_minor");
    info.adc_full_scale_counts = r.F32("adc_full_scale_counts");
    info.frames_per_reading = r.U16("frames_per_reading");
    info.shot_variance_per_count = r.F32("shot_variance_per_count");
    if (info.frames_per_reading == 0) r.Fail("frames_per_reading ≥ 1", "0");
    return info;
  });
}

std::vector<std::uint8_t> EncodeGeometry(const GeometryInfo& info) {
  PayloadWriter w;
  w.U8(static_cast<std::uint8_t>(info.theta_in_deg.size()));
  for (float t : info.theta_in_deg) w.F32(t);
  w.F32(info.theta_out_max_deg);
  w.F32(info.theta_out_step_deg);
  w.F32(info.phi_out_step_deg);
  w.U16(info.rows);
  w.U16(info.columns);
  w.F32(info.min_exposure_ms);
  w.F32(info.max_exposure_ms);
  w.U8(static_cast<std::uint8_t>(info.nd_transmittance.size()));
  for (float t : info.nd_transmittance) w.F32(t);
  return w.Take();
}

GeometryInfo DecodeGeometry(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kGeometry, payload, [](ByteReader& r) {
    GeometryInfo info;
    const std::uint8_t n = r.U8("theta_in count");
    for (std::uint8_t i = 0; i < n; ++i) info.theta_in_deg.push_back(r.F32("theta_in_deg"));
    info.theta_out_max_deg = r.F32("theta_out_max_deg");
    info.theta_out_step_deg = r.F32("theta_out_step_deg");
    info.phi_out_step_deg = r.F32("phi_out_step_deg");
    info.rows = r.U16("rows");
    info.columns = r.U16("columns");
    if (!(info.theta_out_step_deg > 0) || !(info.phi_out_step_deg > 0))
      r.Fail("positive angular steps", std::to_string(info.theta_out_step_deg) + ", " +
                                           std::to_string(info.phi_out_step_deg));
    if (r.remaining() > 0) {  // protocol 1.1
      info.min_exposure_ms = r.F32("min_exposure_ms");
      info.max_exposure_ms = r.F32("max_exposure_ms");
      const std::uint8_t nd = r.U8("nd filter count");
      if (nd == 0) r.Fail("at least the open position in the ND filter list", "0 filters");
      info.nd_transmittance.clear();
      for (std::uint8_t i = 0; i < nd; ++i) {
        const float t = r.F32("nd_transmittance");
        if (!(t > 0 && t <= 1)) r.Fail("an ND transmittance in (0, 1]", std::to_string(t));
        info.nd_transmittance.push_back(t);
      }
    }
    return info;
  });
}

std::vector<std::uint8_t> EncodeExposure(const ExposureSetting& setting) {
  PayloadWriter w;
  w.U8(static_cast<std::uint8_t>(setting.mode));
  w.F32(setting.exposure_ms);
  return w.Take();
}

ExposureSetting DecodeExposure(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kSetExposure, payload, [](ByteReader& r) {
    ExposureSetting s;
    const std::uint8_t mode = r.U8("mode");
    if (mode > static_cast<std::uint8_t>(ExposureMode::kFixed))
      r.Fail("exposure mode 0, 1 or 2", std::to_string(mode));
    s.mode = static_cast<ExposureMode>(mode);
    s.exposure_ms = r.F32("exposure_ms");
    return s;
  });
}

std::vector<std::uint8_t> EncodeThetaIn(float theta_in_deg) {
  PayloadWriter w;
  w.F32(theta_in_deg);
  return w.Take();
}

float DecodeThetaIn(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kMeasureSlice, payload,
                      [](ByteReader& r) { return r.F32("theta_in_deg"); });
}

std::vector<std::uint8_t> EncodeAck(std::uint8_t request_type) { return {request_type}; }

std::uint8_t DecodeAck(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kAck, payload,
                      [](ByteReader& r) { return r.U8("request_type"); });
}

std::vector<std::uint8_t> EncodeDark(const DarkReading& reading) {
  PayloadWriter w;
  WriteRgb(w, reading.mean_counts);
  WriteRgb(w, reading.read_noise_counts);
  w.U16(reading.frames);
  return w.Take();
}

DarkReading DecodeDark(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kDark, payload, [](ByteReader& r) {
    DarkReading d;
    d.mean_counts = ReadRgb(r, "mean_counts");
    d.read_noise_counts = ReadRgb(r, "read_noise_counts");
    d.frames = r.U16("frames");
    return d;
  });
}

std::vector<std::uint8_t> EncodeWhite(const WhiteReading& reading) {
  PayloadWriter w;
  w.F32(reading.theta_in_deg);
  w.F32(reading.exposure_ms);
  WriteRgb(w, reading.counts);
  w.U8(reading.clipped_channels);
  w.U16(reading.frames);
  w.U8(reading.nd_index);
  return w.Take();
}

WhiteReading DecodeWhite(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kWhite, payload, [](ByteReader& r) {
    WhiteReading wr;
    wr.theta_in_deg = r.F32("theta_in_deg");
    wr.exposure_ms = r.F32("exposure_ms");
    wr.counts = ReadRgb(r, "counts");
    wr.clipped_channels = r.U8("clipped_channels");
    wr.frames = r.U16("frames");
    if (r.remaining() > 0) wr.nd_index = r.U8("nd_index");  // protocol 1.1
    return wr;
  });
}

std::vector<std::uint8_t> EncodeSliceBegin(const SliceBegin& begin) {
  PayloadWriter w;
  w.F32(begin.theta_in_deg);
  w.U16(begin.rows);
  w.U16(begin.columns);
  return w.Take();
}

SliceBegin DecodeSliceBegin(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kSliceBegin, payload, [](ByteReader& r) {
    SliceBegin b;
    b.theta_in_deg = r.F32("theta_in_deg");
    b.rows = r.U16("rows");
    b.columns = r.U16("columns");
    return b;
  });
}

std::vector<std::uint8_t> EncodeRowData(const RowData& row) {
  if (row.samples.size() > kMaxSamplesPerRowFrame)
    throw InvalidArgument("ROW_DATA with " + std::to_string(row.samples.size()) +
                          " samples exceeds the limit of " +
                          std::to_string(kMaxSamplesPerRowFrame));
  PayloadWriter w;
  w.U16(row.row);
  w.U16(row.first_column);
  w.U16(static_cast<std::uint16_t>(row.samples.size()));
  w.F32(row.exposure_ms);
  for (const RowSample& s : row.samples) {
    WriteRgb(w, s.counts);
    w.U8(s.clipped_channels);
  }
  w.U8(row.nd_index);
  return w.Take();
}

RowDataView DecodeRowDataView(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kRowData, payload, [](ByteReader& r) {
    RowDataView row;
    row.row = r.U16("row");
    row.first_column = r.U16("first_column");
    const std::uint16_t n = r.U16("sample count");
    if (n > kMaxSamplesPerRowFrame)
      r.Fail("at most " + std::to_string(kMaxSamplesPerRowFrame) + " samples", std::to_string(n));
    row.exposure_ms = r.F32("exposure_ms");
    // One bounds check for all samples, which stay where they are.
    const std::size_t bytes = std::size_t{n} * RowDataView::kSampleBytes;
    row.sample_bytes =
        std::span<const std::uint8_t>(r.Bytes(bytes, "samples (13 bytes each)"), bytes);
    row.nd_index = r.remaining() > 0 ? r.U8("nd_index") : 0;  // protocol 1.1
    return row;
  });
}

RowData DecodeRowData(std::span<const std::uint8_t> payload) {
  const RowDataView view = DecodeRowDataView(payload);
  RowData row;
  row.row = view.row;
  row.first_column = view.first_column;
  row.exposure_ms = view.exposure_ms;
  row.nd_index = view.nd_index;
  row.samples.resize(view.size());
  for (std::size_t i = 0; i < row.samples.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      row.samples[i].counts[static_cast<std::size_t>(c)] = view.Counts(i, c);
    row.samples[i].clipped_channels = view.ClippedChannels(i);
  }
  return row;
}

std::vector<std::uint8_t> EncodeSliceEnd(const SliceEnd& end) {
  PayloadWriter w;
  w.F32(end.theta_in_deg);
  w.U32(end.samples);
  w.U32(end.clipped_samples);
  return w.Take();
}

SliceEnd DecodeSliceEnd(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kSliceEnd, payload, [](ByteReader& r) {
    SliceEnd e;
    e.theta_in_deg = r.F32("theta_in_deg");
    e.samples = r.U32("samples");
    e.clipped_samples = r.U32("clipped_samples");
    return e;
  });
}

std::vector<std::uint8_t> EncodeError(const ErrorReply& error) {
  PayloadWriter w;
  w.U16(static_cast<std::uint16_t>(error.code));
  w.U8(error.request_type);
  w.String(error.message);
  return w.Take();
}

ErrorReply DecodeError(std::span<const std::uint8_t> payload) {
  return ParsePayload(MessageType::kError, payload, [](ByteReader& r) {
    ErrorReply e;
    e.code = static_cast<ErrorCode>(r.U16("code"));
    e.request_type = r.U8("request_type");
    e.message = ReadString(r, "message");
    return e;
  });
}

}  // namespace brdf::device
