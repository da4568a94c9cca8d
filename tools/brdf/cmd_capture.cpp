// `brdf capture`: drives a scatterometer through a whole capture and appends each completed
// slice to a .bpc file, so an interrupted capture keeps what it measured and can be resumed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/device/driver.h"
#include "brdf/device/simulator.h"
#include "brdf/device/transport.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {
namespace {

namespace fs = std::filesystem;

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

std::uint64_t ParseCount(const std::string& text, const std::string& what) {
  std::size_t used = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || v == 0)
    throw InvalidArgument(what + ": expected a frame count ≥ 1, got '" + text + "'");
  return v;
}

// "disconnect:N", "stall:N", "corrupt:N", comma separated.
device::FaultPlan ParseFaults(const std::string& spec) {
  device::FaultPlan plan;
  std::size_t start = 0;
  while (start < spec.size()) {
    std::size_t end = spec.find(',', start);
    if (end == std::string::npos) end = spec.size();
    const std::string item = spec.substr(start, end - start);
    const std::size_t colon = item.find(':');
    const std::string kind = item.substr(0, colon);
    const std::string value = colon == std::string::npos ? "" : item.substr(colon + 1);
    const std::string what = "--sim-fault " + item;
    if (kind == "disconnect")
      plan.disconnect_after_frames = ParseCount(value, what);
    else if (kind == "stall")
      plan.stall_after_frames = ParseCount(value, what);
    else if (kind == "corrupt")
      plan.corrupt_frame = ParseCount(value, what);
    else
      throw InvalidArgument("--sim-fault: expected disconnect:N, stall:N or corrupt:N, got '" +
                            item + "'");
    start = end + 1;
  }
  return plan;
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
  if (o.device != "sim")
    throw InvalidArgument(
        "--device: only 'sim' (the simulated scatterometer) is available in "
        "this build, got '" +
        o.device + "'");
  if (o.sample.empty()) throw InvalidArgument("--sample: a sample name is required");
  if (o.out.empty()) throw InvalidArgument("--out: an output .bpc path is required");
  if (o.theta_in_deg.empty()) throw InvalidArgument("--theta-in: at least one angle is required");
  for (double t : o.theta_in_deg)
    if (!(t >= 0 && t < 90))
      throw InvalidArgument("--theta-in: angles must be in [0, 90) degrees, got " + Deg(t));
  if (!(o.noise >= 0) || !std::isfinite(o.noise))
    throw InvalidArgument("--noise: expected a level ≥ 0 (1 = reference instrument), got " +
                          Deg(o.noise));
  if (!(o.theta_out_max_deg >= 0 && o.theta_out_max_deg < 90))
    throw InvalidArgument("--theta-out-max: expected [0, 90) degrees, got " +
                          Deg(o.theta_out_max_deg));
  if (!(o.theta_out_step_deg >= 0.01 && o.theta_out_step_deg <= 90))
    throw InvalidArgument("--theta-out-step: expected [0.01, 90] degrees, got " +
                          Deg(o.theta_out_step_deg));
  if (!(o.phi_out_step_deg >= 0.01 && o.phi_out_step_deg <= 360))
    throw InvalidArgument("--phi-out-step: expected [0.01, 360] degrees, got " +
                          Deg(o.phi_out_step_deg));
}

// Settings that must agree between an interrupted capture and its resumption, as recorded in
// the metadata `extra` map. "theta_in_deg" is the planned θin list ("0,20,40,60"), written into
// the header before the first slice so that `brdf convert` can tell an interrupted capture
// missing slices from a complete one (brdf::PlannedThetaInDeg in brdf/core/virtual_capture.h reads it). A resumption must
// plan the same list: the header on disk is not rewritten, so a different list would make the
// recorded plan untrue.
std::map<std::string, std::string> SettingsOf(const CaptureOptions& o,
                                              const std::string& material) {
  char seed[32];
  std::snprintf(seed, sizeof seed, "%llu", static_cast<unsigned long long>(o.seed));
  std::string theta_in;
  for (double t : o.theta_in_deg) theta_in += (theta_in.empty() ? "" : ",") + Deg(t);
  return {{"device", o.device},
          {"theta_in_deg", theta_in},
          {"material", material},
          {"noise_level", Deg(o.noise)},
          {"seed", seed},
          {"theta_out_max_deg", Deg(o.theta_out_max_deg)},
          {"theta_out_step_deg", Deg(o.theta_out_step_deg)},
          {"phi_out_step_deg", Deg(o.phi_out_step_deg)},
          {"exposure", o.exposure}};
}

}  // namespace

