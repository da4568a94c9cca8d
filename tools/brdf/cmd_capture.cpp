// `brdf capture`: drives a scatterometer through a whole capture and appends each completed
// slice to a .bpc file, so an interrupted capture keeps what it measured and can be resumed.
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/device/cancel.h"
#include "brdf/device/capture_session.h"
#include "brdf/device/driver.h"
#include "brdf/device/instrument_link.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"
#include "brdf/device/usb_models.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"
#ifdef BRDF_HAVE_DEVICE_EMULATION
#include "brdf/device_emulation/emulated_usb.h"
#endif

namespace brdf::cli {
namespace {

namespace fs = std::filesystem;

// The umockdev-emulated USB and HID links of the simulated instrument, when this build has them
// (BRDF_BUILD_DEVICE_EMULATION).
#ifdef BRDF_HAVE_DEVICE_EMULATION
constexpr bool kHaveEmulatedLinks = true;
constexpr device::EmulatedLinkOpener kEmulatedLinks = &device::OpenEmulatedLink;
#else
constexpr bool kHaveEmulatedLinks = false;
constexpr device::EmulatedLinkOpener kEmulatedLinks = nullptr;
#endif

// "109440" → "109,440".
std::string Thousands(std::size_t n) {
  const std::string digits = std::to_string(n);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

std::string Deg(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// "auto" / "auto-row", "auto-slice", or a fixed exposure in milliseconds.
device::ExposureSetting ParseExposure(const std::string& text) {
  if (text == "auto" || text == "auto-row") return {device::ExposureMode::kAutoPerRow, 0};
  if (text == "auto-slice") return {device::ExposureMode::kAutoPerSlice, 0};
  std::size_t used = 0;
  double ms = 0;
  try {
    ms = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !(ms > 0) || !std::isfinite(ms))
    throw InvalidArgument("--exposure: expected auto, auto-slice or a time in ms, got '" + text +
                          "'");
  return {device::ExposureMode::kFixed, static_cast<float>(ms)};
}

void Validate(const CaptureOptions& o) {
  if (o.sample.empty()) throw InvalidArgument("--sample: a sample name is required");
  if (o.out.empty()) throw InvalidArgument("--out: an output .bpc path is required");
  if (LowerExtension(o.out) != ".bpc")
    throw InvalidArgument("--out: a capture is written as a .bpc file, got '" + o.out + "'");
  const CaptureGeometry& g = o.geometry;
  if (g.theta_in_deg.empty()) throw InvalidArgument("--theta-in: at least one angle is required");
  for (double t : g.theta_in_deg)
    if (!(t >= 0 && t < 90))
      throw InvalidArgument("--theta-in: angles must be in [0, 90) degrees, got " + Deg(t));
  if (!(o.noise >= 0) || !std::isfinite(o.noise))
    throw InvalidArgument("--noise: expected a level ≥ 0 (1 = reference instrument), got " +
                          Deg(o.noise));
  if (!(g.theta_out_max_deg >= 0 && g.theta_out_max_deg < 90))
    throw InvalidArgument("--theta-out-max: expected [0, 90) degrees, got " +
                          Deg(g.theta_out_max_deg));
  if (!(g.theta_out_step_deg >= 0.01 && g.theta_out_step_deg <= 90))
    throw InvalidArgument("--theta-out-step: expected [0.01, 90] degrees, got " +
                          Deg(g.theta_out_step_deg));
  if (!(g.phi_out_step_deg >= 0.01 && g.phi_out_step_deg <= 360))
    throw InvalidArgument("--phi-out-step: expected [0.01, 360] degrees, got " +
                          Deg(g.phi_out_step_deg));
}

// Settings of the simulated instrument that must agree between an interrupted capture and its
// resumption, as recorded in the metadata `extra` map. The planned θin list is the session's
// (CaptureRequest::theta_in_deg, recorded as "theta_in_deg").
std::string Eta(double seconds) {
  char buf[32];
  if (seconds < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  else
    std::snprintf(buf, sizeof buf, "%.0f min %02.0f s", std::floor(seconds / 60),
                  std::fmod(seconds, 60));
  return buf;
}

// Ctrl-C, SIGTERM and SIGHUP (the terminal or SSH session closed) ask the session to abort the
// scan (brdf/device/cancel.h: raising it is async-signal-safe and wakes a waiting read); a second
// signal is not special (the abort itself is bounded by the reply timeout). SIGPIPE is ignored
// meanwhile: once the session's stderr pipe is gone, progress lines fail quietly instead of
// killing the tool with the scan still running.
device::CancelSignal* g_cancel = nullptr;
extern "C" void OnSignal(int) {
  if (g_cancel != nullptr) g_cancel->Raise();
}

class SignalScope {
 public:
  explicit SignalScope(device::CancelSignal& cancel) {
    cancel.Reset();
    g_cancel = &cancel;
    struct sigaction sa {};
    sa.sa_handler = OnSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
    sigaction(SIGHUP, &sa, &old_hup_);
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    sigaction(SIGPIPE, &ignore, &old_pipe_);
  }
  ~SignalScope() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    sigaction(SIGHUP, &old_hup_, nullptr);
    sigaction(SIGPIPE, &old_pipe_, nullptr);
    g_cancel = nullptr;
  }
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;

 private:
  struct sigaction old_int_ {
  }, old_term_{}, old_hup_{}, old_pipe_{};
};

// The session's next step in this tool's words (options by their flag names).
std::string Advice(const device::CaptureSessionResult& r, const std::string& out) {
  using device::NextStep;
  switch (r.next) {
    case NextStep::kNone:
      return {};
    case NextStep::kResume:
      return std::to_string(r.slices_saved) + " of " + std::to_string(r.slices_planned) +
             " slices are saved in " + out +
             "; run the same command with --resume to capture "
             "the rest";
    case NextStep::kRetry:
      return "nothing was saved; check the instrument and run the command again";
    case NextStep::kOverwrite:
      return "start over with --force";
    case NextStep::kAcceptInstrument:
      return "connect the original instrument, or add --force to resume on this one";
    case NextStep::kUseOriginalSettings:
      return "rerun with the original settings";
    case NextStep::kRepairSlices:
      return "run 'brdf repair " + out +
             " --out FIXED.bpc' to drop the refused slices, then rerun this command with "
             "--out FIXED.bpc --resume to measure them again";
  }
  return {};
}

std::string ProblemAdvice(device::InstrumentProblem p) {
  switch (p) {
    case device::InstrumentProblem::kNone:
      return {};
    case device::InstrumentProblem::kLampFailure:
      return "check or replace the lamp, then ";
    case device::InstrumentProblem::kSampleNotInContact:
      return "seat the sample on the measurement port, then ";
    case device::InstrumentProblem::kOverTemperature:
      return "let the instrument cool down, then ";
  }
  return {};
}

}  // namespace

int RunCapture(const CaptureOptions& o) {
  Validate(o);
  device::DeviceSpec spec;
  device::SimLink sim_link = device::SimLink::kLoopback;
  try {
    spec = device::ParseDeviceSpec(o.device);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("--device: ") + e.what());
  }
  try {
    sim_link = device::ParseSimLink(o.transport);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("--transport: ") + e.what());
  }
  const bool sim = spec.kind == device::DeviceSpec::Kind::kSim;
  if (!sim && (o.transport != "loopback" || !o.sim_fault.empty()))
    throw InvalidArgument("--transport and --sim-fault apply to --device sim only");
  if (sim_link != device::SimLink::kLoopback && !kHaveEmulatedLinks)
    throw InvalidArgument("--transport " + o.transport +
                          ": the emulated usb and hid transports are not part of this build "
                          "(configured with BRDF_BUILD_DEVICE_EMULATION=OFF); use loopback");
  device::FaultPlan faults;
  try {
    faults = device::ParseFaultPlan(o.sim_fault);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("--sim-fault: ") + e.what());
  }
  const device::ExposureSetting exposure = ParseExposure(o.exposure);
  if (sim && o.material.empty())
    throw InvalidArgument("--material: the simulated instrument needs a virtual sample");
  // The virtual sample: a library name or any evaluable file, opened by content
  // (brdf::sources::OpenBrdf, the rule of every command).
  const std::string material_path = sim ? sources::ResolveSource(o.material) : std::string();
  std::shared_ptr<const BrdfSource> source;
  if (sim) {
    sources::OpenedSource opened = sources::OpenBrdf(material_path);
    for (const std::string& w : opened.warnings) std::fprintf(stderr, "%s\n", w.c_str());
    source = std::move(opened.brdf);
  }

