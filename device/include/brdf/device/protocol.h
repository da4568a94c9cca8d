// The scatterometer wire protocol: framing and message payloads.
//
// Host and instrument exchange frames over a byte stream (USB bulk, HID reports, or the
// in-process loopback to the simulated firmware). The codec here is pure: it turns bytes into
// frames and frames into bytes and never touches a transport, so it is tested, fuzzed and
// reused by both sides (the host driver and the simulated firmware) without any I/O.
//
// Frame layout (all integers little-endian):
//
//   offset  size  field
//   0       2     sync bytes 0xB7 0xDF
//   2       1     message type (MessageType)
//   3       1     sequence number: the sender's frame counter, modulo 256
//   4       2     payload length N (0 ≤ N ≤ kMaxPayloadBytes)
//   6       N     payload (message specific, see the structs below)
//   6+N     4     CRC-32 (brdf::Crc32, zlib's) of bytes 2 … 5+N (type, sequence, length, payload)
//
// Each side numbers its own frames; a receiver that sees a sequence number jump knows a frame
// was lost. Nothing depends on how the stream is cut into transfers: the HID transport carries
// the stream in 64-byte reports (a count byte and up to 63 stream bytes each), so a frame of
// the largest size spans 66 reports, and the decoder finds frames in any chunking.
//
// Floats are IEEE-754 binary32, little-endian. Angles are degrees, exposures milliseconds,
// detector readings are "counts": the mean of several ADC frames, so fractional.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace brdf::device {

inline constexpr std::uint8_t kSync0 = 0xB7;
inline constexpr std::uint8_t kSync1 = 0xDF;
inline constexpr std::size_t kFrameHeaderBytes = 6;
inline constexpr std::size_t kFrameCrcBytes = 4;
inline constexpr std::size_t kMaxPayloadBytes = 4096;
inline constexpr std::size_t kMaxFrameBytes = kFrameHeaderBytes + kMaxPayloadBytes + kFrameCrcBytes;

// The protocol version this code speaks. A host accepts an instrument with the same major
// version; minor versions only add messages or trailing payload fields.
inline constexpr std::uint16_t kProtocolMajor = 1;
inline constexpr std::uint16_t kProtocolMinor = 1;

// Largest number of samples one kRowData frame carries; longer rows are split into segments.
// 180 samples (one row at 2° azimuth steps, or half a row at 1°) are 2,357 payload bytes
// (protocol 1.1).
inline constexpr std::size_t kMaxSamplesPerRowFrame = 180;

enum class MessageType : std::uint8_t {
  // Host → instrument.
  kIdentify = 0x01,      // no payload; answered by kIdentity
  kGetGeometry = 0x02,   // no payload; answered by kGeometry
  kSetExposure = 0x03,   // ExposureSetting; answered by kAck
  kMeasureDark = 0x04,   // no payload (shutter closed); answered by kDark
  kMeasureWhite = 0x05,  // f32 θin: white reference in place; answered by kWhite
  kMeasureSlice = 0x06,  // f32 θin; answered by kSliceBegin, kRowData…, kSliceEnd
  kAbort = 0x07,         // no payload; stops a slice stream, answered by kAck
  // Instrument → host.
  kIdentity = 0x81,
  kGeometry = 0x82,
  kAck = 0x83,  // u8: the type of the request acknowledged
  kDark = 0x84,
  kWhite = 0x85,
  kSliceBegin = 0x86,
  kRowData = 0x87,
  kSliceEnd = 0x88,
  kError = 0xEE,
};

// "IDENTIFY", "ROW_DATA", … or "0x5A" for a type this code does not know.
std::string MessageTypeName(std::uint8_t type);

struct Frame {
  std::uint8_t type = 0;  // a MessageType value; unknown values are left to the message layer
  std::uint8_t sequence = 0;
  std::vector<std::uint8_t> payload;
};

