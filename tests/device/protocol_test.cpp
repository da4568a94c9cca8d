// The wire protocol codec: frame layout against a hand-built frame, round trips, partial
// frames, resynchronisation after garbage and damaged frames, payload codecs.
#include "brdf/device/protocol.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "brdf/core/error.h"

namespace brdf::device {
namespace {

// Bit-at-a-time CRC-32 (reflected 0xEDB88320, init and final xor 0xFFFFFFFF), written here
// independently of brdf::Crc32.
std::uint32_t ReferenceCrc32(const std::uint8_t* data, std::size_t n) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

std::vector<std::uint8_t> Bytes(std::initializer_list<int> values) {
  std::vector<std::uint8_t> out;
  for (int v : values) out.push_back(static_cast<std::uint8_t>(v));
  return out;
}

std::vector<std::uint8_t> MakeFrame(MessageType type, std::uint8_t seq,
                                    std::vector<std::uint8_t> payload) {
  return EncodeFrame({static_cast<std::uint8_t>(type), seq, std::move(payload)});
}

TEST(FrameCodec, WritesTheDocumentedByteLayout) {
  const auto payload = Bytes({0x10, 0x20, 0x30});
  const auto frame = MakeFrame(MessageType::kMeasureSlice, 0x2A, payload);
  // Hand-built per the table in protocol.h.
  std::vector<std::uint8_t> expected =
      Bytes({0xB7, 0xDF, 0x06, 0x2A, 0x03, 0x00, 0x10, 0x20, 0x30});
  const std::uint32_t crc = ReferenceCrc32(expected.data() + 2, expected.size() - 2);
  for (int i = 0; i < 4; ++i) expected.push_back(static_cast<std::uint8_t>(crc >> (8 * i)));
  EXPECT_EQ(frame, expected);
}

TEST(FrameCodec, RoundTripsEveryPayloadSizeClass) {
  for (std::size_t size : {std::size_t{0}, std::size_t{1}, std::size_t{63}, std::size_t{64},
                           std::size_t{1000}, kMaxPayloadBytes}) {
    std::vector<std::uint8_t> payload(size);
    for (std::size_t i = 0; i < size; ++i) payload[i] = static_cast<std::uint8_t>(i * 7 + 3);
    const auto bytes = MakeFrame(MessageType::kRowData, 200, payload);
    ASSERT_EQ(bytes.size(), size + kFrameHeaderBytes + kFrameCrcBytes);
    const DecodeResult r = DecodeFrame(bytes);
    ASSERT_EQ(r.status, DecodeStatus::kComplete) << size;
    EXPECT_EQ(r.consumed, bytes.size());
    EXPECT_EQ(r.frame.type, static_cast<std::uint8_t>(MessageType::kRowData));
    EXPECT_EQ(r.frame.sequence, 200);
    EXPECT_EQ(r.frame.payload, payload);
  }
}

TEST(FrameCodec, RefusesToEncodeAnOversizedPayload) {
  std::vector<std::uint8_t> payload(kMaxPayloadBytes + 1);
  EXPECT_THROW(MakeFrame(MessageType::kRowData, 0, payload), InvalidArgument);
}

TEST(FrameCodec, EveryStrictPrefixNeedsMoreBytes) {
  const auto bytes = MakeFrame(MessageType::kIdentity, 5, Bytes({1, 2, 3, 4, 5, 6, 7}));
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const DecodeResult r = DecodeFrame(std::span(bytes.data(), n));
    EXPECT_EQ(r.status, DecodeStatus::kNeedMore) << "prefix of " << n << " bytes";
    EXPECT_EQ(r.consumed, 0u);
  }
}

TEST(FrameCodec, SkipsGarbageUpToTheNextSyncByte) {
  std::vector<std::uint8_t> bytes = Bytes({0x00, 0x11, 0xB7, 0x22, 0x33});
  const auto frame = MakeFrame(MessageType::kAck, 1, Bytes({0x03}));
  bytes.insert(bytes.end(), frame.begin(), frame.end());
  DecodeResult r = DecodeFrame(bytes);
  ASSERT_EQ(r.status, DecodeStatus::kInvalid);
  EXPECT_EQ(r.consumed, 2u);  // up to the 0xB7
  EXPECT_FALSE(r.corrupt);
  r = DecodeFrame(std::span(bytes).subspan(2));
  ASSERT_EQ(r.status, DecodeStatus::kInvalid);  // 0xB7 not followed by 0xDF
  EXPECT_EQ(r.consumed, 3u);
  r = DecodeFrame(std::span(bytes).subspan(5));
  ASSERT_EQ(r.status, DecodeStatus::kComplete);
  EXPECT_EQ(r.frame.payload, Bytes({0x03}));
}

TEST(FrameCodec, ReportsACrcMismatchWithBothValues) {
  auto bytes = MakeFrame(MessageType::kDark, 9, Bytes({1, 2, 3, 4}));
  const std::uint32_t good = ReferenceCrc32(bytes.data() + 2, bytes.size() - 6);
  bytes[7] ^= 0x01;
  const std::uint32_t recomputed = ReferenceCrc32(bytes.data() + 2, bytes.size() - 6);
  const DecodeResult r = DecodeFrame(bytes);
  ASSERT_EQ(r.status, DecodeStatus::kInvalid);
  EXPECT_TRUE(r.corrupt);
  EXPECT_EQ(r.consumed, 1u);
  char expected[64];
  std::snprintf(expected, sizeof expected, "expected 0x%08x, got 0x%08x", recomputed, good);
  EXPECT_NE(r.reason.find("CRC-32"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find(expected), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("DARK"), std::string::npos) << r.reason;
}

TEST(FrameCodec, RejectsALengthAboveTheLimitWithoutWaitingForIt) {
  const auto bytes = Bytes({0xB7, 0xDF, 0x87, 0x00, 0x01, 0x10});  // 0x1001 = 4097
  const DecodeResult r = DecodeFrame(bytes);
  ASSERT_EQ(r.status, DecodeStatus::kInvalid);
  EXPECT_EQ(r.consumed, 1u);
  EXPECT_NE(r.reason.find("4097"), std::string::npos) << r.reason;
}

TEST(FrameReader, FindsFramesInAnyChunkingAfterGarbageAndDamage) {
  std::mt19937 rng(7);
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<std::uint8_t> stream;
  // Leading noise that contains false sync pairs.
  for (int i = 0; i < 50; ++i) stream.push_back(static_cast<std::uint8_t>(rng()));
  stream.push_back(0xB7);
  stream.push_back(0xDF);
  stream.push_back(0x01);
  for (int k = 0; k < 20; ++k) {
    std::vector<std::uint8_t> p(rng() % 300);
    for (auto& b : p) b = static_cast<std::uint8_t>(rng());
    auto f = MakeFrame(MessageType::kRowData, static_cast<std::uint8_t>(k), p);
    if (k == 7) {
      f[f.size() / 2] ^= 0x40;  // damaged: must be reported, not delivered
    } else {
      payloads.push_back(p);
    }
    stream.insert(stream.end(), f.begin(), f.end());
    if (k % 5 == 0)
      for (int i = 0; i < 9; ++i) stream.push_back(static_cast<std::uint8_t>(rng()));
  }
  for (std::size_t chunk : {std::size_t{1}, std::size_t{63}, std::size_t{64}, std::size_t{4096}}) {
    FrameReader reader;
    std::vector<std::vector<std::uint8_t>> got;
    int damaged = 0;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      reader.Append(std::span(stream).subspan(at, std::min(chunk, stream.size() - at)));
      for (;;) {
        DecodeResult r = reader.Next();
        if (r.status == DecodeStatus::kNeedMore) break;
        if (r.status == DecodeStatus::kComplete) got.push_back(r.frame.payload);
        if (r.status == DecodeStatus::kInvalid && r.corrupt) ++damaged;
      }
      EXPECT_LE(reader.buffered(), kMaxFrameBytes + chunk);
    }
    // The noise may contain a false frame start whose CRC fails, so at least the one damaged
    // frame is reported; every intact frame arrives, in order.
    EXPECT_GE(damaged, 1) << chunk;
    EXPECT_EQ(got, payloads) << "chunk " << chunk;
  }
}

TEST(Messages, RoundTripEveryPayload) {
  IdentityInfo id{"BRDF-SIM MD2", "SN-42", "2.4.1", 1, 3, 65535.f, 16, 2.5f};
  const IdentityInfo id2 = DecodeIdentity(EncodeIdentity(id));
  EXPECT_EQ(id2.model, id.model);
  EXPECT_EQ(id2.serial, id.serial);
  EXPECT_EQ(id2.firmware_version, id.firmware_version);
  EXPECT_EQ(id2.protocol_minor, 3);
  EXPECT_EQ(id2.frames_per_reading, 16);
  EXPECT_EQ(id2.shot_variance_per_count, 2.5f);

  GeometryInfo g{{0, 20, 40, 60}, 75, 1, 1, 76, 360};
  const GeometryInfo g2 = DecodeGeometry(EncodeGeometry(g));
  EXPECT_EQ(g2.theta_in_deg, g.theta_in_deg);
  EXPECT_EQ(g2.rows, 76);
  EXPECT_EQ(g2.columns, 360);
  EXPECT_EQ(g2.ThetaOutDeg(75), 75.0f);
  EXPECT_EQ(g2.PhiOutDeg(359), 359.0f);

  const ExposureSetting e = DecodeExposure(EncodeExposure({ExposureMode::kFixed, 12.5f}));
  EXPECT_EQ(e.mode, ExposureMode::kFixed);
  EXPECT_EQ(e.exposure_ms, 12.5f);

  RowData row;
  row.row = 17;
  row.first_column = 180;
  row.exposure_ms = 3.25f;
  for (std::size_t i = 0; i < kMaxSamplesPerRowFrame; ++i)
    row.samples.push_back({{float(i), float(i) + 0.5f, 1e-30f}, static_cast<std::uint8_t>(i % 8)});
  const auto payload = EncodeRowData(row);
  EXPECT_LE(payload.size(), kMaxPayloadBytes);
  const RowData row2 = DecodeRowData(payload);
  EXPECT_EQ(row2.row, 17);
  EXPECT_EQ(row2.first_column, 180);
  EXPECT_EQ(row2.exposure_ms, 3.25f);
  ASSERT_EQ(row2.samples.size(), row.samples.size());
  for (std::size_t i = 0; i < row.samples.size(); ++i) {
    EXPECT_EQ(row2.samples[i].counts, row.samples[i].counts);
    EXPECT_EQ(row2.samples[i].clipped_channels, row.samples[i].clipped_channels);
  }

  const ErrorReply err = DecodeError(EncodeError({ErrorCode::kBusy, 0x06, "busy streaming"}));
  EXPECT_EQ(err.code, ErrorCode::kBusy);
  EXPECT_EQ(err.request_type, 0x06);
  EXPECT_EQ(err.message, "busy streaming");

  const SliceEnd end = DecodeSliceEnd(EncodeSliceEnd({40, 27360, 3}));
  EXPECT_EQ(end.theta_in_deg, 40.0f);
  EXPECT_EQ(end.samples, 27360u);
  EXPECT_EQ(end.clipped_samples, 3u);
}

TEST(Messages, TruncatedPayloadIsADeviceErrorNamingTheField) {
  RowData row;
  row.samples.resize(3);
  auto payload = EncodeRowData(row);
  payload.resize(payload.size() - 2);
  try {
    DecodeRowData(payload);
    FAIL() << "no error";
  } catch (const DeviceError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("ROW_DATA payload"), std::string::npos) << msg;
    EXPECT_NE(msg.find("sample"), std::string::npos) << msg;
  }
  EXPECT_THROW(DecodeIdentity(Bytes({5, 'a'})), DeviceError);
  EXPECT_THROW(DecodeExposure(Bytes({9, 0, 0, 0, 0})), DeviceError);  // unknown mode
}

TEST(Messages, RowDataRefusesMoreSamplesThanAFrameCarries) {
  RowData row;
  row.samples.resize(kMaxSamplesPerRowFrame + 1);
  EXPECT_THROW(EncodeRowData(row), InvalidArgument);
  // A forged count above the limit is refused before anything is allocated for it.
  auto payload = Bytes({0, 0, 0, 0, 0xFF, 0xFF, 0, 0, 0, 0});
  EXPECT_THROW(DecodeRowData(payload), DeviceError);
}

}  // namespace
}  // namespace brdf::device