  // The simulated instrument: the reference model with the requested light-arm positions and
  // detector steps (a real instrument reports its own and refuses what it cannot do).
  device::SimulatorConfig config;
  config.sample = source;
  config.noise_level = o.noise;
  config.seed = o.seed;
  config.faults = faults;
  config.model.SetGeometry(o.geometry);
  config.pace_ms_per_row = o.sim_pace_ms;
  // --sim-fault hold:N, for tests that interrupt the capture at a chosen frame: the lines say
  // when the hold begins (the moment to send the signal) and that the ABORT reached the
  // instrument. Always printed (also with --quiet): they are what such a test waits for.
  config.on_hold = [](std::uint64_t frame) {
    std::fprintf(stderr,
                 "brdf: simulated instrument: holding before frame %llu until the capture is "
                 "cancelled\n",
                 static_cast<unsigned long long>(frame));
    std::fflush(stderr);
  };
  config.on_hold_released = [] {
    std::fprintf(stderr, "brdf: simulated instrument: ABORT received, hold released\n");
  };
  const std::unique_ptr<device::InstrumentLink> link =
      device::OpenInstrumentLink(spec, config, sim_link, kEmulatedLinks);

  device::CaptureRequest request;
  request.out_path = o.out;
  request.theta_in_deg = o.geometry.theta_in_deg;
  request.exposure = exposure;
  request.sample_name = o.sample;
  request.operator_notes = o.operator_notes;
  if (sim) {
    request.settings =
        device::SimulatedCaptureSettings(o.device, source->Name(), config, o.geometry, o.exposure);
    request.notes["material_file"] = sources::RecordedSourceName(material_path);
  } else {
    request.settings["device"] = o.device;
  }
  request.resume = o.resume;
  request.saved_values_refusal = sources::SavedValuesRefusal;
  request.force = o.force;
  request.calibrate = o.calibrate;

