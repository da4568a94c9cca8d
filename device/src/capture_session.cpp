#include "brdf/device/capture_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <optional>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"
#include "brdf/core/virtual_capture.h"

namespace brdf::device {
namespace {

namespace fs = std::filesystem;

// Writes the capture file on a second thread, one job at a time in capture order, while the
// instrument measures the next slice, so that the writes and their fsyncs (the header's and
// its folder's above all: about a quarter of a full simulated capture on an idle machine)
// overlap the measuring. Nothing is reported as saved before its job returned, i.e. before
// its fsync: every way out of the session waits for the last job first (Wait), and a job's
// IoError surfaces there or at the next Then.
class BackgroundWriter {
 public:
  BackgroundWriter() = default;
  BackgroundWriter(const BackgroundWriter&) = delete;
  BackgroundWriter& operator=(const BackgroundWriter&) = delete;
  ~BackgroundWriter() {
    if (pending_.valid()) pending_.wait();
  }

  template <class Job>
  void Then(Job job) {
    Wait();
    pending_ = std::async(std::launch::async, std::move(job));
  }
  void Wait() {
    if (pending_.valid()) pending_.get();
  }

 private:
  std::future<void> pending_;
};

bool EndsWithBpc(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  if (name.size() <= 4) return false;
  std::string ext = name.substr(name.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".bpc";
}

// A refusal found while the instrument is connected (different serial or geometry).
struct Refusal {
  NextStep next;
  std::string message;
};

InstrumentProblem ProblemOf(const DriverFault& e) {
  if (e.kind() != FaultKind::kInstrumentError) return InstrumentProblem::kNone;
  switch (e.error_code()) {
    case ErrorCode::kLampFailure:
      return InstrumentProblem::kLampFailure;
    case ErrorCode::kSampleNotInContact:
      return InstrumentProblem::kSampleNotInContact;
    case ErrorCode::kOverTemperature:
      return InstrumentProblem::kOverTemperature;
    default:
      return InstrumentProblem::kNone;
  }
}

// Three numbers written by the driver's calibration metadata ("%.9g" of float32 readings):
// parsed back as float32 (nine digits identify a float uniquely), so the restored reading is
// bit for bit the one the instrument sent.
std::optional<std::array<double, 3>> ParseTriple(const std::map<std::string, std::string>& extra,
                                                 const std::string& key) {
  const auto it = extra.find(key);
  if (it == extra.end()) return std::nullopt;
  std::array<double, 3> v{};
  const char* p = it->second.c_str();
  for (double& x : v) {
    char* end = nullptr;
    const float f = std::strtof(p, &end);  // the nearest float32: the reading as sent
    if (end == p || !std::isfinite(f)) return std::nullopt;
    x = f;
    p = end;
  }
  return v;
}

// A float32 reading (exposure) or a count recorded as text.
std::optional<double> ParseNumber(const std::map<std::string, std::string>& extra,
                                  const std::string& key) {
  const auto it = extra.find(key);
  if (it == extra.end()) return std::nullopt;
  char* end = nullptr;
  const float d = std::strtof(it->second.c_str(), &end);
  if (end == it->second.c_str() || *end != '\0' || !std::isfinite(d)) return std::nullopt;
  return d;
}

std::string Text(const std::map<std::string, std::string>& extra, const std::string& key) {
  const auto it = extra.find(key);
  return it == extra.end() ? std::string() : it->second;
}

// The dark and white readings a capture recorded, for every θin of `theta_in_deg`; nullopt when
// the file lacks any of them (older files, or a plan the file never calibrated).
bool RestoreFromMetadata(Driver& driver, const Metadata& recorded,
                         const std::vector<double>& theta_in_deg) {
  const auto& x = recorded.extra;
  const auto dark = ParseTriple(x, "dark_counts");
  const auto noise = ParseTriple(x, "read_noise_counts");
  const auto dark_frames = ParseNumber(x, "dark_frames");
  if (!dark || !noise || !dark_frames || *dark_frames < 2) return false;
  DarkCalibration d;
  d.mean_counts = *dark;
  d.read_noise_counts = *noise;
  d.frames = static_cast<int>(*dark_frames);
  d.time = Text(x, "dark_time");
  std::vector<WhiteCalibration> whites;
  for (double t : theta_in_deg) {
    const std::string key = "white_theta_in_" + ShortNumberText(t);
    const auto counts = ParseTriple(x, key + "_counts");
    const auto exposure = ParseNumber(x, key + "_exposure_ms");
    const auto frames = ParseNumber(x, key + "_frames");
    if (!counts || !exposure || !frames || *frames < 1) return false;
    WhiteCalibration w;
    w.theta_in_deg = t;
    w.exposure_ms = *exposure;
    w.nd_transmittance = ParseNumber(x, key + "_nd_transmittance").value_or(1.0);
    w.counts = *counts;
    w.frames = static_cast<int>(*frames);
    w.time = Text(x, key + "_time");
    whites.push_back(std::move(w));
  }
  driver.RestoreCalibration(d, std::move(whites));
  return true;
}

}  // namespace

std::string GeometryText(const GeometryInfo& g) {
  std::string theta_in;
  for (float t : g.theta_in_deg) theta_in += (theta_in.empty() ? "" : ",") + ShortNumberText(t);
  return "theta_in " + theta_in + "; theta_out 0-" + ShortNumberText(g.theta_out_max_deg) +
         " step " + ShortNumberText(g.theta_out_step_deg) + "; phi_out step " +
         ShortNumberText(g.phi_out_step_deg) + "; " + std::to_string(g.rows) + "x" +
         std::to_string(g.columns);
}

CaptureSessionResult RunCaptureSession(const CaptureRequest& request, Transport& link,
                                       const SessionEvents& events, const CancelSignal* cancel) {
  const std::string& path = request.out_path;
  if (!EndsWithBpc(path))
    throw InvalidArgument("the capture file must be a .bpc file, got '" + path + "'");
  if (request.theta_in_deg.empty())
    throw InvalidArgument("a capture needs at least one incidence angle");

  CaptureSessionResult result;
  result.slices_planned = request.theta_in_deg.size();
  std::map<std::string, std::string> settings = request.settings;
  settings[kPlannedThetaInKey] = EncodeThetaInList(request.theta_in_deg);

  // What is already on disk, by the rule of every writing command: resuming a file is a
  // deliberate way of writing into it, as --force is.
  SessionStart start;
  start.removed_temporaries = CheckWritableOutput(path, request.force || request.resume);
  std::error_code ec;
  const bool exists = fs::exists(path, ec);
  start.slices_planned = request.theta_in_deg.size();
  std::vector<double> pending = request.theta_in_deg;
  std::optional<BpcReadResult> existing;
  if (request.resume && exists) {
    try {
      existing = ReadBpc(path);
    } catch (const FormatError& e) {
      result.outcome = CaptureOutcome::kRefused;
      result.next = NextStep::kOverwrite;
      result.message = FormatError(e.file(), e.position(), e.expected(), e.got()).what() +
                       std::string("; nothing in it can be resumed");
      return result;
    }
    const Metadata& old = existing->measurement.metadata;
    result.slices_saved = existing->measurement.slices.size();
    if (request.saved_values_refusal) {
      if (std::optional<std::string> why = request.saved_values_refusal(path)) {
        result.outcome = CaptureOutcome::kRefused;
        result.next = NextStep::kRepairSlices;
        result.message = std::move(*why);
        return result;
      }
    }
    if (existing->finished) {
      result.outcome = CaptureOutcome::kNothingToResume;
      result.resumed = true;
      result.message = path + " is a finished capture (" +
                       std::to_string(existing->measurement.slices.size()) +
                       " slices); nothing to resume";
      return result;
    }
    auto refuse = [&](const std::string& message) {
      result.outcome = CaptureOutcome::kRefused;
      result.next = NextStep::kUseOriginalSettings;
      result.message = message;
      return result;
    };
    if (old.sample_name != request.sample_name)
      return refuse(path + " holds sample '" + old.sample_name + "', not '" + request.sample_name +
                    "'");
    for (const auto& [key, value] : settings) {
      const auto it = old.extra.find(key);
      if (it != old.extra.end() && it->second != value)
        return refuse(path + " was captured with " + key + " = " + it->second +
                      ", this capture has " + value);
    }
    for (const Slice& done : existing->measurement.slices) {
      const auto it = std::find_if(pending.begin(), pending.end(), [&](double t) {
        return std::fabs(t - done.theta_in_deg) <= 1e-6;
      });
      if (it == pending.end())
        return refuse(path + " holds a slice at θin " + ShortNumberText(done.theta_in_deg) +
                      "° that this capture does not plan");
      pending.erase(it);
    }
    start.resuming = true;
    start.slices_done = existing->measurement.slices.size();
    result.resumed = true;
  }
  start.pending_theta_in_deg = pending;
  if (events.on_start) events.on_start(start);

  Driver driver(link, request.driver);
  driver.SetCancelFlag(cancel);

  CapturePlan plan;
  plan.theta_in_deg = pending;
  plan.exposure = request.exposure;
  plan.metadata.sample_name = request.sample_name;
  plan.metadata.operator_notes = request.operator_notes;
  plan.metadata.extra = settings;
  for (const auto& [key, value] : request.notes) plan.metadata.extra[key] = value;

  std::optional<BpcAppender> appender;
  BackgroundWriter writer;        // after `appender`: joined before it is destroyed
  std::size_t slices_handed = 0;  // to the writer by this session
  const std::size_t slices_before = existing ? existing->measurement.slices.size() : 0;
  std::vector<double> slice_seconds;
  CaptureCallbacks callbacks;
  callbacks.on_connected = [&](const InstrumentInfo& info) {
    const std::string geometry = GeometryText(info.geometry);
    plan.metadata.extra["instrument_geometry"] = geometry;
    if (events.on_connected) events.on_connected(info);
    if (!existing || request.force) return;
    const Metadata& old = existing->measurement.metadata;
    if (old.instrument_model != info.identity.model ||
        old.instrument_serial != info.identity.serial)
      throw Refusal{NextStep::kAcceptInstrument,
                    path + " was started on " + old.instrument_model + " serial " +
                        old.instrument_serial + "; the connected instrument is " +
                        info.identity.model + " serial " + info.identity.serial};
    const std::string old_geometry = Text(old.extra, "instrument_geometry");
    const std::size_t per_slice = std::size_t{info.geometry.rows} * info.geometry.columns;
    bool same = old_geometry.empty() || old_geometry == geometry;
    for (const Slice& s : existing->measurement.slices)
      same = same && s.samples.size() == per_slice;
    if (!same)
      throw Refusal{NextStep::kAcceptInstrument,
                    path + " was captured with geometry " +
                        (old_geometry.empty() ? "of other size" : old_geometry) +
                        "; the connected instrument measures " + geometry};
  };
  bool restored = false;
  callbacks.restore_calibration = [&](Driver& d) {
    if (!existing || request.calibrate) return false;
    restored = RestoreFromMetadata(d, existing->measurement.metadata, pending);
    return restored;
  };
  callbacks.on_retry = [&](const DriverFault& e, int attempt) {
    ++result.retries;
    if (events.on_retry)
      events.on_retry(std::string(e.what()) + " (measuring again, attempt " +
                      std::to_string(attempt + 1) + " of " +
                      std::to_string(request.driver.retries + 1) + ")");
  };
  callbacks.on_calibrated = [&](const Metadata& header) {
    writer.Then([&, header] {
      if (existing)
        appender.emplace(BpcAppender::Resume(path, nullptr));
      else
        appender.emplace(BpcAppender::Create(path, header));
    });
    if (events.on_calibrated) events.on_calibrated(header, !restored);
  };
  callbacks.on_slice = [&](Slice&& slice, const SliceReport& report) {
    ++slices_handed;
    result.new_samples += report.samples;
    result.saturated += report.saturated;
    result.below_noise_floor += report.below_noise_floor;
    slice_seconds.push_back(report.seconds);
    SliceProgress p;
    p.report = report;
    p.index = slices_before + slices_handed;
    p.planned = result.slices_planned;
    double mean = 0;
    for (double s : slice_seconds) mean += s / static_cast<double>(slice_seconds.size());
    p.eta_seconds = mean * static_cast<double>(pending.size() - slice_seconds.size());
    // The progress event comes from the writer, once the slice is on disk: what the user reads
    // as captured is durable.
    writer.Then([&appender, &events, s = std::move(slice), p] {
      appender->AppendSlice(s);
      if (events.on_slice) events.on_slice(p);
    });
  };

  // What is durable in the file once the writer is idle (every way out of the session).
  const auto saved = [&] {
    writer.Wait();
    return appender ? static_cast<std::size_t>(appender->slice_count()) : slices_before;
  };
  Metadata final_metadata;
  try {
    if (!pending.empty()) final_metadata = Capture(driver, plan, callbacks);
  } catch (const Refusal& r) {
    result.slices_saved = saved();
    result.outcome = CaptureOutcome::kRefused;
    result.next = r.next;
    result.message = r.message;
    return result;
  } catch (const DriverFault& e) {
    result.outcome =
        e.kind() == FaultKind::kCancelled ? CaptureOutcome::kInterrupted : CaptureOutcome::kFailed;
    result.problem = ProblemOf(e);
    result.message = e.what();
    result.slices_saved = saved();
    result.next = appender ? NextStep::kResume : NextStep::kRetry;
    return result;
  } catch (const DeviceError& e) {
    result.outcome = CaptureOutcome::kFailed;
    result.message = e.what();
    result.slices_saved = saved();
    result.next = appender ? NextStep::kResume : NextStep::kRetry;
    return result;
  }
  writer.Wait();
  if (existing) {
    // The header keeps the original capture's start, calibration and notes; what the resumed
    // part measured differently is added beside it.
    Metadata merged = existing->measurement.metadata;
    if (!pending.empty()) {
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
    merged.extra["resumed_theta_in_deg"] = EncodeThetaInList(pending);
    merged.capture_end = UtcNowIso8601();
    final_metadata = merged;
    if (!appender) appender.emplace(BpcAppender::Resume(path, nullptr));
  }
  appender->Finish(final_metadata);
  result.outcome = CaptureOutcome::kFinished;
  result.slices_saved = static_cast<std::size_t>(appender->slice_count());
  return result;
}

}  // namespace brdf::device
