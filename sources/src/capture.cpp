#include "brdf/sources/capture.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "brdf/core/file_util.h"
#include "brdf/core/virtual_capture.h"
#include "brdf/processing/resample.h"
#include "text.h"

namespace brdf::sources {
namespace {

namespace fs = std::filesystem;

using detail::Deg;
using detail::DegList;

bool ContainsAngle(const std::vector<double>& values, double v) {
  return std::any_of(values.begin(), values.end(),
                     [v](double x) { return std::fabs(x - v) <= 1e-3; });
}

// Bytes of returned slice i's chunk: up to the next intact chunk or damaged region.
std::uint64_t ChunkBytes(const BpcReadResult& r, std::size_t i) {
  const std::uint64_t start = r.slice_offsets[i];
  std::uint64_t end = i + 1 < r.slice_offsets.size() ? r.slice_offsets[i + 1] : r.valid_bytes;
  for (const BpcProblem& p : r.problems)
    if (p.offset > start && p.offset < end) end = p.offset;
  return end > start ? end - start : 0;
}

std::string SlicesText(std::size_t n) {
  return std::to_string(n) + " intact slice" + (n == 1 ? "" : "s");
}

// Slice indices and the end chunk's counts against what the file holds: CRC-valid chunks that
// disagree were written wrong (a broken writer or a tampered file), not damaged in transit.
void CheckStructure(CaptureAssessment& a) {
  const BpcReadResult& r = a.read;
  std::size_t slice_chunks = r.measurement.slices.size();
  for (const BpcProblem& p : r.problems)
    if (p.slice_index >= 0 && p.kind == BpcProblemKind::kCorrupt) ++slice_chunks;
  const Remedy repair{RemedyKind::kRepairCapture, a.path, r.valid_bytes, a.missing_theta_in_deg};
  for (std::size_t i = 0; i < r.slice_indices.size(); ++i) {
    const int index = r.slice_indices[i];
    const std::string where = BytePosition(r.slice_offsets[i]) + " (slice chunk " +
                              std::to_string(i) + " of the intact ones)";
    bool duplicate = false;
    for (std::size_t k = 0; k < i; ++k) duplicate = duplicate || r.slice_indices[k] == index;
    if (duplicate)
      a.refusals.push_back({where, "a slice index not used before",
                            "slice index " + std::to_string(index) + " a second time",
                            "two chunks claim to be the same slice", repair,
                            CaptureRefusal::Cause::kStructure});
    else if (index < 0 || static_cast<std::size_t>(index) >= slice_chunks)
      a.refusals.push_back(
          {where,
           "a slice index below the number of slice chunks (" + std::to_string(slice_chunks) + ")",
           "slice index " + std::to_string(index), "the file's slices are numbered wrong", repair,
           CaptureRefusal::Cause::kStructure});
  }
  if (r.finished && r.problems.empty()) {
    const std::string where = BytePosition(r.end_offset) + " (end chunk)";
    if (r.end_slice_count != static_cast<std::int64_t>(r.measurement.slices.size()))
      a.refusals.push_back(
          {where,
           "slice_count " + std::to_string(r.measurement.slices.size()) +
               " (the slices in the file)",
           r.end_slice_count < 0 ? std::string("no slice count")
                                 : "slice_count " + std::to_string(r.end_slice_count),
           "the end chunk does not describe this file", repair, CaptureRefusal::Cause::kStructure});
    if (r.end_sample_count != static_cast<std::int64_t>(r.measurement.SampleCount()))
      a.refusals.push_back(
          {where,
           "sample_count " + std::to_string(r.measurement.SampleCount()) +
               " (the samples in the file)",
           r.end_sample_count < 0 ? std::string("no sample count")
                                  : "sample_count " + std::to_string(r.end_sample_count),
           "the end chunk does not describe this file", repair, CaptureRefusal::Cause::kStructure});
  }
}

// Problems of one slice's values that a LUT cannot be built from and that dropping the slice
// removes (a resume then measures it again): bad samples, no valid sample, θin out of range.
// A duplicate θin is dropped as a second slice at the same θin; a degenerate measured range is
// a property of the whole capture.
bool DroppableForValues(const processing::LutInputProblem& p) {
  using Kind = processing::LutInputProblem::Kind;
  return p.slice >= 0 && (p.kind == Kind::kBadSamples || p.kind == Kind::kNoValidSample ||
                          p.kind == Kind::kThetaInOutOfRange);
}

std::vector<processing::LutInputProblem> ValueProblems(const Measurement& m) {
  processing::ResampleOptions options;
  options.require_uniform_theta_in = false;  // any distinct θin: eval accepts those too
  return processing::FindLutInputProblems(m, options);
}

// The values, by the rule BuildLut applies. A slice whose values are refused is dropped by
// RepairCapture, so the remedy is a repair and a resume measuring the dropped slices (and any
// planned slice not captured yet) again; a whole-capture problem can only be recaptured.
void CheckValues(CaptureAssessment& a) {
  const Measurement& m = a.read.measurement;
  if (m.slices.empty()) return;  // reported as missing slices
  const std::vector<processing::LutInputProblem> problems = ValueProblems(m);
  std::vector<double> to_measure = a.missing_theta_in_deg;
  for (const processing::LutInputProblem& p : problems)
    if (DroppableForValues(p) && ContainsAngle(a.planned_theta_in_deg, p.theta_in_deg) &&
        !ContainsAngle(to_measure, p.theta_in_deg))
      to_measure.push_back(p.theta_in_deg);
  std::vector<double> in_plan_order;
  for (double t : a.planned_theta_in_deg)
    if (ContainsAngle(to_measure, t)) in_plan_order.push_back(t);
  for (const processing::LutInputProblem& p : problems) {
    std::string where = "values";
    if (p.slice >= 0 && static_cast<std::size_t>(p.slice) < a.read.slice_offsets.size())
      where = BytePosition(a.read.slice_offsets[static_cast<std::size_t>(p.slice)]) + " (slice " +
              std::to_string(a.read.slice_indices[static_cast<std::size_t>(p.slice)]) + ")";
    a.refusals.push_back({where,
                          "values a LUT can be built from",
                          p.message,
                          {},
                          DroppableForValues(p) ? Remedy{RemedyKind::kRepairCapture, a.path,
                                                         a.read.valid_bytes, in_plan_order}
                                                : Remedy{RemedyKind::kRecapture, a.path},
                          CaptureRefusal::Cause::kValues});
  }
}

}  // namespace

FormatError CaptureRefusal::ToError(const std::string& file) const {
  return FormatError(file, position, expected, got, hint, remedy);
}

const Measurement& CaptureAssessment::UsableMeasurement() const {
  if (refusal) throw refusal->ToError(path);
  return read.measurement;
}

CaptureAssessment AssessCapture(const std::string& path) {
  return AssessCapture(path, ReadBpc(path));
}

CaptureAssessment AssessCapture(const std::string& path, BpcReadResult read) {
  CaptureAssessment a;
  a.path = path;
  a.read = std::move(read);
  const BpcReadResult& r = a.read;
  if (auto planned = PlannedThetaInDeg(r.header_metadata, path)) {
    a.planned_theta_in_deg = std::move(*planned);
    a.plan_recorded = true;
  } else if (auto from_end = PlannedThetaInDeg(r.measurement.metadata, path)) {
    a.planned_theta_in_deg = std::move(*from_end);
    a.plan_recorded = true;
  } else {
    a.planned_theta_in_deg = ReferenceGeometry().theta_in_deg;
  }
  for (const Slice& s : r.measurement.slices)
    if (s.complete) a.present_theta_in_deg.push_back(s.theta_in_deg);
  for (double t : a.planned_theta_in_deg)
    if (!ContainsAngle(a.present_theta_in_deg, t)) a.missing_theta_in_deg.push_back(t);

  const std::string intact = SlicesText(r.measurement.slices.size());
  // What lets the user continue: a resume when only the tail is damaged, else a repair first.
  const Remedy continue_remedy =
      r.intact_data_after_damage
          ? Remedy{RemedyKind::kRepairCapture, path, r.valid_bytes, a.missing_theta_in_deg}
          : Remedy{RemedyKind::kResumeCapture, path, r.valid_bytes, a.missing_theta_in_deg};
  bool tail_cut_outside_slices = false;
  for (const BpcProblem& p : r.problems) {
    if (p.kind == BpcProblemKind::kCorrupt) {
      const std::string where =
          BytePosition(p.offset) +
          (p.slice_index >= 0 ? " (slice " + std::to_string(p.slice_index) + ")" : std::string());
      a.refusals.push_back(CaptureRefusal{
          where, p.expected, p.got,
          "corrupt chunk; a LUT needs every slice intact; " + intact +
              (r.intact_data_after_damage ? ", some of them after the damage"
                                          : " end at byte " + std::to_string(r.valid_bytes)),
          continue_remedy, CaptureRefusal::Cause::kDamage});
      continue;
    }
    if (p.kind == BpcProblemKind::kTruncated) {
      if (p.slice_index >= 0) {
        a.refusals.push_back(CaptureRefusal{
            BytePosition(p.offset) + " (slice " + std::to_string(p.slice_index) + ")", p.expected,
            p.got,
            "the capture was interrupted inside slice " + std::to_string(p.slice_index) +
                "; a LUT needs every slice; " + intact + " end at byte " +
                std::to_string(r.valid_bytes),
            continue_remedy, CaptureRefusal::Cause::kDamage});
        continue;
      }
      tail_cut_outside_slices = true;
    }
  }
  for (std::size_t i = 0; i < r.measurement.slices.size(); ++i) {
    const Slice& s = r.measurement.slices[i];
    if (!s.complete)
      a.refusals.push_back(CaptureRefusal{
          BytePosition(r.slice_offsets[i]) + " (slice " + std::to_string(r.slice_indices[i]) +
              ", θin " + Deg(s.theta_in_deg) + "°)",
          "a complete slice",
          "a slice the instrument stopped before finishing (" + std::to_string(s.samples.size()) +
              " samples)",
          "a LUT needs every slice complete",
          Remedy{RemedyKind::kRepairCapture, path, r.valid_bytes, a.missing_theta_in_deg},
          CaptureRefusal::Cause::kIncompleteSlice});
  }
  CheckStructure(a);
  CheckValues(a);
  if (!r.finished && a.refusals.empty()) {
    if (!a.missing_theta_in_deg.empty()) {
      a.refusals.push_back(
          CaptureRefusal{BytePosition(r.valid_bytes),
                         "slices for every planned θin (" + DegList(a.planned_theta_in_deg) + "°)",
                         "the end of an unfinished capture " +
                             (a.present_theta_in_deg.empty()
                                  ? std::string("without any slice")
                                  : "with θin " + DegList(a.present_theta_in_deg) + "° only") +
                             " (missing " + DegList(a.missing_theta_in_deg) + "°)",
                         {},
                         continue_remedy,
                         CaptureRefusal::Cause::kMissingSlices});
    } else {
      a.warnings.push_back(
          path + ": warning: no intact end chunk (" +
          (tail_cut_outside_slices
               ? "the file is cut after the last slice, at byte " + std::to_string(r.valid_bytes)
               : std::string("the capture was never finalised")) +
          "), but all " + std::to_string(a.planned_theta_in_deg.size()) + " planned slices (θin " +
          DegList(a.planned_theta_in_deg) + "°) are intact: using them");
    }
  }
  if (!a.refusals.empty()) a.refusal = a.refusals.front();
  if (a.refusals.empty()) {
    // The exported slices' own requirement, by the rule BuildLut applies for them. No refusal
    // means CheckValues found no problem with the samples (the same checks for any θin rule),
    // so the θin list's are all that is left to find.
    for (const processing::LutInputProblem& p : processing::FindThetaInProblems(r.measurement))
      if (p.kind == processing::LutInputProblem::Kind::kThetaInNotUniform)
        a.export_refusals.push_back(
            {"slices (θin " + DegList(a.present_theta_in_deg) + "°)",
             "θin = k·Δin from 0° for the LUT textures (docs/design.md §5)",
             p.message.find("got ") != std::string::npos
                 ? p.message.substr(p.message.find("got ") + 4)
                 : p.message,
             "evaluating it needs no such steps; only the exported slices do",
             Remedy{RemedyKind::kRecapture, path}, CaptureRefusal::Cause::kValues});
  }
  for (const BpcProblem& p : r.problems)
    if (p.kind == BpcProblemKind::kTrailingData)
      a.warnings.push_back(path + ": warning: " + std::to_string(p.size) +
                           " unexpected bytes after the end chunk at byte " +
                           std::to_string(p.offset) + " were ignored");
  return a;
}

std::optional<std::string> SavedValuesRefusal(const std::string& path) {
  CaptureAssessment a;
  try {
    a = AssessCapture(path);
  } catch (const FormatError&) {
    return std::nullopt;  // not even a header: the session's own read says so
  }
  for (const CaptureRefusal& refusal : a.refusals)
    if (refusal.cause == CaptureRefusal::Cause::kValues) return refusal.ToError(path).what();
  return std::nullopt;
}

Measurement LoadCaptureForLut(const std::string& path, std::vector<std::string>* warnings,
                              std::vector<CaptureRefusal>* export_refusals) {
  CaptureAssessment a = AssessCapture(path);
  if (a.refusal) throw a.refusal->ToError(path);
  if (warnings) warnings->insert(warnings->end(), a.warnings.begin(), a.warnings.end());
  if (export_refusals)
    export_refusals->insert(export_refusals->end(), a.export_refusals.begin(),
                            a.export_refusals.end());
  return std::move(a.read.measurement);
}

Measurement LoadCaptureForCopy(const std::string& path, std::vector<std::string>* warnings) {
  CaptureAssessment a = AssessCapture(path);
  const bool empty = a.read.measurement.SampleCount() == 0;
  for (const CaptureRefusal& refusal : a.refusals)
    if (refusal.cause == CaptureRefusal::Cause::kDamage ||
        refusal.cause == CaptureRefusal::Cause::kStructure ||
        (empty && refusal.cause == CaptureRefusal::Cause::kMissingSlices))
      throw refusal.ToError(path);  // nothing to copy from an unfinished capture: resume it
  if (warnings) {
    warnings->insert(warnings->end(), a.warnings.begin(), a.warnings.end());
    // What the copy keeps that every reading command refuses (an incomplete slice, values no
    // LUT is built from): said, so that a CSV read back does not silently pass for a capture
    // the others accept.
    for (const CaptureRefusal& refusal : a.refusals) {
      if (refusal.cause != CaptureRefusal::Cause::kIncompleteSlice &&
          refusal.cause != CaptureRefusal::Cause::kValues)
        continue;
      std::string why = refusal.ToError(path).what();
      if (why.compare(0, path.size() + 2, path + ": ") == 0) why.erase(0, path.size() + 2);
      warnings->push_back(path +
                          ": warning: copied as it is, though the capture is refused "
                          "by every command that reads it: " +
                          why);
    }
    if (!a.read.finished && !a.missing_theta_in_deg.empty())
      warnings->push_back(path + ": warning: an unfinished capture: planned θin " +
                          DegList(a.missing_theta_in_deg) +
                          "° not captured yet; only the slices present are copied");
  }
  return std::move(a.read.measurement);
}

RepairReport RepairCapture(const std::string& input, const std::string& output, bool overwrite) {
  std::error_code ec;
  if (fs::exists(output, ec) && fs::equivalent(input, output, ec))
    throw InvalidArgument(output + ": the repaired capture must go to a new file, not over " +
                          input);
  CheckWritableOutput(output, overwrite);  // the overwrite rule of every writer
  CaptureAssessment a = AssessCapture(input);
  const BpcReadResult& r = a.read;
  // Damage, an incomplete slice, or CRC-valid chunks that contradict each other (slice
  // indices, the end chunk's counts): what the assessment tells the user to repair.
  // Slices whose values every reader refuses (by file order), dropped so a resume measures
  // them again.
  std::vector<std::string> value_reasons(r.measurement.slices.size());
  for (const processing::LutInputProblem& p : ValueProblems(r.measurement))
    if (DroppableForValues(p) && static_cast<std::size_t>(p.slice) < value_reasons.size() &&
        value_reasons[static_cast<std::size_t>(p.slice)].empty())
      value_reasons[static_cast<std::size_t>(p.slice)] =
          "values no LUT can be built from: " + p.message;
  const bool refused_values = std::any_of(value_reasons.begin(), value_reasons.end(),
                                          [](const std::string& why) { return !why.empty(); });
  const bool damaged =
      refused_values || !r.problems.empty() ||
      std::any_of(r.measurement.slices.begin(), r.measurement.slices.end(),
                  [](const Slice& s) { return !s.complete; }) ||
      std::any_of(a.refusals.begin(), a.refusals.end(), [](const CaptureRefusal& refusal) {
        return refusal.cause == CaptureRefusal::Cause::kStructure;
      });
  if (r.finished && !damaged)
    throw InvalidArgument(input + ": an intact, finished capture (" +
                          SlicesText(r.measurement.slices.size()) + "); nothing to repair");

  RepairReport report;
  report.input = input;
  report.output = output;
  report.planned_theta_in_deg = a.planned_theta_in_deg;
  for (const BpcProblem& p : r.problems) {
    if (p.kind == BpcProblemKind::kTrailingData) continue;
    DroppedPart d;
    d.offset = p.offset;
    d.size = p.size;
    d.slice_index = p.slice_index;
    d.reason =
        std::string(p.kind == BpcProblemKind::kCorrupt ? "corrupt chunk" : "cut inside a chunk") +
        ": expected " + p.expected + ", got " + p.got;
    report.dropped.push_back(std::move(d));
  }
  for (const BpcProblem& p : r.problems)
    if (p.kind == BpcProblemKind::kTrailingData)
      report.dropped.push_back({p.offset, p.size, -1, std::nullopt, "bytes after the end chunk"});
  // An end chunk whose counts contradict the slices is dropped (the output is unfinished and
  // gets a true one when it is resumed); slices with inconsistent indices are renumbered.
  for (const CaptureRefusal& refusal : a.refusals)
    if (refusal.cause == CaptureRefusal::Cause::kStructure && r.finished &&
        refusal.position.find("end chunk") != std::string::npos)
      report.dropped.push_back(
          {r.end_offset, r.valid_bytes > r.end_offset ? r.valid_bytes - r.end_offset : 0, -1,
           std::nullopt, "end chunk: expected " + refusal.expected + ", got " + refusal.got});

  // The header keeps what the capture started with (the settings a resume compares); the end
  // chunk's metadata, if any, is not carried over: the repaired capture is unfinished again.
  Metadata header = r.header_metadata;
  header.capture_end.clear();
  if (!a.plan_recorded)
    header.extra[kPlannedThetaInKey] = EncodeThetaInList(a.planned_theta_in_deg);
  header.extra["repaired_from"] = input;

  AtomicOutputPath out(output);
  {
    BpcAppender appender = BpcAppender::Create(out.temp_path(), header);
    for (std::size_t i = 0; i < r.measurement.slices.size(); ++i) {
      const Slice& s = r.measurement.slices[i];
      if (!s.complete) {
        report.dropped.push_back({r.slice_offsets[i], ChunkBytes(r, i), r.slice_indices[i],
                                  s.theta_in_deg,
                                  "slice incomplete: the instrument stopped after " +
                                      std::to_string(s.samples.size()) + " samples"});
        continue;
      }
      if (!value_reasons[i].empty()) {
        report.dropped.push_back({r.slice_offsets[i], ChunkBytes(r, i), r.slice_indices[i],
                                  s.theta_in_deg, value_reasons[i]});
        continue;
      }
      if (ContainsAngle(report.kept_theta_in_deg, s.theta_in_deg)) {
        report.dropped.push_back({r.slice_offsets[i], ChunkBytes(r, i), r.slice_indices[i],
                                  s.theta_in_deg, "a second slice at the same θin"});
        continue;
      }
      appender.AppendSlice(s);
      report.kept_theta_in_deg.push_back(s.theta_in_deg);
    }
  }  // closed without an end chunk: an unfinished, valid capture
  out.Commit();
  std::stable_sort(report.dropped.begin(), report.dropped.end(),
                   [](const DroppedPart& x, const DroppedPart& y) { return x.offset < y.offset; });
  for (double t : a.planned_theta_in_deg)
    if (!ContainsAngle(report.kept_theta_in_deg, t)) report.missing_theta_in_deg.push_back(t);
  report.output_bytes = fs::file_size(output, ec);
  return report;
}

}  // namespace brdf::sources
