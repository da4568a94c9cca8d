// Runs the fuzz entry (fuzz/protocol_fuzzer.cpp) on inputs generated here: random bytes, valid
// streams of every message with random damage, and forged headers with extreme fields.
// Passing means no crash, hang or escape of a non-brdf exception, and, for the driver fed those
// bytes directly: the valid stream gives the slice it encodes, a damaged copy either that same
// slice or a brdf::Error (never other values: every frame carries a CRC-32), random bytes never
// a slice, and a forged geometry too large to hold is refused at Connect, before any allocation.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <span>
#include <string>

#include "brdf/core/error.h"
#include "brdf/device/driver.h"
#include "brdf/device/protocol.h"
#include "brdf/device/transport.h"
#include "replay_transport.h"  // fuzz/: the fuzz entry's hostile instrument

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace brdf::device {
namespace {

using fuzz::ReplayTransport;

// The driver through one slice on `bytes`: the slice, or nothing after a brdf::Error (its
// message in *error).
std::optional<Slice> DriveOneSlice(const std::vector<std::uint8_t>& bytes, std::string* error) {
  ReplayTransport link(bytes);
  DriverOptions options;
  options.timeout_ms = 1;
  Driver driver(link, options);
  try {
    return fuzz::MeasureOneSlice(driver);
  } catch (const Error& e) {
    *error = e.what();
    return std::nullopt;
  }
}

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
  // The valid stream itself drives the driver through a whole slice: 3 rows × 4 columns at
  // θin 20°, every sample's channels in the ratio of their dark-subtracted counts against one
  // white level, (1000 − 500) : (2000 − 500) : (3000 − 500) = 1 : 3 : 5 (within 0.5 %: the
  // white panel's reflectance differs a little per channel).
  EXPECT_EQ(LLVMFuzzerTestOneInput(valid.data(), valid.size()), 0);
  std::string error;
  const std::optional<Slice> reference = DriveOneSlice(valid, &error);
  ASSERT_TRUE(reference.has_value()) << error;
  ASSERT_EQ(reference->samples.size(), 12u);
  for (const Sample& x : reference->samples) {
    EXPECT_FLOAT_EQ(x.theta_in_deg, 20);
    ASSERT_GT(x.rgb[0], 0);
    EXPECT_NEAR(x.rgb[1] / x.rgb[0], 3.0, 0.015);
    EXPECT_NEAR(x.rgb[2] / x.rgb[0], 5.0, 0.025);
  }
  // Bytes after the slice's last frame change nothing the driver reads.
  {
    std::vector<std::uint8_t> longer = valid;
    for (int k = 0; k < 50; ++k) longer.push_back(static_cast<std::uint8_t>(rng()));
    const std::optional<Slice> same = DriveOneSlice(longer, &error);
    ASSERT_TRUE(same.has_value()) << error;
    ASSERT_EQ(same->samples.size(), reference->samples.size());
    for (std::size_t k = 0; k < same->samples.size(); ++k)
      EXPECT_EQ(same->samples[k].rgb, reference->samples[k].rgb);
  }
  int damaged_refused = 0;
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
    error.clear();
    const std::optional<Slice> got = DriveOneSlice(input, &error);
    if (i % 3 == 0) {
      EXPECT_FALSE(got.has_value()) << "random bytes gave a slice (input " << i << ")";
    } else if (i % 3 == 1) {
      if (!got) {
        ++damaged_refused;
        EXPECT_FALSE(error.empty());
        continue;
      }
      // Accepted only where the damage missed what the slice needs (the cut after SLICE_END,
      // a changed byte between frames that the reader skipped): then it is the same slice.
      ASSERT_EQ(got->samples.size(), reference->samples.size()) << "input " << i;
      for (std::size_t k = 0; k < got->samples.size(); ++k)
        ASSERT_EQ(got->samples[k].rgb, reference->samples[k].rgb) << "input " << i;
    }
  }
  // Damage is refused (almost every copy is cut short of SLICE_END, or has a frame whose CRC
  // fails).
  EXPECT_GT(damaged_refused, 900);
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
  // 65535² samples would need ~170 GB; the driver must refuse the geometry instead, at Connect
  // (checked first: without the refusal the fuzz entry below dies of the allocation).
  ReplayTransport link(s);
  Driver driver(link, DriverOptions{});
  try {
    driver.Connect();
    ADD_FAILURE() << "a geometry of 65535 × 65535 samples per slice was accepted";
  } catch (const DriverFault& e) {
    EXPECT_EQ(e.kind(), FaultKind::kProtocol);
    EXPECT_NE(std::string(e.what()).find("65535 × 65535"), std::string::npos) << e.what();
  }
  EXPECT_EQ(LLVMFuzzerTestOneInput(s.data(), s.size()), 0);
}

}  // namespace
}  // namespace brdf::device
