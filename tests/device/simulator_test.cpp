// The simulated firmware seen from the wire: a raw host in this file sends frames through the
// loopback and checks the replies against the detector model computed independently here.
#include "brdf/device/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <set>
#include <tuple>

#include "brdf/core/error.h"
#include "brdf/device/transport.h"
#include "device_test_support.h"

namespace brdf::device {
namespace {

using testing::Config;
using testing::LibraryMaterial;

// Speaks the protocol by hand, without the driver under test.
class RawHost {
 public:
  explicit RawHost(SimulatedFirmware& firmware) : link_(firmware) {}

  void Send(std::uint8_t type, std::vector<std::uint8_t> payload = {}) {
    link_.Write(EncodeFrame({type, sequence_++, std::move(payload)}));
  }
  void Send(MessageType type, std::vector<std::uint8_t> payload = {}) {
    Send(static_cast<std::uint8_t>(type), std::move(payload));
  }

  // The next intact frame, or nothing when the instrument has nothing to send.
  std::optional<Frame> Next() {
    for (;;) {
      DecodeResult r = reader_.Next();
      if (r.status == DecodeStatus::kComplete) return std::move(r.frame);
      if (r.status == DecodeStatus::kInvalid) {
        invalid.push_back(r);
        continue;
      }
      std::uint8_t buf[512];
      const std::size_t n = link_.Read(buf, 0);
      if (n == 0) return std::nullopt;
      reader_.Append(std::span<const std::uint8_t>(buf, n));
    }
  }

  Frame Expect(MessageType type) {
    std::optional<Frame> f = Next();
    EXPECT_TRUE(f.has_value());
    if (!f) return {};
    EXPECT_EQ(f->type, static_cast<std::uint8_t>(type)) << "got " << MessageTypeName(f->type);
    return *f;
  }

  struct Streamed {
    std::vector<RowData> rows;
    SliceEnd end;
  };
  Streamed MeasureSlice(float theta_in_deg) {
    Send(MessageType::kMeasureSlice, EncodeThetaIn(theta_in_deg));
    Expect(MessageType::kSliceBegin);
    Streamed s;
    for (;;) {
      std::optional<Frame> f = Next();
      if (!f) {
        ADD_FAILURE() << "stream ended without SLICE_END";
        return s;
      }
      if (f->type == static_cast<std::uint8_t>(MessageType::kSliceEnd)) {
        s.end = DecodeSliceEnd(f->payload);
        return s;
      }
      s.rows.push_back(DecodeRowData(f->payload));
    }
  }

  std::vector<DecodeResult> invalid;

 private:
  LoopbackTransport link_;
  FrameReader reader_;
  std::uint8_t sequence_ = 0;
};

TEST(SimulatedFirmware, ReportsTheReferenceInstrumentGeometry) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1));
  RawHost host(fw);
  host.Send(MessageType::kIdentify);
  const IdentityInfo id = DecodeIdentity(host.Expect(MessageType::kIdentity).payload);
  EXPECT_EQ(id.model, ReferenceInstrument().model);
  EXPECT_EQ(id.protocol_major, kProtocolMajor);
  host.Send(MessageType::kGetGeometry);
  const GeometryInfo g = DecodeGeometry(host.Expect(MessageType::kGeometry).payload);
  // docs/design.md §1: θin ∈ {0, 20, 40, 60}°, θout 0–75° and φout 0–359° at 1°.
  EXPECT_EQ(g.theta_in_deg, (std::vector<float>{0, 20, 40, 60}));
  EXPECT_EQ(g.rows, 76);
  EXPECT_EQ(g.columns, 360);
  EXPECT_EQ(std::size_t{4} * g.rows * g.columns, 109440u);
}

// Expected noise-free counts t · R_c · f_r,c · cosθi of the detector model in simulator.h.
std::array<double, 3> ExpectedSignal(const Material& m, double exposure_ms, float theta_in,
                                     float theta_out, float phi_out) {
  const Vec3 l = SphericalDirectionDeg(theta_in, 0);
  const Rgb f = m.Evaluate(l, SphericalDirectionDeg(theta_out, phi_out));
  const auto& resp = ReferenceInstrument().responsivity_counts_per_ms;
  return {exposure_ms * resp[0] * f[0] * l.z, exposure_ms * resp[1] * f[1] * l.z,
          exposure_ms * resp[2] * f[2] * l.z};
}

