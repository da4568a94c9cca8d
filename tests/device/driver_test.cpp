// The host driver against the simulated instrument: calibrated captures compared with the
// analytic f_r of each library material (evaluated here with models.h), noise statistics,
// flags, metadata, and device faults.
#include "brdf/device/driver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/virtual_capture.h"
#include "device_test_support.h"
#include "test_support.h"

namespace brdf::device {
namespace {

using testing::Config;
using testing::LibraryMaterial;
using testing::LibraryNames;
using testing::RunCapture;
using testing::Truth;

TEST(Capture, NoiseFreeMatchesTheAnalyticTruthAtEverySampleOfEveryLibraryMaterial) {
  for (const std::string& name : LibraryNames()) {
    const Material m = LibraryMaterial(name);
    SimulatedFirmware fw(Config(m, 0));
    testing::CaptureRun run;
    RunCapture(fw, &run);
    ASSERT_EQ(run.slices.size(), 4u) << name;
    std::size_t samples = 0, worst_index = 0;
    double worst = 0;
    for (const Slice& slice : run.slices) {
      EXPECT_TRUE(slice.complete);
      for (const Sample& s : slice.samples) {
        const Rgb truth = Truth(m, s);
        for (int c = 0; c < 3; ++c) {
          const double err = std::fabs(s.rgb[c] - truth[c]) / std::max(truth[c], 1e-30);
          if (err > worst) {
            worst = err;
            worst_index = samples;
          }
          EXPECT_EQ(s.sigma[c], 0.0f);
        }
        EXPECT_EQ(s.flags, 0) << name << ": an ideal detector neither clips nor has a floor";
        ++samples;
      }
    }
    EXPECT_EQ(samples, 109440u) << name;
    EXPECT_LT(worst, 1e-5) << name << ": worst relative error at sample " << worst_index;
  }
}

// Blinn-Phong and Ward (no library material uses them) against numpy written from the
// docs/design.md §9 formulas (tests/python/analytic_brdf_oracle.py), for both noise-free
// captures: the simulated instrument at noise 0 through the driver, and CaptureNoiseFree.
// Samples are stored as float32 (relative rounding ≤ 2^-24 ≈ 6e-8); the tolerance 1e-6 leaves
// room for the instrument's exposure × responsivity and back, and nothing else.
TEST(Capture, NoiseFreeBlinnPhongAndWardMatchNumpyFromTheFormulas) {
  const std::vector<Material> materials = {
      Material::Make(Model::kBlinnPhong, {{0.3, 0.2, 0.1}, {0.5, 0.4, 0.2}, {40, 40, 40}}),
      Material::Make(Model::kWard, {{0.2, 0.25, 0.3}, {0.3, 0.2, 0.1}, {0.15, 0.15, 0.15}})};
  struct Case {
    std::string what;
    Sample sample;
  };
  std::vector<Case> cases;
  const brdf::test::ScopedTempDir dir("oracle");
  const std::string input = (dir / "directions.txt").string();
  {
    std::ofstream out(input);
    out.precision(17);
    for (const Material& m : materials) {
      SimulatedFirmware fw(Config(m, 0));
      testing::CaptureRun run;
      RunCapture(fw, &run);
      ASSERT_EQ(run.slices.size(), 4u);
      const Measurement direct = CaptureNoiseFree(AnalyticBrdf(m));
      ASSERT_EQ(direct.slices.size(), 4u);
      const std::pair<const char*, const std::vector<Slice>*> captures[] = {
          {"simulator", &run.slices}, {"CaptureNoiseFree", &direct.slices}};
      for (const auto& [source, slices] : captures) {
        for (const Slice& slice : *slices) {
          // Up to 100 samples per slice: every 271st of the 27360 (all θout rows, varied φout),
          // plus the neighbourhood of the mirror direction where the lobe peaks.
          std::vector<const Sample*> picked;
          for (std::size_t i = 0; i < slice.samples.size() && picked.size() < 80; i += 271)
            picked.push_back(&slice.samples[i]);
          for (const Sample& s : slice.samples)
            if (std::fabs(s.theta_out_deg - slice.theta_in_deg) <= 2 &&
                std::fabs(s.phi_out_deg - 180) <= 2 && picked.size() < 100)
              picked.push_back(&s);
          for (const Sample* s : picked) {
            const Rgb kd = m.Parameter(0), ks = m.Parameter(1);
            out << ModelName(m.model) << ' ' << kd[0] << ' ' << kd[1] << ' ' << kd[2] << ' '
                << ks[0] << ' ' << ks[1] << ' ' << ks[2] << ' ' << m.Parameter(2)[0] << ' '
                << s->theta_in_deg << ' ' << s->phi_in_deg << ' ' << s->theta_out_deg << ' '
                << s->phi_out_deg << '\n';
            cases.push_back({std::string(ModelName(m.model)) + " " + source, *s});
          }
        }
      }
    }
  }
  ASSERT_GE(cases.size(), 2u * 2u * 4u * 95u);  // θin 0: only 15 samples near the mirror
  const std::string cmd = std::string(BRDF_PYTHON3) + " " + BRDF_SOURCE_DIR +
                          "/tests/python/analytic_brdf_oracle.py < '" + input + "'";
  const brdf::test::CommandOutput oracle = brdf::test::RunCommand(cmd);
  ASSERT_EQ(oracle.status, 0) << cmd << "\n" << oracle.out.substr(0, 500);
  // The oracle prints three numbers per input line, in order.
  std::vector<double> numbers;
  std::istringstream numbers_text(oracle.out);
  for (double x; numbers_text >> x;) numbers.push_back(x);
  ASSERT_EQ(numbers.size(), 3 * cases.size()) << "the oracle answered a different count";
  double worst = 0;
  for (std::size_t k = 0; k < numbers.size(); ++k) {
    const Case& one = cases[k / 3];
    const int c = static_cast<int>(k % 3);
    const double want = numbers[k];
    ASSERT_GT(want, 0) << one.what << ": the oracle gave no value";
    const double err = std::fabs(one.sample.rgb[c] - want) / want;
    worst = std::max(worst, err);
    EXPECT_LE(err, 1e-6) << one.what << " at θin " << one.sample.theta_in_deg << " θout "
                         << one.sample.theta_out_deg << " φout " << one.sample.phi_out_deg
                         << " channel " << c << ": " << one.sample.rgb[c] << " vs numpy " << want;
  }
  char worst_text[32];
  std::snprintf(worst_text, sizeof worst_text, "%.3g", worst);
  RecordProperty("worst_relative_error", worst_text);
}

TEST(Capture, RecordsEveryGridDirectionOnceInRowMajorOrder) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 0, 5, 10));
  testing::CaptureRun run;
  RunCapture(fw, &run, {20, 60});
  ASSERT_EQ(run.slices.size(), 2u);
  EXPECT_EQ(run.slices[1].theta_in_deg, 60.0);
  const auto& samples = run.slices[1].samples;
  ASSERT_EQ(samples.size(), 16u * 36u);  // θout 0…75 by 5, φout 0…350 by 10
  for (std::size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(samples[i].theta_in_deg, 60.0f);
    EXPECT_EQ(samples[i].phi_in_deg, 0.0f);
    EXPECT_EQ(samples[i].theta_out_deg, static_cast<float>(5 * (i / 36)));
    EXPECT_EQ(samples[i].phi_out_deg, static_cast<float>(10 * (i % 36)));
  }
}

