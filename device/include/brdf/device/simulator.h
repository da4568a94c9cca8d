// The simulated scatterometer: firmware that measures a virtual sample and speaks the real
// wire protocol (protocol.h) behind a transport.
//
// The simulator is the instrument, not a shortcut around it: the host driver talks to it
// through LoopbackTransport exactly as it would talk to hardware, and receives raw detector
// counts that it must calibrate itself. The virtual sample is any brdf::BrdfSource: an
// analytic material or a measured one (a MERL or RGL file).
//
// Detector model, per channel c, for one ADC frame of exposure t (ms):
//   counts = t · R_c · L_c + D_c + shot noise + read noise, clipped to [0, full scale]
//   L_c = f_r,c(ωi, ωo) · cosθi        (radiance of the sample under unit irradiance)
//   shot noise: Gaussian, variance g · (t · R_c · L_c)   (g: conversion gain, counts/electron)
//   read noise: Gaussian, standard deviation σ_read
// R_c is the channel's responsivity and D_c its dark signal (bias). A reading is the mean of
// frames_per_reading frames, sent as float32, so it is not quantised to whole counts.
//
// The noise level s scales every detector imperfection: shot and read noise by s and the
// dark signal by s. s = 1 is the reference instrument; s = 0 is an ideal detector with no
// noise, no dark signal and no clipping, whose readings are exactly t · R_c · L_c in float32
// (the noise-free, unsaturated signal tests compare with the analytic truth). The dark signal
// is scaled too because a float32 reading of D_c + (a tiny signal) cannot hold the tiny signal
// to float precision; an ideal detector has no bias.
//
// Exposure is auto-ranged per θout row (default): the firmware finds the row's brightest
// sample with a probe exposure (simulated as the noise-free maximum of the row) and sets t so
// it reaches `autorange_target_fraction` of the range above dark, within
// [min_exposure_ms, max_exposure_ms]. A row too bright even at the shortest exposure is read
// through the neutral-density filter stage (nd_transmittance: the least attenuating filter
// that lets the exposure reach its target within the range; PROTOCOL.md, ND filters). The
// white reference is always ranged this way. A peak too bright even at the shortest exposure
// behind the densest filter clips, and the sample carries clip bits per channel. Noise
// is drawn from a seeded generator restarted for every measurement from (seed, what is measured,
// θin), so a slice is reproduced exactly whatever was measured before it (a resumed capture matches
// an uninterrupted one).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/virtual_capture.h"
#include "brdf/device/protocol.h"

namespace brdf::device {

// Constants of one instrument model: geometry and detector. Table data (InstrumentModels()),
// so a new model is a new row, not new code.
struct InstrumentModel {
  std::string model;                // reported by IDENTIFY
  std::string firmware_version;     // reported by IDENTIFY
  std::vector<float> theta_in_deg;  // incidence angles the light arm can be set to
  float theta_out_max_deg = 75;
  float theta_out_step_deg = 1;
  float phi_out_step_deg = 1;

  double adc_full_scale_counts = 65535;            // one frame clips here
  int frames_per_reading = 16;                     // frames averaged per sample
  int dark_frames = 64;                            // frames averaged by MEASURE_DARK
  int white_frames = 64;                           // frames averaged by MEASURE_WHITE
  std::array<double, 3> dark_offset_counts{};      // D_c at noise level 1
  double read_noise_counts = 0;                    // σ_read per frame at noise level 1
  double conversion_gain_counts_per_electron = 0;  // g
  // R_c: counts per ms per unit radiance (f_r · cosθi under unit irradiance).
  std::array<double, 3> responsivity_counts_per_ms{};
  double min_exposure_ms = 1;
  // The ND filter wheel: transmittance of each position, [0] = open (1.0), then denser.
  std::vector<float> nd_transmittance = {1.0f, 0.1f, 0.01f, 0.001f};
  double max_exposure_ms = 2000;
  double autorange_target_fraction = 0.8;  // of (full scale − dark)