TEST(SimulatedFirmware, NoiseFreeReadingsAreExposureTimesResponsivityTimesRadiance) {
  const Material gold = LibraryMaterial("gold");
  SimulatedFirmware fw(Config(gold, 0, 5, 5));
  RawHost host(fw);
  host.Send(MessageType::kSetExposure, EncodeExposure({ExposureMode::kFixed, 10}));
  host.Expect(MessageType::kAck);
  const auto slice = host.MeasureSlice(40);
  const GeometryInfo& g = fw.geometry();
  std::size_t checked = 0;
  for (const RowData& row : slice.rows) {
    EXPECT_EQ(row.exposure_ms, 10.0f);
    for (std::size_t i = 0; i < row.samples.size(); ++i) {
      const auto expected =
          ExpectedSignal(gold, 10, 40, g.ThetaOutDeg(row.row), g.PhiOutDeg(row.first_column + i));
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(row.samples[i].counts[c], expected[c], 1e-6 * expected[c]);
      EXPECT_EQ(row.samples[i].clipped_channels, 0);  // an ideal detector does not clip
      ++checked;
    }
  }
  EXPECT_EQ(checked, std::size_t{g.rows} * g.columns);
  EXPECT_EQ(slice.end.samples, checked);
}

TEST(SimulatedFirmware, AutoRangePutsEachRowPeakAtTheTargetLevel) {
  const InstrumentModel& m = ReferenceInstrument();
  for (const char* name : {"paper_white", "plastic_glossy_red", "silver"}) {
    SimulatedFirmware fw(Config(LibraryMaterial(name), 0, 5, 5));
    RawHost host(fw);
    const auto slice = host.MeasureSlice(20);
    for (const RowData& row : slice.rows) {
      double peak = 0;
      for (const RowSample& s : row.samples)
        for (float v : s.counts) peak = std::max<double>(peak, v);
      const double target = m.autorange_target_fraction * m.adc_full_scale_counts;
      if (row.exposure_ms > m.min_exposure_ms && row.exposure_ms < m.max_exposure_ms)
        EXPECT_NEAR(peak, target, 1e-5 * target) << name << " row " << row.row;
      else if (row.exposure_ms == static_cast<float>(m.min_exposure_ms))
        EXPECT_GE(peak, target * (1 - 1e-6)) << name << " row " << row.row;
      else
        EXPECT_LE(peak, target * (1 + 1e-6)) << name << " row " << row.row;
    }
  }
}

TEST(SimulatedFirmware, ClipBitsMarkReadingsBeyondFullScaleAndOnlyThose) {
  const Material m = LibraryMaterial("plastic_glossy_red");
  const InstrumentModel& model = ReferenceInstrument();
  SimulatedFirmware fw(Config(m, 1, 5, 2));
  RawHost host(fw);
  // Long fixed exposure: the specular lobe and the red diffuse part overflow, the rest not.
  const float exposure = 400;
  host.Send(MessageType::kSetExposure, EncodeExposure({ExposureMode::kFixed, exposure}));
  host.Expect(MessageType::kAck);
  const auto slice = host.MeasureSlice(20);
  const GeometryInfo& g = fw.geometry();
  std::set<std::tuple<int, int>> flagged;
  std::size_t must = 0, must_not = 0;
  for (const RowData& row : slice.rows) {
    for (std::size_t i = 0; i < row.samples.size(); ++i) {
      const std::size_t col = row.first_column + i;
      const auto signal = ExpectedSignal(m, exposure, 20, g.ThetaOutDeg(row.row), g.PhiOutDeg(col));
      const RowSample& s = row.samples[i];
      if (s.clipped_channels) flagged.insert({row.row, static_cast<int>(col)});
      for (int c = 0; c < 3; ++c) {
        const double mean = signal[c] + model.dark_offset_counts[c];
        const double sigma = std::sqrt(model.read_noise_counts * model.read_noise_counts +
                                       model.conversion_gain_counts_per_electron * signal[c]);
        const bool clipped = (s.clipped_channels >> c) & 1;
        if (mean > model.adc_full_scale_counts + 6 * sigma) {
          EXPECT_TRUE(clipped) << "row " << row.row << " col " << col << " ch " << c;
          EXPECT_LE(s.counts[c], model.adc_full_scale_counts);
          ++must;
        } else if (mean < model.adc_full_scale_counts - 6 * sigma) {
          EXPECT_FALSE(clipped) << "row " << row.row << " col " << col << " ch " << c;
          ++must_not;
        }
      }
    }
  }
  EXPECT_GT(must, 100u);
  EXPECT_GT(must_not, 100u);
  EXPECT_EQ(slice.end.clipped_samples, flagged.size());
  std::set<std::tuple<int, int>> logged;
  for (const ClipRecord& r : fw.clip_log()) logged.insert({r.row, r.column});
  EXPECT_EQ(logged, flagged);
}