TEST(Capture, DefaultNoiseKeepsTheMedianRelativeErrorUnderTwoPercent) {
  for (const std::string& name : LibraryNames()) {
    const Material m = LibraryMaterial(name);
    SimulatedFirmware fw(Config(m, 1));
    testing::CaptureRun run;
    RunCapture(fw, &run);
    for (const Slice& slice : run.slices) {
      for (int c = 0; c < 3; ++c) {
        double max_truth = 0;
        for (const Sample& s : slice.samples) max_truth = std::max(max_truth, Truth(m, s)[c]);
        std::vector<double> errors;
        for (const Sample& s : slice.samples) {
          const double truth = Truth(m, s)[c];
          if (truth > 0.01 * max_truth) errors.push_back(std::fabs(s.rgb[c] - truth) / truth);
        }
        ASSERT_FALSE(errors.empty());
        std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
        const double median = errors[errors.size() / 2];
        EXPECT_LT(median, 0.02) << name << " θin " << slice.theta_in_deg << " channel " << c;
        EXPECT_GT(median, 0.0) << name << ": noise is on";
      }
    }
  }
}

TEST(Capture, SigmaDescribesTheActualScatter) {
  for (const char* name : {"paper_white", "plastic_glossy_red", "gold"}) {
    const Material m = LibraryMaterial(name);
    SimulatedFirmware fw(Config(m, 1, 1, 2));
    testing::CaptureRun run;
    RunCapture(fw, &run);
    std::vector<double> z;
    for (const Slice& slice : run.slices) {
      EXPECT_TRUE(slice.has_sigma);
      for (const Sample& s : slice.samples) {
        if (s.flags != 0) continue;
        const Rgb truth = Truth(m, s);
        for (int c = 0; c < 3; ++c)
          if (s.sigma[c] > 0) z.push_back(std::fabs(s.rgb[c] - truth[c]) / s.sigma[c]);
      }
    }
    ASSERT_GT(z.size(), 10000u);
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    // For Gaussian errors the median of |error/σ| is 0.6745.
    EXPECT_NEAR(z[z.size() / 2], 0.6745, 0.1) << name;
  }
}

