// The host side of the scatterometer: drives an instrument over a Transport and turns its raw
// detector counts into calibrated f_r.
//
// A capture runs identify → dark → white reference at every θin → one slice per θin
// (Capture() below does all of it). Calibration follows a real lab's: for channel c,
//   f_r = (C_s − D)/t_s ÷ ((C_w − D)/t_w) · ρ_w/π
// with C_s the sample's reading at exposure t_s, C_w the white panel's reading at the same θin
// and exposure t_w, D the dark reading, and ρ_w the panel's certificate reflectance
// (white_reference.h). The panel is Lambertian, so its radiance ρ_w/π · cosθi carries the same
// cosθi as the sample's f_r · cosθi and the ratio is f_r itself, never multiplied by cosθ.
//
// Each sample's sigma is the one-standard-deviation uncertainty from the detector noise of
// the three readings (sample, white, dark), propagated to first order with the noise model the
// instrument reports (read noise measured from the dark frames, shot noise from IDENTIFY). It
// does not include the certificate's uncertainty of ρ_w, which scales a whole capture and is
// recorded in the metadata instead. Values are not clamped: a sample under the noise floor may
// be slightly negative, and is flagged.
//
// Flags: kFlagSaturated where the instrument reports that a frame of the reading clipped at
// full scale; kFlagBelowNoiseFloor where the signal above dark, C_s − D, is below
// noise_floor_sigmas × the read noise of a reading (σ_read/√frames) in any channel.
//
// Faults throw DriverFault (a brdf::DeviceError) saying which kind of fault it was, so the
// caller can tell what is safe to retry: a timeout, a damaged frame or a frame out of sequence
// loses nothing the instrument cannot measure again, so Capture() aborts the scan and measures
// that step again (up to DriverOptions::retries times); a disconnect, an instrument that stops
// answering, or an error the instrument reports (lamp, sample contact, temperature) stops the
// capture. A frame received twice (a duplicated transfer: same type, sequence number, length
// and CRC-32) is dropped. Capture() hands every completed slice to its callback before it
// returns or throws, so an interrupted capture loses only the slice in progress, which is
// never handed out.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/measurement.h"
#include "brdf/device/protocol.h"
#include "brdf/device/transport.h"
#include "brdf/device/white_reference.h"

namespace brdf::device {

class CancelSignal;

// Largest slice the driver accepts from an instrument (a slice is held in memory while it
// streams): 2^22 samples, room for 0.1° steps over the whole hemisphere.
inline constexpr std::size_t kMaxSamplesPerSlice = std::size_t{1} << 22;

enum class FaultKind {
  kDisconnected,     // the link is gone (unplugged, powered off)
  kTimeout,          // no reply within timeout_ms (retryable)
  kDamagedFrame,     // a frame failed its CRC (retryable)
  kOutOfSequence,    // a frame was lost, or came out of order (retryable)
  kNotAnswering,     // the instrument does not answer even ABORT
  kInstrumentError,  // the instrument refused a request (error_code says why)
  kProtocol,         // a reply that does not follow the protocol
  kCancelled,        // the host cancelled (the scan was aborted on the instrument)
};

class DriverFault : public DeviceError {
 public:
  DriverFault(FaultKind kind, const std::string& message, ErrorCode code = ErrorCode{0})
      : DeviceError(message), kind_(kind), code_(code) {}
  FaultKind kind() const { return kind_; }
  // kInstrumentError only: the instrument's error code.
  ErrorCode error_code() const { return code_; }
  bool retryable() const {
    return kind_ == FaultKind::kTimeout || kind_ == FaultKind::kDamagedFrame ||
           kind_ == FaultKind::kOutOfSequence;
  }

 private:
  FaultKind kind_;
  ErrorCode code_;
};

struct InstrumentInfo {
  IdentityInfo identity;
  GeometryInfo geometry;
};

struct DarkCalibration {
  std::array<double, 3> mean_counts{};
  std::array<double, 3> read_noise_counts{};  // σ of one frame
  int frames = 0;
  std::string time;  // ISO 8601 UTC
};

struct WhiteCalibration {
  double theta_in_deg = 0;
  double exposure_ms = 0;
  double nd_transmittance = 1;     // the ND filter the panel was read through (1 = open)
  std::array<double, 3> counts{};  // dark not subtracted
  int frames = 0;
  std::string time;  // ISO 8601 UTC
};

struct SliceReport {
  double theta_in_deg = 0;
  std::size_t samples = 0;
  std::size_t saturated = 0;
  std::size_t below_noise_floor = 0;
  double seconds = 0;  // wall-clock time of the slice
};

struct DriverOptions {
  // Longest wait for a byte once a reply or stream frame is due. Real instruments need the
  // longest exposure (2 s) plus readout; the loopback answers at once.
  int timeout_ms = 5000;
  double noise_floor_sigmas = 3.0;
  WhiteReference white = SpectralonWhiteReference();
  // How often Capture() measures a step again after a retryable fault before giving up.
  int retries = 2;
};

class Driver {
 public:
  // `transport` must outlive the driver.
  explicit Driver(Transport& transport, DriverOptions options = {});
  ~Driver();  // takes its cancel back from the transport
  Driver(const Driver&) = delete;
  Driver& operator=(const Driver&) = delete;

  // IDENTIFY and GET_GEOMETRY. Throws DeviceError for an instrument speaking another major
  // protocol version.
  const InstrumentInfo& Connect();
  const InstrumentInfo& info() const { return info_; }
  const DriverOptions& options() const { return options_; }