int RunCapture(const CaptureOptions& o) {
  Validate(o);
  const device::FaultPlan faults = ParseFaults(o.sim_fault);
  const device::ExposureSetting exposure = ParseExposure(o.exposure);
  const std::string material_path = ResolveMaterial(o.material);
  std::shared_ptr<const BrdfSource> source = OpenBrdfSource(material_path);
  const std::map<std::string, std::string> settings = SettingsOf(o, source->Name());

  // The simulated instrument: the reference model with the requested light-arm positions and
  // detector steps (a real instrument reports its own and refuses what it cannot do).
  device::SimulatorConfig config;
  config.sample = source;
  config.noise_level = o.noise;
  config.seed = o.seed;
  config.faults = faults;
  config.model.theta_in_deg.assign(o.theta_in_deg.begin(), o.theta_in_deg.end());
  config.model.theta_out_max_deg = static_cast<float>(o.theta_out_max_deg);
  config.model.theta_out_step_deg = static_cast<float>(o.theta_out_step_deg);
  config.model.phi_out_step_deg = static_cast<float>(o.phi_out_step_deg);
  device::SimulatedFirmware firmware(config);
  device::LoopbackTransport link(firmware);
  device::Driver driver(link);

  // What is already on disk.
  std::error_code ec;
  const bool exists = fs::exists(o.out, ec);
  std::vector<double> pending = o.theta_in_deg;
  std::optional<BpcReadResult> existing;
  if (exists && !o.resume && !o.force)
    throw InvalidArgument(o.out +
                          " already exists: use --resume to continue an interrupted "
                          "capture or --force to overwrite it");
  if (o.resume && exists) {
    try {
      existing = ReadBpc(o.out);
    } catch (const FormatError& e) {
      throw FormatError(e.file(), e.position(), e.expected(), e.got(),
                        "nothing in it can be resumed; start over with --force");
    }
    const Metadata& old = existing->measurement.metadata;
    if (existing->finished) {
      if (!o.quiet)
        std::fprintf(stderr, "%s is a finished capture (%zu slices); nothing to resume\n",
                     o.out.c_str(), existing->measurement.slices.size());
      return 0;
    }
    if (old.sample_name != o.sample)
      throw InvalidArgument("--resume: " + o.out + " holds sample '" + old.sample_name +
                            "', not '" + o.sample + "'");
    for (const auto& [key, value] : settings) {
      const auto it = old.extra.find(key);
      if (it != old.extra.end() && it->second != value)
        throw InvalidArgument("--resume: " + o.out + " was captured with " + key + " = " +
                              it->second + ", this command has " + value +
                              " (rerun with the original settings)");
    }
    for (const Slice& done : existing->measurement.slices) {
      const auto it = std::find_if(pending.begin(), pending.end(), [&](double t) {
        return std::fabs(t - done.theta_in_deg) <= 1e-6;
      });
      if (it == pending.end())
        throw InvalidArgument("--resume: " + o.out + " holds a slice at θin " +
                              Deg(done.theta_in_deg) + "° that --theta-in does not list");
      pending.erase(it);
    }
  } else if (o.resume && !o.quiet) {
    std::fprintf(stderr, "%s does not exist yet: starting a new capture\n", o.out.c_str());
  }

  const std::size_t total = o.theta_in_deg.size();
  const std::size_t done_before = total - pending.size();
  std::optional<BpcAppender> appender;
  if (existing) {
    appender.emplace(BpcAppender::Resume(o.out, nullptr));
    if (!o.quiet)
      std::fprintf(stderr, "resuming %s: %zu of %zu slices already captured\n", o.out.c_str(),
                   done_before, total);
  }

  device::CapturePlan plan;
  plan.theta_in_deg = pending;
  plan.exposure = exposure;
  plan.metadata.sample_name = o.sample;
  plan.metadata.operator_notes = o.operator_notes;
  plan.metadata.extra = settings;
  plan.metadata.extra["material_file"] = material_path;

  std::size_t slices_saved = done_before, samples = 0, saturated = 0, below = 0;
  device::CaptureCallbacks callbacks;
  callbacks.on_calibrated = [&](const Metadata& header) {
    if (!appender) appender.emplace(BpcAppender::Create(o.out, header));
    if (!o.quiet)
      std::fprintf(stderr, "%s %s: dark and white reference measured at %zu θin\n",
                   header.instrument_model.c_str(), header.instrument_serial.c_str(),
                   pending.size());
  };
  callbacks.on_slice = [&](const Slice& slice, const device::SliceReport& report) {
    appender->AppendSlice(slice);
    ++slices_saved;
    samples += report.samples;
    saturated += report.saturated;
    below += report.below_noise_floor;
    if (!o.quiet) {
      std::string line = "slice " + std::to_string(slices_saved) + "/" + std::to_string(total) +
                         " θin=" + Deg(report.theta_in_deg) + "°: " + Thousands(report.samples) +
                         " samples, ";
      char secs[32];
      std::snprintf(secs, sizeof secs, "%.1f s", report.seconds);
      line += secs;
      line += ", " + Thousands(report.saturated) + " saturated";
      if (report.below_noise_floor > 0)
        line += ", " + Thousands(report.below_noise_floor) + " below noise floor";
      std::fprintf(stderr, "%s\n", line.c_str());
    }
  };

  Metadata final_metadata;
  try {
    if (!pending.empty()) final_metadata = device::Capture(driver, plan, callbacks);
  } catch (const DeviceError& e) {
    std::fprintf(stderr, "brdf: error: %s\n", e.what());
    if (appender) {
      std::fprintf(stderr,
                   "brdf: %zu of %zu slices are saved in %s; run the same command with --resume "
                   "to capture the rest\n",
                   slices_saved, total, o.out.c_str());
    } else {
      std::fprintf(stderr,
                   "brdf: nothing was saved; check the instrument and run the command "
                   "again\n");
    }
    return 1;
  }

  if (existing) {
    // The header keeps the original capture's start, calibration and notes; what the resumed
    // part measured differently is added beside it.
    Metadata merged = existing->measurement.metadata;
    if (pending.empty()) {
      final_metadata = merged;
    } else {
      for (const auto& [key, value] : final_metadata.extra) {
        const auto it = merged.extra.find(key);
        if (it == merged.extra.end())
          merged.extra[key] = value;
        else if (it->second != value)
          merged.extra[key + "_resume"] = value;
      }
      merged.extra["calibration_time_resume"] = final_metadata.calibration_time;
      merged.extra["capture_start_resume"] = final_metadata.capture_start;
    }
    std::string resumed;
    for (double t : pending) resumed += (resumed.empty() ? "" : ",") + Deg(t);
    merged.extra["resumed_theta_in_deg"] = resumed;
    merged.capture_end = UtcNowIso8601();
    final_metadata = merged;
  }
  appender->Finish(final_metadata);
  if (!o.quiet)
    std::fprintf(stderr,
                 "wrote %s: %zu slices, %s new samples, %s saturated, %s below noise floor\n",
                 o.out.c_str(), total, Thousands(samples).c_str(), Thousands(saturated).c_str(),
                 Thousands(below).c_str());
  return 0;
}

}  // namespace brdf::cli