// Distance in representable floats (0: the same float, 1: neighbours).
std::int64_t UlpDistance(float a, float b) {
  const auto ordered = [](float x) {
    const auto bits = static_cast<std::int64_t>(std::bit_cast<std::int32_t>(x));
    return bits < 0 ? std::int64_t{INT32_MIN} - bits : bits;
  };
  return std::llabs(ordered(a) - ordered(b));
}

TEST(Capture, ValuesAndSigmasAreTheFirstOrderFormulaToTheFloat) {
  // The calibration and its uncertainty recomputed in long double from the raw readings on the
  // wire, written from the header's formula f = ρ_w/π · t_w T_w/(t_s T_s) · s/w (s = C_s − D,
  // w = C_w − D) with σf² = Σ (∂f/∂x)² var(x) over x = C_s, C_w, D taken directly:
  //   ∂f/∂C_s = k/w, ∂f/∂C_w = −k·s/w², ∂f/∂D = k·(s − w)/w²   (k = f·w/s),
  //   var C_s = (σr² + shot·max(0, s))/N, var C_w = (σr² + shot·w)/N_w, var D = σr²/N_D.
  // The driver's float values must be the exact values rounded: the same float or its
  // neighbour. Gold has bright peaks, the diamond rows read through ND filters, and black
  // plastic at a fixed 1 ms exposure has thousands of samples at and below dark.
  struct Case {
    const char* name;
    ExposureSetting exposure;
  };
  for (const Case& test_case : {Case{"gold", {}}, Case{"diamond_on_black", {}},
                                Case{"plastic_glossy_black", {ExposureMode::kFixed, 1}}}) {
    const char* name = test_case.name;
    SimulatedFirmware fw(Config(LibraryMaterial(name), 1));
    LoopbackTransport loopback(fw);
    RecordingTransport link(loopback);
    Driver driver(link);
    CapturePlan plan;
    plan.theta_in_deg = {0, 20, 40, 60};
    plan.exposure = test_case.exposure;
    std::vector<Slice> slices;
    CaptureCallbacks callbacks;
    callbacks.on_slice = [&](const Slice& slice, const SliceReport&) { slices.push_back(slice); };
    Capture(driver, plan, callbacks);
    ASSERT_EQ(slices.size(), 4u);

    const IdentityInfo& id = driver.info().identity;
    const GeometryInfo& g = driver.info().geometry;
    const DarkCalibration& dark = *driver.dark();
    const long double pi = std::acos(-1.0L);
    const std::array<double, 3> rho = DriverOptions{}.white.rho;
    FrameReader reader;
    for (const std::vector<std::uint8_t>& chunk : link.received()) reader.Append(chunk);
    std::size_t slice_index = 0, checked = 0, same_rgb = 0, same_sigma = 0, below = 0, nd = 0;
    std::int64_t worst_rgb = 0, worst_sigma = 0;
    const WhiteCalibration* white = nullptr;
    for (DecodeResult r = reader.Next(); r.status != DecodeStatus::kNeedMore; r = reader.Next()) {
      ASSERT_EQ(r.status, DecodeStatus::kComplete);
      if (r.frame.type == static_cast<std::uint8_t>(MessageType::kSliceBegin)) {
        const float theta_in = DecodeSliceBegin(r.frame.payload).theta_in_deg;
        white = nullptr;
        for (const WhiteCalibration& w : driver.whites())
          if (w.theta_in_deg == theta_in) white = &w;
        ASSERT_NE(white, nullptr) << theta_in;
      }
      if (r.frame.type == static_cast<std::uint8_t>(MessageType::kSliceEnd)) ++slice_index;
      if (r.frame.type != static_cast<std::uint8_t>(MessageType::kRowData)) continue;
      const RowData row = DecodeRowData(r.frame.payload);
      nd += row.nd_index != 0;
      const long double t_s = static_cast<long double>(row.exposure_ms) *
                              static_cast<long double>(g.nd_transmittance.at(row.nd_index));
      for (std::size_t i = 0; i < row.samples.size(); ++i) {
        const Sample& got =
            slices.at(slice_index)
                .samples.at(std::size_t{row.row} * g.columns + row.first_column + i);
        bool under_floor = false;
        for (int c = 0; c < 3; ++c) {
          const long double d = dark.mean_counts[c];
          const long double read_var = static_cast<long double>(dark.read_noise_counts[c]) *
                                       static_cast<long double>(dark.read_noise_counts[c]);
          const long double s = static_cast<long double>(row.samples[i].counts[c]) - d;
          const long double w = static_cast<long double>(white->counts[c]) - d;
          const long double k = rho[c] / pi * white->exposure_ms * white->nd_transmittance / t_s;
          const long double f = k * s / w;
          const long double df_ds = k / w, df_dw = -k * s / (w * w), df_dd = k * (s - w) / (w * w);
          const long double shot = id.shot_variance_per_count;
          const long double var_s = (read_var + shot * std::max(0.0L, s)) / id.frames_per_reading;
          const long double var_w = (read_var + shot * w) / white->frames;
          const long double var_d = read_var / dark.frames;
          const long double sigma =
              std::sqrt(df_ds * df_ds * var_s + df_dw * df_dw * var_w + df_dd * df_dd * var_d);
          const std::int64_t du = UlpDistance(got.rgb[c], static_cast<float>(f));
          const std::int64_t ds = UlpDistance(got.sigma[c], static_cast<float>(sigma));
          worst_rgb = std::max(worst_rgb, du);
          worst_sigma = std::max(worst_sigma, ds);
          same_rgb += du == 0;
          same_sigma += ds == 0;
          ++checked;
          under_floor = under_floor || s < 3 * std::sqrt(read_var / id.frames_per_reading);
        }
        EXPECT_EQ((got.flags & kFlagBelowNoiseFloor) != 0, under_floor);
        below += under_floor;
      }
    }
    EXPECT_EQ(slice_index, 4u);
    EXPECT_EQ(checked, 3u * 109440u) << name;
    EXPECT_LE(worst_rgb, 1) << name;
    EXPECT_LE(worst_sigma, 1) << name;
    std::printf(
        "%s: %zu values, rounded exactly: f %zu, sigma %zu; %zu samples under the floor, "
        "%zu row frames through an ND filter\n",
        name, checked, same_rgb, same_sigma, below, nd);
  }
}