  // Exposure policy for the following slices (the white reference always auto-ranges).
  void SetExposure(const ExposureSetting& setting);
  // Shutter closed: the dark signal and the read noise per channel.
  const DarkCalibration& MeasureDark();
  // White reference in place at incidence θin (one of the instrument's θin).
  const WhiteCalibration& MeasureWhite(double theta_in_deg);
  // Streams one slice and calibrates it. Needs Connect, MeasureDark and MeasureWhite(θin)
  // first (InvalidArgument otherwise, and for a θin the instrument does not offer).
  Slice MeasureSlice(double theta_in_deg, SliceReport* report = nullptr);
  // Stops a slice stream and waits for the acknowledgement.
  void Abort();
  // After a retryable fault: aborts whatever the instrument is doing, discards what is in
  // flight and resynchronises on the ABORT acknowledgement. Throws DriverFault kNotAnswering
  // when the instrument does not acknowledge.
  void Recover();

  // Uses dark and white readings measured earlier (a resumed capture keeps its file's
  // references) instead of measuring them. Needs Connect first.
  void RestoreCalibration(const DarkCalibration& dark, std::vector<WhiteCalibration> whites);
  const DarkCalibration* dark() const { return have_dark_ ? &dark_ : nullptr; }
  const std::vector<WhiteCalibration>& whites() const { return whites_; }

  // The cancel (cancel.h), also handed to the transport (Transport::SetCancel) so that a read
  // waiting for the instrument ends early. Looked at before every frame of a slice and whenever
  // a read returns with nothing: once it is raised the scan is aborted on the instrument (ABORT,
  // and its acknowledgement awaited) and the step throws DriverFault kCancelled. Null disables.
  // `cancel` must outlive the driver's use of it.
  void SetCancelFlag(const CancelSignal* cancel);
  bool cancelled() const;
  // Frames dropped as exact duplicates of the previous one.
  std::size_t duplicates_dropped() const { return duplicates_dropped_; }

  // Instrument and calibration fields of the metadata (model, serial, firmware and protocol
  // versions, calibration reference and time, software version, and the raw calibration
  // readings under `extra`).
  Metadata CalibrationMetadata() const;

 private:
  void Send(MessageType type, const std::vector<std::uint8_t>& payload);
  Frame NextFrame(std::string_view waiting_for, bool check_sequence = true);
  [[noreturn]] void Fail(FaultKind kind, const std::string& what) const;
  Frame Expect(MessageType request, MessageType reply);
  [[noreturn]] void ThrowInstrumentError(const Frame& frame, MessageType request) const;
  const WhiteCalibration* FindWhite(double theta_in_deg) const;
  class AbortScope;  // while ABORT's acknowledgement is awaited (driver.cpp)

  Transport& transport_;
  DriverOptions options_;
  FrameReader reader_;
  std::uint8_t host_sequence_ = 0;
  bool have_device_sequence_ = false;
  std::uint8_t device_sequence_ = 0;
  std::uint8_t last_frame_type_ = 0;  // the last frame, to recognise a duplicate of it
  std::uint32_t last_frame_crc_ = 0;
  std::size_t last_frame_size_ = 0;
  std::size_t duplicates_dropped_ = 0;
  const CancelSignal* cancel_ = nullptr;
  bool aborting_ = false;    // in Abort or Recover: a cancel is not acted on twice
  std::string last_damage_;  // first damaged frame since the last good one, to explain a loss
  bool connected_ = false;
  InstrumentInfo info_;
  ExposureSetting exposure_;
  bool have_dark_ = false;
  DarkCalibration dark_;
  std::vector<WhiteCalibration> whites_;
};

struct CapturePlan {
  std::vector<double> theta_in_deg;  // slices to capture, in this order
  ExposureSetting exposure;
  // Sample name, operator notes and anything in `extra` are copied into the metadata; the
  // driver fills the instrument, calibration and time fields.
  Metadata metadata;
};

struct CaptureCallbacks {
  // After IDENTIFY and GET_GEOMETRY, before anything is measured; may throw to refuse the
  // instrument (nothing has been measured yet).
  std::function<void(const InstrumentInfo&)> on_connected;
  // Return true when the callback restored the calibration (Driver::RestoreCalibration), so
  // Capture() does not measure dark and white references. Called after on_connected.
  std::function<bool(Driver&)> restore_calibration;
  // A retryable fault occurred and the step is measured again.
  std::function<void(const DriverFault&, int attempt)> on_retry;
  // Once, after the calibration and before the first slice: the metadata a file header carries
  // (capture_end still empty).
  std::function<void(const Metadata&)> on_calibrated;
  // As each slice completes, in capture order. The slice is handed over: the callback may move
  // from it (a callback taking `const Slice&` works too).
  std::function<void(Slice&&, const SliceReport&)> on_slice;
};

// The whole capture: Connect, SetExposure, MeasureDark, MeasureWhite for every θin of the plan,
// then MeasureSlice for each; every step is measured again after a retryable fault (Recover
// first), up to DriverOptions::retries times. Returns the final metadata (capture_end set).
// Throws DriverFault on a fault that cannot be retried (or that persists), after every
// completed slice went to on_slice; InvalidArgument for a plan the instrument cannot do
// (checked before anything is measured).
Metadata Capture(Driver& driver, const CapturePlan& plan, const CaptureCallbacks& callbacks);

}  // namespace brdf::device