  // Sets the light-arm positions and detector steps to `geometry`'s, in float32 as the
  // instrument reports them (GET_GEOMETRY). Not validated here: the firmware refuses what it
  // cannot do.
  void SetGeometry(const CaptureGeometry& geometry);
};

// Every known model; the first is the reference instrument of docs/design.md §1 (MiniDiff V2 class:
// θin ∈ {0, 20, 40, 60}°, θout 0–75°, φout 0–359° at 1°).
std::span<const InstrumentModel> InstrumentModels();
const InstrumentModel& ReferenceInstrument();
// Throws InvalidArgument listing the known names.
const InstrumentModel& FindInstrumentModel(std::string_view model);

// Faults to inject, for tests of the host's error handling and for demos. Frames are counted
// from 1 in the order the firmware sends them (retransmissions included).
enum class FaultType {
  kDisconnect,       // the link drops instead of sending frame N (unplugged cable)
  kStall,            // the firmware stops answering before frame N, for good
  kTimeout,          // frame N is not sent and the firmware hangs until it receives ABORT
  kCorrupt,          // frame N is sent with one payload bit flipped (CRC mismatch)
  kDuplicate,        // frame N is sent twice
  kReorder,          // frames N and N+1 are sent in swapped order
  kLampFailure,      // instead of frame N: ERROR lamp failure, and the scan stops
  kSampleContact,    // instead of frame N: ERROR sample not in contact, and the scan stops
  kOverTemperature,  // instead of frame N: ERROR over-temperature, and the scan stops
  kEndpointHalt,     // transport level: the Nth bulk/interrupt IN transfer stalls (USB, HID)
  // Frame N is not sent and the firmware is silent until it receives ABORT, as kTimeout, but
  // announced (SimulatorConfig::on_hold) and, on the loopback, read as "still waiting" for as
  // long as the session is not cancelled (transport.h): the deterministic way for a test to
  // interrupt a capture at a chosen frame, with no race against real time.
  kHold,
};

struct Fault {
  FaultType type = FaultType::kCorrupt;
  std::uint64_t at = 0;  // frame number N (kEndpointHalt: IN transfer number N), ≥ 1
  // When set (a firmware fault only): N counts the frames of the first slice stream at this θin
  // instead (its SLICE_BEGIN is frame 1), so the fault lands at the same place in the capture
  // however often earlier steps were measured again (a retry after a frame the host lost sends
  // frames of its own, which shift every later frame number). The instrument errors (lamp,
  // contact, over-temperature) then apply to every stream at that θin: the state persists.
  std::optional<float> in_slice_theta_in_deg;
};

struct FaultPlan {
  std::vector<Fault> faults;  // every one applies; several of one type are fine
  bool empty() const { return faults.empty(); }
  bool Has(FaultType type, std::uint64_t at) const;
  // Firmware faults only (everything but kEndpointHalt).
  bool HasFirmwareFaults() const;
};

// "disconnect:50,corrupt:30" → the plan. Names: disconnect, stall, timeout, corrupt, duplicate,
// reorder, lamp, contact, overtemp, halt, hold. Throws InvalidArgument naming the item and what was
// expected.
FaultPlan ParseFaultPlan(std::string_view spec);

struct SimulatorConfig {
  InstrumentModel model = ReferenceInstrument();  // copy: adjust the geometry freely
  std::string serial = "SIM-000001";
  std::shared_ptr<const BrdfSource> sample;  // the virtual sample under the head (required)
  // The white reference panel MEASURE_WHITE sees; null means a Lambertian with the
  // Spectralon reflectance of white_reference.h (the panel the host calibrates against).
  std::shared_ptr<const BrdfSource> white_reference;
  double noise_level = 1.0;  // s above: 1 = reference instrument, 0 = ideal detector
  std::uint64_t seed = 1;
  FaultPlan faults;
  // Real time the firmware spends per θout row (sleeping), for demos and for tests that must
  // interrupt a capture while it runs; 0 = as fast as the host reads (virtual time).
  double pace_ms_per_row = 0;
  // Testing: called when a FaultType::kHold begins (with the frame number held back) and when
  // the ABORT that ends it arrives, on the thread that runs the firmware (the caller's over
  // the loopback, umockdev's behind emulated USB). A test raises the session's cancel from
  // on_hold, or tells the process it will signal that the hold point is reached.
  std::function<void(std::uint64_t frame)> on_hold;
  std::function<void()> on_hold_released;
};

// One raw reading that clipped, for tests only: real firmware reports clipping through the
// clip bits of its messages and nothing else.
struct ClipRecord {
  float theta_in_deg = 0;
  // θout row and φout column of the sample; 0xFFFF for both in a white reference reading.
  std::uint16_t row = 0, column = 0;
  std::uint8_t channels = 0;  // bit c: channel c clipped
};

class SimulatedFirmware {
 public:
  // Throws InvalidArgument for an unusable configuration (no sample, bad geometry, negative
  // noise level).
  explicit SimulatedFirmware(SimulatorConfig config);