TEST(Capture, SaturationFlagsAppearExactlyWhereTheRawSignalClipped) {
  struct Case {
    const char* material;
    ExposureSetting exposure;
  };
  // Without the ND filter stage, diamond's specular peak clips even at the shortest exposure;
  // a long fixed exposure (no ND filter) makes a glossy plastic clip over a wide area.
  for (const Case& k :
       {Case{"diamond_on_black", {}}, Case{"plastic_glossy_yellow", {ExposureMode::kFixed, 300}}}) {
    SimulatorConfig c = Config(LibraryMaterial(k.material), 1, 1, 2);
    c.model.nd_transmittance = {1.0f};
    SimulatedFirmware fw(c);
    testing::CaptureRun run;
    RunCapture(fw, &run, {0, 20, 40, 60}, k.exposure);
    const GeometryInfo& g = fw.geometry();
    std::set<std::tuple<float, std::size_t>> flagged, clipped;
    for (const Slice& slice : run.slices)
      for (std::size_t i = 0; i < slice.samples.size(); ++i)
        if (slice.samples[i].flags & kFlagSaturated)
          flagged.insert({static_cast<float>(slice.theta_in_deg), i});
    for (const ClipRecord& r : fw.clip_log())
      clipped.insert({r.theta_in_deg, std::size_t{r.row} * g.columns + r.column});
    EXPECT_FALSE(flagged.empty()) << k.material;
    EXPECT_EQ(flagged, clipped) << k.material;
  }
}