TEST(SimulatedFirmware, DarkReadingScalesWithTheNoiseLevel) {
  const InstrumentModel& model = ReferenceInstrument();
  for (double noise : {0.0, 1.0, 2.0}) {
    SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), noise));
    RawHost host(fw);
    host.Send(MessageType::kMeasureDark);
    const DarkReading d = DecodeDark(host.Expect(MessageType::kDark).payload);
    EXPECT_EQ(d.frames, model.dark_frames);
    for (int c = 0; c < 3; ++c) {
      const double sigma = noise * model.read_noise_counts;
      // The mean of 64 frames is within 5 standard errors; the sample σ within 30 %.
      EXPECT_NEAR(d.mean_counts[c], noise * model.dark_offset_counts[c], 5 * sigma / 8 + 1e-9);
      EXPECT_NEAR(d.read_noise_counts[c], sigma, 0.3 * sigma + 1e-9);
    }
  }
}

TEST(SimulatedFirmware, SliceNoiseDependsOnSeedAndAngleNotOnHistory) {
  const Material m = LibraryMaterial("wood_oak");
  auto counts_of = [&](std::uint64_t seed, bool measure_others_first) {
    SimulatedFirmware fw(Config(m, 1, 15, 15, seed));
    RawHost host(fw);
    if (measure_others_first) {
      host.Send(MessageType::kMeasureDark);
      host.Expect(MessageType::kDark);
      host.MeasureSlice(0);
    }
    std::vector<float> out;
    for (const RowData& r : host.MeasureSlice(40).rows)
      for (const RowSample& s : r.samples) out.insert(out.end(), s.counts.begin(), s.counts.end());
    return out;
  };
  const auto a = counts_of(7, false);
  EXPECT_EQ(a, counts_of(7, true));
  EXPECT_NE(a, counts_of(8, false));
}

TEST(SimulatedFirmware, RefusesUnknownCommandsBadAnglesAndRequestsWhileStreaming) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1, 5, 5));
  RawHost host(fw);
  host.Send(std::uint8_t{0x55});
  EXPECT_EQ(DecodeError(host.Expect(MessageType::kError).payload).code, ErrorCode::kUnknownCommand);
  host.Send(MessageType::kMeasureSlice, EncodeThetaIn(33));
  EXPECT_EQ(DecodeError(host.Expect(MessageType::kError).payload).code, ErrorCode::kBadArgument);
  host.Send(MessageType::kMeasureWhite, {1, 2});  // payload too short for θin
  EXPECT_EQ(DecodeError(host.Expect(MessageType::kError).payload).code, ErrorCode::kBadPayload);
  host.Send(MessageType::kSetExposure, EncodeExposure({ExposureMode::kFixed, 1e6f}));
  EXPECT_EQ(DecodeError(host.Expect(MessageType::kError).payload).code, ErrorCode::kBadArgument);

  host.Send(MessageType::kMeasureSlice, EncodeThetaIn(20));
  host.Expect(MessageType::kSliceBegin);
  host.Expect(MessageType::kRowData);
  host.Send(MessageType::kIdentify);
  // Busy reply after whatever row data was already produced.
  std::optional<Frame> f;
  while ((f = host.Next()) && f->type == static_cast<std::uint8_t>(MessageType::kRowData)) {
  }
  ASSERT_TRUE(f);
  ASSERT_EQ(f->type, static_cast<std::uint8_t>(MessageType::kError));
  EXPECT_EQ(DecodeError(f->payload).code, ErrorCode::kBusy);
  host.Send(MessageType::kAbort);
  const Frame ack = host.Expect(MessageType::kAck);
  EXPECT_EQ(DecodeAck(ack.payload), static_cast<std::uint8_t>(MessageType::kAbort));
  EXPECT_FALSE(host.Next().has_value()) << "nothing streams after the abort";
  host.Send(MessageType::kIdentify);
  host.Expect(MessageType::kIdentity);
}