  device::SessionEvents events;
  events.on_start = [&](const device::SessionStart& s) {
    ReportRemovedTemporaries(s.removed_temporaries);
    if (o.quiet) return;
    if (o.resume && !s.resuming)
      std::fprintf(stderr, "%s does not exist yet: starting a new capture\n", o.out.c_str());
    if (s.resuming)
      std::fprintf(stderr, "resuming %s: %zu of %zu slices already captured\n", o.out.c_str(),
                   s.slices_done, s.slices_planned);
  };
  events.on_calibrated = [&](const Metadata& header, bool measured) {
    if (o.quiet) return;
    std::fprintf(stderr, "%s %s: %s\n", header.instrument_model.c_str(),
                 header.instrument_serial.c_str(),
                 measured ? "dark and white reference measured"
                          : "dark and white reference of the interrupted capture reused");
  };
  events.on_retry = [&](const std::string& message) {
    if (!o.quiet) std::fprintf(stderr, "brdf: warning: %s\n", message.c_str());
  };
  events.on_slice = [&](const device::SliceProgress& p) {
    if (o.quiet) return;
    const device::SliceReport& report = p.report;
    std::string line = "slice " + std::to_string(p.index) + "/" + std::to_string(p.planned) +
                       " θin=" + Deg(report.theta_in_deg) + "°: " + Thousands(report.samples) +
                       " samples, ";
    char secs[32];
    std::snprintf(secs, sizeof secs, "%.1f s", report.seconds);
    line += secs;
    line += ", " + Thousands(report.saturated) + " saturated";
    if (report.below_noise_floor > 0)
      line += ", " + Thousands(report.below_noise_floor) + " below noise floor";
    if (p.index < p.planned) line += ", ETA " + Eta(p.eta_seconds);
    std::fprintf(stderr, "%s\n", line.c_str());
  };

  device::CaptureSessionResult r;
  {
    device::CancelSignal cancel;
    SignalScope signals(cancel);
    r = device::RunCaptureSession(request, link->transport(), events, &cancel);
  }
  switch (r.outcome) {
    case device::CaptureOutcome::kFinished:
      if (!o.quiet)
        std::fprintf(stderr,
                     "wrote %s: %zu slices, %s new samples, %s saturated, %s below noise floor\n",
                     o.out.c_str(), r.slices_saved, Thousands(r.new_samples).c_str(),
                     Thousands(r.saturated).c_str(), Thousands(r.below_noise_floor).c_str());
      WarnAboutVerdict(o.out);
      return 0;
    case device::CaptureOutcome::kNothingToResume:
      if (!o.quiet) std::fprintf(stderr, "%s\n", r.message.c_str());
      return 0;
    case device::CaptureOutcome::kRefused:
      std::fprintf(stderr, "brdf: error: %s%s%s\n", r.message.c_str(),
                   r.next == device::NextStep::kNone ? "" : ": ", Advice(r, o.out).c_str());
      return 1;
    case device::CaptureOutcome::kInterrupted:
    case device::CaptureOutcome::kFailed:
      std::fprintf(stderr, "brdf: error: %s\n", r.message.c_str());
      std::fprintf(stderr, "brdf: %s%s\n", ProblemAdvice(r.problem).c_str(),
                   Advice(r, o.out).c_str());
      return r.outcome == device::CaptureOutcome::kInterrupted ? 130 : 1;
  }
  return 1;
}

}  // namespace brdf::cli