// The ND filter stage: the sharpest peak of the library (diamond) is read through a dense
// filter instead of clipping, and the host's calibration divides the filter out again: the
// noise-free capture equals the analytic f_r at the peak rows too.
TEST(Capture, NdFilterStageKeepsTheSharpestPeakUnclippedAndCalibrated) {
  const Material m = LibraryMaterial("diamond_on_black");
  for (double noise : {0.0, 1.0}) {
    SimulatedFirmware fw(Config(m, noise, 1, 2));
    testing::CaptureRun run;
    RunCapture(fw, &run);
    EXPECT_TRUE(fw.clip_log().empty()) << "noise " << noise;
    double peak = 0;
    for (const Slice& slice : run.slices)
      for (const Sample& s : slice.samples) {
        EXPECT_EQ(s.flags & kFlagSaturated, 0);
        if (noise == 0) {
          const Rgb t = testing::Truth(m, s);
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.rgb[c], t[c], 1e-5 * t[c] + 1e-30);
          peak = std::max(peak, t[1]);
        }
      }
    if (noise == 0) {
      EXPECT_GT(peak, 100.0) << "the peak needs a filter: f_r far above the white's 0.3";
    }
  }
}

TEST(Capture, IdealDetectorNeverFlagsSaturationEvenBeyondFullScale) {
  SimulatedFirmware fw(Config(LibraryMaterial("plastic_glossy_yellow"), 0, 5, 5));
  testing::CaptureRun run;
  RunCapture(fw, &run, {20}, {ExposureMode::kFixed, 300});
  const Material m = LibraryMaterial("plastic_glossy_yellow");
  for (const Sample& s : run.slices[0].samples) {
    EXPECT_EQ(s.flags & kFlagSaturated, 0);
    const Rgb truth = Truth(m, s);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.rgb[c], truth[c], 1e-5 * truth[c]);
  }
}

