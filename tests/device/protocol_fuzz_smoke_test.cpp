// Runs the fuzz entry (fuzz/protocol_fuzzer.cpp) on inputs generated here: random bytes, valid
// streams of every message with random damage, and forged headers with extreme fields.
// Passing means no crash, hang or escape of a non-brdf exception.
#include <gtest/gtest.h>

#include <random>

#include "brdf/device/protocol.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace brdf::device {
namespace {

std::vector<std::uint8_t> ValidReplyStream() {
  std::vector<std::uint8_t> s;
  std::uint8_t seq = 0;
  auto add = [&](MessageType t, const std::vector<std::uint8_t>& p) {
    AppendFrame(s, static_cast<std::uint8_t>(t), seq++, p);
  };
  add(MessageType::kIdentity, EncodeIdentity({"M", "S", "F", 1, 0, 65535, 16, 2}));
  add(MessageType::kGeometry, EncodeGeometry({{20}, 10, 5, 90, 3, 4}));
  add(MessageType::kAck, EncodeAck(static_cast<std::uint8_t>(MessageType::kSetExposure)));
  add(MessageType::kDark, EncodeDark({{500, 500, 500}, {6, 6, 6}, 64}));
  add(MessageType::kWhite, EncodeWhite({20, 80, {50000, 50000, 50000}, 0, 64}));
  add(MessageType::kSliceBegin, EncodeSliceBegin({20, 3, 4}));
  for (std::uint16_t row = 0; row < 3; ++row) {
    RowData r;
    r.row = row;
    r.exposure_ms = 10;
    r.samples.assign(4, RowSample{{1000, 2000, 3000}, 0});
    add(MessageType::kRowData, EncodeRowData(r));
  }
  add(MessageType::kSliceEnd, EncodeSliceEnd({20, 12, 0}));
  return s;
}

TEST(ProtocolFuzzSmoke, HostileBytesNeverCrashTheParsers) {
  std::mt19937 rng(1234);
  const std::vector<std::uint8_t> valid = ValidReplyStream();
  // The valid stream itself drives the driver through a whole slice.
  EXPECT_EQ(LLVMFuzzerTestOneInput(valid.data(), valid.size()), 0);
  for (int i = 0; i < 3000; ++i) {
    std::vector<std::uint8_t> input;
    switch (i % 3) {
      case 0:  // random bytes, sometimes with sync pairs
        input.resize(rng() % 600);
        for (auto& b : input) b = static_cast<std::uint8_t>(rng() % 4 == 0 ? 0xB7 : rng());
        break;
      case 1:  // the valid stream with a few bytes changed, cut at a random length
        input = valid;
        for (int k = 0; k < 1 + static_cast<int>(rng() % 4); ++k)
          input[rng() % input.size()] = static_cast<std::uint8_t>(rng());
        input.resize(rng() % (input.size() + 1));
        break;
      default: {  // a correctly framed message of random type with a random payload
        std::vector<std::uint8_t> payload(rng() % 64);
        for (auto& b : payload) b = static_cast<std::uint8_t>(rng());
        input = valid;
        input.resize(rng() % input.size());
        AppendFrame(input, static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng()),
                    payload);
        break;
      }
    }
    ASSERT_EQ(LLVMFuzzerTestOneInput(input.data(), input.size()), 0);
  }
}

TEST(ProtocolFuzzSmoke, ForgedHugeGeometryIsRefusedNotAllocated) {
  std::vector<std::uint8_t> s;
  AppendFrame(s, static_cast<std::uint8_t>(MessageType::kIdentity), 0,
              EncodeIdentity({"M", "S", "F", 1, 0, 65535, 16, 2}));
  AppendFrame(s, static_cast<std::uint8_t>(MessageType::kGeometry), 1,
              EncodeGeometry({{0}, 89, 0.01f, 0.01f, 65535, 65535}));
  AppendFrame(s, static_cast<std::uint8_t>(MessageType::kAck), 2,
              EncodeAck(static_cast<std::uint8_t>(MessageType::kSetExposure)));
  AppendFrame(s, static_cast<std::uint8_t>(MessageType::kDark), 3,
              EncodeDark({{500, 500, 500}, {6, 6, 6}, 64}));
  AppendFrame(s, static_cast<std::uint8_t>(MessageType::kWhite), 4,
              EncodeWhite({0, 80, {50000, 50000, 50000}, 0, 64}));
  AppendFrame(s, static_cast<std::uint8_t>(MessageType::kSliceBegin), 5,
              EncodeSliceBegin({0, 65535, 65535}));
  // 65535² samples would need ~170 GB; the driver must refuse the geometry instead.
  EXPECT_EQ(LLVMFuzzerTestOneInput(s.data(), s.size()), 0);
}

}  // namespace
}  // namespace brdf::device