  // Bytes arriving from the host. Throws DeviceError once the link is down.
  void Receive(std::span<const std::uint8_t> bytes);
  // Copies up to out.size() bytes waiting to go to the host into `out`, producing the next
  // frame of a slice stream when nothing else is waiting. Returns 0 when the firmware has
  // nothing to say (idle, stalled, or the link is down).
  std::size_t Transmit(std::span<std::uint8_t> out);

  bool link_up() const { return link_up_; }
  // A FaultType::kHold is in force: nothing is sent until ABORT.
  bool held() const { return held_; }
  // Nothing more will be sent before ABORT (kTimeout, kHold) or ever (kStall).
  bool silent() const { return hung_ || stalled_; }
  std::uint64_t frames_sent() const { return frames_sent_; }
  const GeometryInfo& geometry() const { return geometry_; }
  const SimulatorConfig& config() const { return config_; }
  const std::vector<ClipRecord>& clip_log() const { return clip_log_; }

 private:
  struct Reading {
    std::array<float, 3> counts{};
    std::uint8_t clipped = 0;
  };

  void Handle(const Frame& frame);
  void Send(MessageType type, const std::vector<std::uint8_t>& payload);
  void SendError(ErrorCode code, std::uint8_t request_type, const std::string& message);
  bool FindThetaIn(float theta_in_deg) const;
  void StartSlice(float theta_in_deg);
  void ProduceStreamFrame();
  void PrepareRow(std::size_t row);
  // Radiance L_c of the sample seen from (row, column) under the slice's light.
  std::array<double, 3> RowRates(std::size_t row, std::vector<std::array<double, 3>>* rates) const;
  struct Exposure {
    float ms = 0;
    std::uint8_t nd = 0;  // ND filter position
  };
  Exposure AutoExposure(double brightest_rate) const;
  Reading Read(const std::array<double, 3>& rate, Exposure exposure, int frames);
  void Reseed(std::uint64_t what, float theta_in_deg);

  SimulatorConfig config_;
  GeometryInfo geometry_;
  std::shared_ptr<const BrdfSource> white_;
  FrameReader input_;
  std::vector<std::uint8_t> output_;  // bytes waiting for the host, from output_start_ on
  std::size_t output_start_ = 0;
  std::uint64_t frames_sent_ = 0;
  std::uint8_t sequence_ = 0;
  bool link_up_ = true;
  bool stalled_ = false;
  bool hung_ = false;                     // kTimeout, kHold: silent until ABORT
  bool held_ = false;                     // kHold
  std::uint64_t stream_frame_ = 0;        // frames of the slice stream, SLICE_BEGIN = 1
  std::vector<bool> slice_fault_fired_;   // per fault: a slice-relative fault fires once
  std::vector<std::uint8_t> held_frame_;  // kReorder: frame N, sent after frame N+1
  ExposureSetting exposure_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
  std::vector<ClipRecord> clip_log_;

  // The slice being streamed.
  bool streaming_ = false;
  float slice_theta_in_deg_ = 0;
  Vec3 light_{};
  Exposure slice_exposure_;  // kAutoPerSlice / kFixed
  std::size_t next_row_ = 0, next_column_ = 0;
  std::vector<Reading> row_readings_;
  // cos φ and sin φ of every detector column, so a row costs two trig calls, not four per
  // sample (the same products as SphericalDirectionDeg, so the same bits).
  std::vector<double> column_cos_phi_, column_sin_phi_;
  Exposure row_exposure_;
  std::uint32_t slice_samples_ = 0, slice_clipped_ = 0;
};

// What defines a capture with the simulator besides the instrument: the settings such a capture
// records (CaptureRequest::settings) and a resume requires unchanged, written the same way by
// every host (`brdf capture --device sim`, the Python module's brdf.capture), so a capture one
// of them started can be resumed by the other. `device` is the instrument spec ("sim"),
// `material` the virtual sample's name, `exposure` the exposure as the user gave it ("auto",
// "auto-slice" or milliseconds); numbers are written "%g".
std::map<std::string, std::string> SimulatedCaptureSettings(const std::string& device,
                                                            const std::string& material,
                                                            const SimulatorConfig& config,
                                                            const CaptureGeometry& geometry,
                                                            const std::string& exposure);

}  // namespace brdf::device