TEST(Capture, BelowNoiseFloorFlagsFollowTheExpectedSignal) {
  // Glass on black has no diffuse part: away from the specular lobe the signal is zero.
  const Material m = LibraryMaterial("glass_on_black");
  const InstrumentModel& model = ReferenceInstrument();
  const float exposure = 1;  // the shortest: most of the hemisphere gives well under a count
  SimulatedFirmware fw(Config(m, 1, 1, 2));
  testing::CaptureRun run;
  RunCapture(fw, &run, {20}, {ExposureMode::kFixed, exposure});
  const double reading_sigma = model.read_noise_counts / std::sqrt(model.frames_per_reading);
  const double floor = 3 * reading_sigma;
  const double cos_in = std::cos(DegToRad(20));
  std::size_t above = 0, near_zero = 0, near_zero_flagged = 0;
  for (const Sample& s : run.slices[0].samples) {
    const Rgb f = Truth(m, s);
    bool surely_above = true, some_channel_near_zero = false;
    for (int c = 0; c < 3; ++c) {
      const double signal = exposure * model.responsivity_counts_per_ms[c] * f[c] * cos_in;
      const double sigma =
          std::sqrt(reading_sigma * reading_sigma +
                    model.conversion_gain_counts_per_electron * signal / model.frames_per_reading);
      // The threshold uses the read noise measured from 64 dark frames (within ~30 %).
      surely_above = surely_above && signal > 1.3 * floor + 6 * sigma;
      some_channel_near_zero = some_channel_near_zero || signal < 0.25 * reading_sigma;
    }
    const bool flagged = (s.flags & kFlagBelowNoiseFloor) != 0;
    if (surely_above) {
      EXPECT_FALSE(flagged) << "θout " << s.theta_out_deg << " φout " << s.phi_out_deg;
      ++above;
    }
    if (some_channel_near_zero) {
      ++near_zero;
      near_zero_flagged += flagged;
    }
  }
  EXPECT_GT(above, 20u);
  EXPECT_GT(near_zero, 1000u);
  // A signal under σ/4 stays under a 3σ floor with probability ≥ 0.993, even if the measured
  // read noise came out 10 % low.
  EXPECT_GE(near_zero_flagged, near_zero * 97 / 100);
}

TEST(Capture, MetadataRecordsInstrumentCalibrationAndTimes) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1, 15, 15));
  testing::CaptureRun run;
  const Metadata md = RunCapture(fw, &run);
  const std::regex iso(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)");
  EXPECT_EQ(md.sample_name, "test sample");
  EXPECT_EQ(md.instrument_model, ReferenceInstrument().model);
  EXPECT_EQ(md.instrument_serial, "SIM-000001");
  EXPECT_EQ(md.firmware_version, ReferenceInstrument().firmware_version);
  EXPECT_EQ(md.protocol_version, "1.1");
  EXPECT_NE(md.calibration_reference.find("Spectralon"), std::string::npos);
  EXPECT_NE(md.calibration_reference.find("0.989747"), std::string::npos);
  EXPECT_TRUE(std::regex_match(md.calibration_time, iso)) << md.calibration_time;
  EXPECT_TRUE(std::regex_match(md.capture_start, iso)) << md.capture_start;
  EXPECT_TRUE(std::regex_match(md.capture_end, iso)) << md.capture_end;
  EXPECT_LE(md.capture_start, md.capture_end);
  EXPECT_EQ(md.software_version, SoftwareVersion());
  EXPECT_EQ(md.units, "1/sr");
  EXPECT_EQ(md.extra.at("exposure_mode"), "auto-row");
  EXPECT_EQ(md.extra.count("white_theta_in_60_counts"), 1u);
}

TEST(Capture, RefusesAnglesTheInstrumentDoesNotOfferBeforeMeasuring) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1, 15, 15));
  testing::CaptureRun run;
  EXPECT_THROW(RunCapture(fw, &run, {0, 30}), InvalidArgument);
  EXPECT_THROW(RunCapture(fw, &run, {20, 20}), InvalidArgument);
  EXPECT_TRUE(run.slices.empty());
}

// Frames the firmware sends before the first slice (IDENTITY, GEOMETRY, ACK, DARK, 4 WHITE)
// and per slice of 16 rows × 72 columns (SLICE_BEGIN, 16 ROW_DATA, SLICE_END).
constexpr std::uint64_t kSetupFrames = 8, kSliceFrames = 18;