// Appends the encoded frame to `out`. Throws InvalidArgument if the payload is larger than
// kMaxPayloadBytes.
void AppendFrame(std::vector<std::uint8_t>& out, std::uint8_t type, std::uint8_t sequence,
                 std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeFrame(const Frame& frame);

enum class DecodeStatus {
  kComplete,  // a whole, CRC-checked frame starts at the first byte
  kNeedMore,  // the bytes are the beginning of a frame; call again with more
  kInvalid,   // the first bytes cannot start a valid frame; discard `consumed` bytes and retry
};

struct DecodeResult {
  DecodeStatus status = DecodeStatus::kNeedMore;
  // kComplete: the frame's length in bytes. kInvalid: how many leading bytes to discard (at
  // least 1; up to the next possible sync byte). kNeedMore: 0.
  std::size_t consumed = 0;
  Frame frame;            // kComplete only
  std::uint32_t crc = 0;  // kComplete only: the frame's CRC-32 (identifies a repeated frame)
  std::string reason;    // kInvalid only: "CRC-32: expected 0x…, got 0x…", "no sync bytes", …
  bool corrupt = false;  // kInvalid only: a frame header was found but its content is damaged
                         // (CRC mismatch), as opposed to bytes between frames
};

// Decodes the frame at the start of `bytes`. Pure: no state, no allocation beyond the result.
// Resynchronisation after garbage or a damaged frame is the caller discarding `consumed` bytes
// and calling again; a damaged frame discards only its first byte, so a frame hidden inside
// the garbage is still found.
DecodeResult DecodeFrame(std::span<const std::uint8_t> bytes);

// Buffers a byte stream and hands out decode results one at a time: the stateful wrapper a
// receiver uses around DecodeFrame. Bounded: never holds more than one maximal frame plus the
// last chunk appended.
class FrameReader {
 public:
  void Append(std::span<const std::uint8_t> bytes);
  // The next complete frame or invalid stretch (already discarded), or kNeedMore when the
  // buffered bytes are only the beginning of a frame.
  DecodeResult Next();
  std::size_t buffered() const { return buffer_.size() - start_; }
  void Clear();

 private:
  std::vector<std::uint8_t> buffer_;
  std::size_t start_ = 0;
};

// Message payloads. Encode* produce a payload; Decode* parse one and throw brdf::DeviceError
// naming the message and the field when the payload is malformed (a frame that passed its CRC
// but does not follow the protocol is a device fault, not an expected outcome).

struct IdentityInfo {
  std::string model;             // "BRDF-SIM MD2"
  std::string serial;            // "SIM-000001"
  std::string firmware_version;  // "2.4.1-sim"
  std::uint16_t protocol_major = kProtocolMajor;
  std::uint16_t protocol_minor = kProtocolMinor;
  // Detector description the host needs to propagate uncertainty and flag samples:
  float adc_full_scale_counts = 0;       // a single ADC frame clips here
  std::uint16_t frames_per_reading = 1;  // a sample's counts are the mean of this many frames
  // Shot noise: variance of one frame, in counts², per count of signal above dark
  // (the conversion gain in counts per electron, times the square of the noise level).
  float shot_variance_per_count = 0;
};

struct GeometryInfo {
  std::vector<float> theta_in_deg;  // incidence angles the instrument can measure
  float theta_out_max_deg = 0;
  float theta_out_step_deg = 0;
  float phi_out_step_deg = 0;
  std::uint16_t rows = 0;     // θout rows: θout = row · step, row = 0 … rows − 1
  std::uint16_t columns = 0;  // φout columns: φout = column · step, column = 0 … columns − 1

  // Protocol 1.1 (trailing fields; a 1.0 instrument omits them): the exposure range and the
  // neutral-density filter stage. nd_transmittance[0] is the open position (1.0); a reading
  // taken through filter k saw exposure_ms · nd_transmittance[k] worth of light.
  float min_exposure_ms = 0, max_exposure_ms = 0;  // 0: not reported (1.0 instrument)
  std::vector<float> nd_transmittance = {1.0f};

  // The angles of a row and a column exactly as both ends compute them (float32, so the
  // simulator's directions and the host's recorded angles agree bit for bit).
  float ThetaOutDeg(std::size_t row) const;
  float PhiOutDeg(std::size_t column) const;
};

enum class ExposureMode : std::uint8_t {
  kAutoPerRow = 0,    // each θout row is auto-ranged on its own brightest sample (default)
  kAutoPerSlice = 1,  // one exposure per slice, ranged on the slice's brightest sample
  kFixed = 2,         // the exposure given; bright samples may saturate
};
std::string_view ExposureModeName(ExposureMode mode);  // "auto-row", "auto-slice", "fixed"

struct ExposureSetting {
  ExposureMode mode = ExposureMode::kAutoPerRow;
  float exposure_ms = 0;  // kFixed only
};

struct DarkReading {
  std::array<float, 3> mean_counts{};        // dark signal per channel (shutter closed)
  std::array<float, 3> read_noise_counts{};  // standard deviation of a single dark frame
  std::uint16_t frames = 0;                  // frames averaged
};

struct WhiteReading {
  float theta_in_deg = 0;
  float exposure_ms = 0;
  std::array<float, 3> counts{};      // mean of `frames` frames, dark not subtracted
  std::uint8_t clipped_channels = 0;  // bit c set: some frame of channel c clipped
  std::uint16_t frames = 0;
  std::uint8_t nd_index = 0;  // 1.1 trailing field: the ND filter of the reading (0 = open)
};

struct SliceBegin {
  float theta_in_deg = 0;
  std::uint16_t rows = 0, columns = 0;
};

struct RowSample {
  std::array<float, 3> counts{};      // mean of frames_per_reading frames, dark not subtracted
  std::uint8_t clipped_channels = 0;  // bit c set: some frame of channel c clipped at full scale
};

struct RowData {
  std::uint16_t row = 0;
  std::uint16_t first_column = 0;
  float exposure_ms = 0;
  std::vector<RowSample> samples;  // columns first_column … first_column + size − 1
  std::uint8_t nd_index = 0;       // 1.1 trailing field: the ND filter of the row (0 = open)
};

struct SliceEnd {
  float theta_in_deg = 0;
  std::uint32_t samples = 0;          // samples streamed for the slice
  std::uint32_t clipped_samples = 0;  // of which some channel clipped
};

enum class ErrorCode : std::uint16_t {
  kUnknownCommand = 1,
  kBadPayload = 2,
  kBadArgument = 3,  // e.g. a θin the instrument cannot set
  kBusy = 4,         // a slice is streaming; only kAbort is accepted
  kBadFrame = 5,     // the instrument received a damaged frame
  // Instrument states that stop a measurement; the host cannot retry them away.
  kLampFailure = 6,         // the light source failed or did not reach its set point
  kSampleNotInContact = 7,  // the sample port sensor sees no sample seated
  kOverTemperature = 8,     // the detector is above its operating temperature
};

struct ErrorReply {
  ErrorCode code = ErrorCode::kBadArgument;
  std::uint8_t request_type = 0;
  std::string message;
};

std::vector<std::uint8_t> EncodeIdentity(const IdentityInfo& info);
IdentityInfo DecodeIdentity(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeGeometry(const GeometryInfo& info);
GeometryInfo DecodeGeometry(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeExposure(const ExposureSetting& setting);
ExposureSetting DecodeExposure(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeThetaIn(float theta_in_deg);  // kMeasureWhite, kMeasureSlice
float DecodeThetaIn(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeAck(std::uint8_t request_type);
std::uint8_t DecodeAck(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeDark(const DarkReading& reading);
DarkReading DecodeDark(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeWhite(const WhiteReading& reading);
WhiteReading DecodeWhite(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeSliceBegin(const SliceBegin& begin);
SliceBegin DecodeSliceBegin(std::span<const std::uint8_t> payload);
// Throws InvalidArgument for more than kMaxSamplesPerRowFrame samples.
std::vector<std::uint8_t> EncodeRowData(const RowData& row);
RowData DecodeRowData(std::span<const std::uint8_t> payload);
// A ROW_DATA payload checked as DecodeRowData checks it, with the samples left in the payload
// (13 bytes each: three f32 counts, then the clip bits): the driver calibrates straight from
// the frame instead of from a copy. Valid while `payload` is.
struct RowDataView {
  static constexpr std::size_t kSampleBytes = 13;
  std::uint16_t row = 0;
  std::uint16_t first_column = 0;
  float exposure_ms = 0;
  std::uint8_t nd_index = 0;
  std::span<const std::uint8_t> sample_bytes;  // size() × kSampleBytes

  std::size_t size() const { return sample_bytes.size() / kSampleBytes; }
  float Counts(std::size_t i, int channel) const {
    std::uint32_t bits = 0;
    for (int b = 3; b >= 0; --b)
      bits = (bits << 8) | sample_bytes[i * kSampleBytes + 4 * static_cast<std::size_t>(channel) +
                                        static_cast<std::size_t>(b)];
    return std::bit_cast<float>(bits);
  }
  std::uint8_t ClippedChannels(std::size_t i) const { return sample_bytes[i * kSampleBytes + 12]; }
};
RowDataView DecodeRowDataView(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeSliceEnd(const SliceEnd& end);
SliceEnd DecodeSliceEnd(std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> EncodeError(const ErrorReply& error);
ErrorReply DecodeError(std::span<const std::uint8_t> payload);

}  // namespace brdf::device