TEST(SimulatedFirmware, AnswersADamagedRequestWithBadFrame) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1));
  LoopbackTransport link(fw);
  auto bytes = EncodeFrame({static_cast<std::uint8_t>(MessageType::kIdentify), 0, {}});
  bytes.back() ^= 1;
  link.Write(bytes);
  RawHost host(fw);
  EXPECT_EQ(DecodeError(host.Expect(MessageType::kError).payload).code, ErrorCode::kBadFrame);
}

TEST(SimulatedFirmware, InjectedDisconnectDeliversTheFramesBeforeIt) {
  SimulatorConfig c = Config(LibraryMaterial("paper_white"), 1, 5, 5);
  c.faults.faults.push_back({FaultType::kDisconnect, (3) + 1});
  SimulatedFirmware fw(c);
  RawHost host(fw);
  host.Send(MessageType::kMeasureSlice, EncodeThetaIn(0));
  host.Expect(MessageType::kSliceBegin);
  host.Expect(MessageType::kRowData);
  host.Expect(MessageType::kRowData);
  EXPECT_THROW(host.Next(), DeviceError);
  EXPECT_FALSE(fw.link_up());
  EXPECT_THROW(host.Send(MessageType::kIdentify), DeviceError);
}

TEST(SimulatedFirmware, InjectedStallGoesSilent) {
  SimulatorConfig c = Config(LibraryMaterial("paper_white"), 1, 5, 5);
  c.faults.faults.push_back({FaultType::kStall, (1) + 1});
  SimulatedFirmware fw(c);
  RawHost host(fw);
  host.Send(MessageType::kIdentify);
  host.Expect(MessageType::kIdentity);
  host.Send(MessageType::kIdentify);
  EXPECT_FALSE(host.Next().has_value());
  EXPECT_TRUE(fw.link_up());
}

TEST(SimulatedFirmware, InjectedCorruptionFailsTheFrameCrc) {
  SimulatorConfig c = Config(LibraryMaterial("paper_white"), 1, 5, 5);
  c.faults.faults.push_back({FaultType::kCorrupt, 2});
  SimulatedFirmware fw(c);
  RawHost host(fw);
  host.Send(MessageType::kIdentify);
  host.Expect(MessageType::kIdentity);
  host.Send(MessageType::kGetGeometry);
  EXPECT_FALSE(host.Next().has_value());
  ASSERT_FALSE(host.invalid.empty());
  bool crc = false;
  for (const auto& r : host.invalid)
    crc = crc || (r.corrupt && r.reason.find("CRC") != std::string::npos);
  EXPECT_TRUE(crc);
}

TEST(SimulatedFirmware, RejectsUnusableConfigurations) {
  SimulatorConfig c = Config(LibraryMaterial("paper_white"), 1);
  c.sample.reset();
  EXPECT_THROW(SimulatedFirmware{c}, InvalidArgument);
  c = Config(LibraryMaterial("paper_white"), -1);
  EXPECT_THROW(SimulatedFirmware{c}, InvalidArgument);
  c = Config(LibraryMaterial("paper_white"), 1, 0);
  EXPECT_THROW(SimulatedFirmware{c}, InvalidArgument);
  c = Config(LibraryMaterial("paper_white"), 1);
  c.model.theta_in_deg = {95};
  EXPECT_THROW(SimulatedFirmware{c}, InvalidArgument);
}

}  // namespace
}  // namespace brdf::device