TEST(Capture, DisconnectMidSliceThrowsAfterDeliveringTheCompletedSlices) {
  const Material m = LibraryMaterial("gold");
  testing::CaptureRun reference;
  SimulatedFirmware clean(Config(m, 0, 5, 5));
  RunCapture(clean, &reference);

  SimulatorConfig c = Config(m, 0, 5, 5);
  c.faults.faults.push_back({FaultType::kDisconnect, (kSetupFrames + 2 * kSliceFrames + 5) + 1});
  SimulatedFirmware fw(c);
  testing::CaptureRun run;
  try {
    RunCapture(fw, &run);
    FAIL() << "no DeviceError";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("disconnected"), std::string::npos) << e.what();
  }
  ASSERT_EQ(run.slices.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    ASSERT_EQ(run.slices[k].samples.size(), reference.slices[k].samples.size());
    for (std::size_t i = 0; i < run.slices[k].samples.size(); ++i)
      EXPECT_EQ(run.slices[k].samples[i].rgb, reference.slices[k].samples[i].rgb);
  }
}

// A damaged frame loses nothing the instrument cannot measure again: the driver aborts the
// slice, measures it again, and the capture equals an undisturbed one (the simulator reseeds
// its noise per measurement, so a repeated slice reads the same values).
TEST(Capture, CorruptFrameIsRetriedAndTheCaptureEqualsAnUndisturbedOne) {
  struct Case {
    std::uint64_t frame;
    const char* expect;
  };
  for (const Case& k : {Case{kSetupFrames + kSliceFrames + 4, "CRC-32"},  // a ROW_DATA of slice 2
                        Case{kSetupFrames + 4 * kSliceFrames, "SLICE_END"}}) {  // the final one
    SCOPED_TRACE(k.frame);
    testing::CaptureRun reference;
    SimulatedFirmware clean(Config(LibraryMaterial("gold"), 1, 5, 5));
    RunCapture(clean, &reference);

    SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 5, 5);
    c.faults.faults.push_back({FaultType::kCorrupt, k.frame});
    SimulatedFirmware fw(c);
    LoopbackTransport link(fw);
    Driver driver(link);
    CapturePlan plan;
    plan.theta_in_deg = {0, 20, 40, 60};
    std::vector<std::string> retries;
    std::vector<Slice> slices;
    CaptureCallbacks callbacks;
    callbacks.on_retry = [&](const DriverFault& e, int) { retries.push_back(e.what()); };
    callbacks.on_slice = [&](const Slice& s, const SliceReport&) { slices.push_back(s); };
    Capture(driver, plan, callbacks);
    ASSERT_EQ(retries.size(), 1u);
    EXPECT_NE(retries[0].find("CRC-32"), std::string::npos) << retries[0];
    EXPECT_NE(retries[0].find(k.expect), std::string::npos) << retries[0];
    ASSERT_EQ(slices.size(), 4u);
    for (int s = 0; s < 4; ++s)
      for (std::size_t i = 0; i < slices[s].samples.size(); ++i)
        ASSERT_EQ(slices[s].samples[i].rgb, reference.slices[s].samples[i].rgb);
  }
}

