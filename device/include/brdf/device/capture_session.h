// A capture session: one `brdf capture` run as a library call.
//
// The session owns everything between "the user asked for a capture into FILE.bpc" and "the
// file is finished or safely interrupted": the rule for an existing file, resuming an
// interrupted capture (re-identifying the instrument, keeping the complete slices, measuring
// the rest), calibration, appending each completed slice durably, the metadata merge of a
// resumed file, cancellation, and the summary counts. The tool only parses options, opens the
// instrument's transport, calls RunCaptureSession and prints what comes back.
//
// Outcomes a user can act on (a fault, a refusal, an interruption) are returned as values with
// a NextStep the tool renders in its own words; exceptions are left for arguments no capture
// can run with (InvalidArgument), unreadable files (IoError) and program faults.
//
// Resume guarantee: a capture interrupted at any point (fault, unplug, signal) and resumed
// with the same settings equals the uninterrupted capture value for value. On the simulated
// instrument this holds because its noise is reseeded per measurement; on a real one because
// a resumed capture by default calibrates against the dark and white readings recorded in the
// file (CaptureRequest::calibrate measures fresh ones instead).
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/measurement.h"
#include "brdf/device/cancel.h"
#include "brdf/device/driver.h"
#include "brdf/device/transport.h"

namespace brdf::device {

struct CaptureRequest {
  std::string out_path;  // the capture file; must end in .bpc
  // The planned slices, in capture order. The session records the plan in the header before
  // the first slice (extra "theta_in_deg", brdf::EncodeThetaInList of brdf/core/virtual_capture.h),
  // so that an interrupted capture missing slices can be told from a complete one; a resumption
  // must plan the same list, since the header on disk is not rewritten.
  std::vector<double> theta_in_deg;
  ExposureSetting exposure;
  std::string sample_name;
  std::string operator_notes;
  // What defines the capture besides the instrument (simulated material, seed, noise level,
  // requested geometry…): recorded in the header's `extra` map and, on resume, required to
  // equal what the file recorded. "theta_in_deg" (the plan) is added by the session.
  std::map<std::string, std::string> settings;
  // Recorded in `extra` but not compared on resume (e.g. the material file's path).
  std::map<std::string, std::string> notes;
  // Continue the interrupted capture in out_path (a missing file starts a new capture).
  bool resume = false;
  // Without resume: overwrite an existing out_path. With resume: accept an instrument whose
  // serial number or geometry differs from the one the file was started with.
  bool force = false;
  // With resume: measure new dark and white references instead of reusing the file's. A new
  // capture always measures them.
  bool calibrate = false;
  DriverOptions driver;
  // With resume: the rule every reading command applies to a capture's values (NaN, negative
  // or absurd f_r, a slice without a valid sample: brdf::sources::AssessCapture, a layer above
  // this library). Called with out_path before anything is measured, it returns the sentence
  // saying why a reader refuses the slices on disk, or nothing. Such a file is not resumed
  // (kRefused, NextStep::kRepairSlices) whether finished or not: measuring the missing slices
  // would still leave a capture no command reads; `brdf repair` drops the refused slices, and a
  // resume of the repaired file measures them again. Unset: not checked.
  std::function<std::optional<std::string>(const std::string& path)> saved_values_refusal;
};

enum class CaptureOutcome {
  kFinished,         // the file is complete (new or resumed)
  kNothingToResume,  // resume of a file that is already finished: nothing was done
  kRefused,          // nothing was measured: the file or instrument is not what the request says
  kInterrupted,      // cancelled (signal): the scan was aborted on the instrument
  kFailed,           // an instrument or link fault stopped the capture
};

// What the user should do next, for the tool to put in its own words.
enum class NextStep {
  kNone,
  kResume,               // completed slices are saved: run the same capture again, resuming
  kRetry,                // nothing was saved: check the instrument, run the capture again
  kOverwrite,            // the file cannot be resumed: start over, overwriting it deliberately
  kAcceptInstrument,     // a different instrument: connect the original or accept this one
  kUseOriginalSettings,  // resume with other settings than the file records
  kRepairSlices          // saved slices hold values no reader accepts: repair drops them, then
                         // a resume of the repaired file measures them again
};

// Instrument states the firmware reports with an error code; each has its own remedy.
enum class InstrumentProblem {
  kNone,
  kLampFailure,         // the light source failed: replace or reseat the lamp
  kSampleNotInContact,  // the sample is not seated on the measurement port
  kOverTemperature,     // the detector is too warm: let it cool
};

struct SessionStart {
  bool resuming = false;
  std::size_t slices_done = 0;  // already in the file
  std::size_t slices_planned = 0;
  std::vector<double> pending_theta_in_deg;
  // Temporary files of killed runs removed from the capture's folder (CheckWritableOutput).
  std::vector<std::string> removed_temporaries;
};

struct SliceProgress {
  SliceReport report;
  std::size_t index = 0;  // 1-based position in the plan
  std::size_t planned = 0;
  double eta_seconds = 0;  // for the slices still to measure, from the mean so far
};

struct SessionEvents {
  std::function<void(const SessionStart&)> on_start;
  // The instrument answered IDENTIFY: model, serial, geometry.
  std::function<void(const InstrumentInfo&)> on_connected;
  // Dark and white references are ready (measured, or taken from the file on resume).
  std::function<void(const Metadata& header, bool measured)> on_calibrated;
  // A slice is in the file and flushed to disk. Called from the session's writer thread (one
  // call at a time, in capture order), possibly while on_retry runs on the caller's thread.
  std::function<void(const SliceProgress&)> on_slice;
  // A recoverable fault; the driver is retrying (message says what and which attempt).
  std::function<void(const std::string& message)> on_retry;
};

struct CaptureSessionResult {
  CaptureOutcome outcome = CaptureOutcome::kFailed;
  NextStep next = NextStep::kNone;
  InstrumentProblem problem = InstrumentProblem::kNone;
  std::string message;  // what happened, for kRefused, kInterrupted and kFailed
  bool resumed = false;
  std::size_t slices_planned = 0;
  std::size_t slices_saved = 0;  // in the file now
  std::size_t new_samples = 0, saturated = 0, below_noise_floor = 0;
  std::size_t retries = 0;
};

// Runs the capture of `request` on the instrument behind `link`. `cancel` (may be null) stops
// the capture: once it is raised the scan is aborted on the instrument (ABORT, acknowledged)
// and the result is kInterrupted with the completed slices saved. How soon: the driver looks
// at the cancel before each slice, before each frame of a slice, and whenever a read returns
// with nothing while a reply is awaited; a read waiting for a silent instrument ends within
// kCancelStepMs (50 ms, usb_transport.h) on USB and HID and at once on the loopback
// (Transport::SetCancel). So a cancel is acted on within one read timeout
// (DriverOptions::timeout_ms) at most, however the instrument behaves; then the acknowledgement
// of ABORT is awaited for up to one more timeout (an instrument that never acknowledges gives
// kFailed). Throws InvalidArgument for a request no
// capture can run with (a name not ending in .bpc, no θin, a θin listed twice or not offered
// by the instrument), IoError when the file cannot be written. An existing file follows the
// overwrite rule of every writing command (brdf::CheckWritableOutput in brdf/core/file_util.h):
// OutputExistsError unless `force` or `resume`, IoError for a folder, FIFO or device whatever
// they say; both before anything is measured.
CaptureSessionResult RunCaptureSession(const CaptureRequest& request, Transport& link,
                                       const SessionEvents& events = {},
                                       const CancelSignal* cancel = nullptr);

// The one-line geometry description a capture records ("extra" key "instrument_geometry") and
// a resume compares: "theta_in 0,20,40,60; theta_out 0-75 step 1; phi_out step 1; 76x360".
std::string GeometryText(const GeometryInfo& geometry);

}  // namespace brdf::device