// DriverOptions::retries bounds the attempts of one step: a step damaged `retries` times in a row
// is still measured (after exactly that many retries), one damaged once more stops the capture
// with the damage. The frame of each attempt is found from the firmware's own frame count: an
// attempt that fails at frame F costs D frames more than the undisturbed capture, so the same
// frame of the next attempt is F + D.
TEST(Capture, AStepIsRetriedExactlyUpToTheRetryLimit) {
  const std::uint64_t first = kSetupFrames + kSliceFrames + 4;  // a ROW_DATA of slice 2
  auto run = [&](const std::vector<std::uint64_t>& corrupt, int retries_allowed,
                 std::vector<int>* attempts, std::uint64_t* frames) {
    SimulatorConfig c = Config(LibraryMaterial("gold"), 0, 5, 5);
    for (std::uint64_t f : corrupt) c.faults.faults.push_back({FaultType::kCorrupt, f});
    SimulatedFirmware fw(c);
    LoopbackTransport link(fw);
    DriverOptions options;
    options.retries = retries_allowed;
    Driver driver(link, options);
    CapturePlan plan;
    plan.theta_in_deg = {0, 20, 40, 60};
    CaptureCallbacks callbacks;
    std::size_t slices = 0;
    callbacks.on_retry = [&](const DriverFault&, int attempt) { attempts->push_back(attempt); };
    callbacks.on_slice = [&](const Slice&, const SliceReport&) { ++slices; };
    try {
      Capture(driver, plan, callbacks);
    } catch (...) {
      *frames = fw.frames_sent();
      throw;
    }
    *frames = fw.frames_sent();
    return slices;
  };
  std::vector<int> attempts;
  std::uint64_t clean_frames = 0, one_retry_frames = 0;
  ASSERT_EQ(run({}, 2, &attempts, &clean_frames), 4u);
  ASSERT_EQ(run({first}, 2, &attempts, &one_retry_frames), 4u);
  ASSERT_EQ(attempts, std::vector<int>{1});
  const std::uint64_t d = one_retry_frames - clean_frames;
  ASSERT_GT(d, 4u);
  for (int limit : {0, 1, 2, 4}) {
    SCOPED_TRACE("retries " + std::to_string(limit));
    std::vector<std::uint64_t> faults;
    for (int k = 0; k < limit; ++k) faults.push_back(first + static_cast<std::uint64_t>(k) * d);
    // `limit` damaged attempts in a row: measured, after exactly `limit` retries.
    attempts.clear();
    std::uint64_t frames = 0;
    EXPECT_EQ(run(faults, limit, &attempts, &frames), 4u);
    std::vector<int> want;
    for (int k = 1; k <= limit; ++k) want.push_back(k);
    EXPECT_EQ(attempts, want);
    EXPECT_EQ(frames, clean_frames + static_cast<std::uint64_t>(limit) * d);
    // One more: the capture stops with the damage, having tried limit + 1 times.
    faults.push_back(first + static_cast<std::uint64_t>(limit) * d);
    attempts.clear();
    try {
      run(faults, limit, &attempts, &frames);
      ADD_FAILURE() << limit + 1 << " damaged attempts in a row did not stop the capture";
    } catch (const DriverFault& e) {
      // The damaged frame is named (the driver may report it as the frame the sequence lost).
      EXPECT_TRUE(e.retryable()) << e.what();
      EXPECT_NE(std::string(e.what()).find("CRC-32"), std::string::npos) << e.what();
    }
    EXPECT_EQ(attempts, want);
  }
}

TEST(Capture, InstrumentThatStopsAnsweringStopsTheCapture) {
  SimulatorConfig c = Config(LibraryMaterial("gold"), 1, 5, 5);
  c.faults.faults.push_back({FaultType::kStall, (kSetupFrames + kSliceFrames + 1) + 1});
  SimulatedFirmware fw(c);
  testing::CaptureRun run;
  try {
    RunCapture(fw, &run);
    FAIL() << "no DeviceError";
  } catch (const DriverFault& e) {
    EXPECT_EQ(e.kind(), FaultKind::kNotAnswering);
    EXPECT_NE(std::string(e.what()).find("stopped answering"), std::string::npos) << e.what();
  }
  EXPECT_EQ(run.slices.size(), 1u);
}

TEST(Driver, NeedsCalibrationBeforeASliceAndAbortsWhenIdle) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1, 15, 15));
  LoopbackTransport link(fw);
  Driver driver(link);
  driver.Connect();
  EXPECT_THROW(driver.MeasureSlice(20), InvalidArgument);
  driver.MeasureDark();
  EXPECT_THROW(driver.MeasureSlice(20), InvalidArgument);
  driver.MeasureWhite(20);
  SliceReport report;
  const Slice s = driver.MeasureSlice(20, &report);
  EXPECT_EQ(report.samples, s.samples.size());
  EXPECT_EQ(report.theta_in_deg, 20.0);
  driver.Abort();
  EXPECT_EQ(driver.MeasureSlice(20).samples.size(), s.samples.size());
}

TEST(Driver, ReportsTheInstrumentsRefusal) {
  SimulatedFirmware fw(Config(LibraryMaterial("paper_white"), 1, 15, 15));
  LoopbackTransport link(fw);
  Driver driver(link);
  driver.Connect();
  try {
    driver.SetExposure({ExposureMode::kFixed, 1e5f});
    FAIL() << "no DeviceError";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("refused SET_EXPOSURE"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace brdf::device
