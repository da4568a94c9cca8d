// Captures (.bpc) as inputs: the damaged-capture rule every command applies, and repair.
//
// The rule (a LUT needs every planned slice intact):
//  - any corrupt chunk (CRC mismatch, inconsistent fields) or a cut inside a slice chunk:
//    refused, naming the byte offset and slice. The remedy is a resume when the damage is the
//    file's tail (a resume cuts the file back to its intact prefix and captures the rest), a
//    repair when intact slices follow the damage (a resume would discard them);
//  - a slice flagged incomplete (the instrument stopped mid-slice): refused, remedy recapture
//    (repair drops the slice, then a resume captures it again);
//  - no end chunk (never finalised, or its end chunk is cut) but every planned θin slice intact:
//    usable, with a warning. The plan is the metadata's planned θin list
//    (PlannedThetaInDeg, brdf/core/virtual_capture.h) when recorded, else the reference
//    instrument's 0, 20, 40, 60°; a plan not fully present is refused with the resume remedy;
//  - bytes after the end chunk: usable, with a warning.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/measurement.h"

namespace brdf::sources {

// Why a capture cannot become a LUT, as the FormatError it throws would say it.
struct CaptureRefusal {
  // What kind of reason it is: commands that copy every sample (`brdf export-csv`) refuse
  // damage and inconsistent structure only; repair rewrites both.
  enum class Cause {
    kDamage,           // a corrupt chunk or a cut inside a slice
    kStructure,        // CRC-valid chunks that disagree (slice indices, end chunk counts)
    kIncompleteSlice,  // a slice the instrument stopped before finishing
    kMissingSlices,    // an unfinished capture without every planned slice
    kValues,           // values a LUT cannot be built from (NaN, angles out of range, ...)
  };
  std::string position;  // "byte 1840 (slice 2)"
  std::string expected, got, hint;
  Remedy remedy;
  Cause cause = Cause::kDamage;
  // The error itself: "<file>: <position>: expected ..., got ... (<hint>)" with the remedy.
  FormatError ToError(const std::string& file) const;
};

// The damaged-capture rule applied to one file, together with the checks of the file's
// structure (slice indices, the end chunk's counts) and of its values
// (processing::FindLutInputProblems with any θin set: NaN values, angles out of range, duplicate
// θin, a slice without valid samples, a degenerate measured range). `brdf info`, `convert` and
// `eval` all apply this one assessment, so they cannot disagree about a capture. The verdict,
// one rule for every command: refused (`refusals`) by every command that reads it; else
// accepted by all, except that a θin list other than k·Δin is refused by the LUT exports alone
// (`export_refusals`: convert, atlas), the capture staying evaluable.
struct CaptureAssessment {
  std::string path;
  BpcReadResult read;  // everything ReadBpc found (intact slices, problems, valid bytes)
  // The θin plan: recorded in the metadata, else the reference instrument's.
  std::vector<double> planned_theta_in_deg;
  bool plan_recorded = false;                // planned_theta_in_deg came from the file
  std::vector<double> present_theta_in_deg;  // intact, complete slices, in file order
  std::vector<double> missing_theta_in_deg;  // planned but not present (in plan order)
  std::optional<CaptureRefusal> refusal;     // the first of `refusals`, if any
  std::vector<CaptureRefusal> refusals;      // every reason the capture cannot become a LUT
  std::vector<std::string> warnings;         // full sentences starting with the path
  // Why the LUT textures (`brdf convert`, `brdf atlas`) cannot be made from a capture every
  // other command accepts: the θin list is not k·Δin from 0° (docs/design.md §5), which only
  // the exported slices need; evaluating it (eval, preview, fit, brdf-view) interpolates
  // between any distinct θin. Empty when `refusals` is not.
  std::vector<CaptureRefusal> export_refusals;

  // Every reading command accepts the capture (usable(), exportable()).
  bool usable() const { return !refusal.has_value(); }
  bool exportable() const { return usable() && export_refusals.empty(); }
  // read.measurement when usable; throws the refusal's FormatError otherwise.
  const Measurement& UsableMeasurement() const;
};

// Reads `path` (ReadBpc) and applies the rule. Damage is a value (refusal), not an exception;
// throws FormatError only when not even the header is readable (wrong magic, corrupt header),
// IoError when the file cannot be read, FormatError for a malformed planned θin list.
CaptureAssessment AssessCapture(const std::string& path);
// The same rule over a read already done.
CaptureAssessment AssessCapture(const std::string& path, BpcReadResult read);

// Why every reading command refuses the values of the slices saved in the capture `path`
// (the first refusal of AssessCapture caused by values, as its FormatError's sentence), or
// nothing: the check a resume makes before measuring (device::CaptureRequest::
// saved_values_refusal). Nothing also when the file has no readable header (the resume's own
// read reports that).
std::optional<std::string> SavedValuesRefusal(const std::string& path);

// AssessCapture(path).UsableMeasurement(), moved out, warnings appended to `warnings` and, when
// `export_refusals` is not null, the assessment's export_refusals there (why the LUT textures
// cannot be made of a capture every other command accepts).
Measurement LoadCaptureForLut(const std::string& path, std::vector<std::string>* warnings,
                              std::vector<CaptureRefusal>* export_refusals = nullptr);

// The same assessment for a command that copies every sample instead of building a LUT
// (`brdf export-csv`): refused for damage and inconsistent structure exactly as AssessCapture
// refuses (the first such refusal, thrown as its FormatError); an incomplete slice and planned
// slices not captured yet are kept (with a warning for the latter; an unfinished capture without
// any sample is refused with the resume remedy), as are values a LUT could
// not be built from (the caller's format decides whether it can hold them). A cut or missing end
// chunk and bytes after it give AssessCapture's warnings.
Measurement LoadCaptureForCopy(const std::string& path, std::vector<std::string>* warnings);

// What RepairCapture dropped from the damaged file.
struct DroppedPart {
  std::uint64_t offset = 0;            // byte offset of the dropped region in the damaged file
  std::uint64_t size = 0;              // its length in bytes
  int slice_index = -1;                // the file's slice index, -1 when not a slice or not known
  std::optional<double> theta_in_deg;  // when the slice's θin is known (an incomplete slice)
  std::string reason;  // "corrupt chunk: expected ..., got ...", "slice incomplete", ...
};

struct RepairReport {
  std::string input, output;
  std::vector<double> kept_theta_in_deg;     // slices written, in the order written
  std::vector<DroppedPart> dropped;          // in file order
  std::vector<double> planned_theta_in_deg;  // the plan the output records
  std::vector<double> missing_theta_in_deg;  // planned slices the output lacks (to resume)
  std::uint64_t output_bytes = 0;
};

// Writes every intact, complete slice of the capture `input` whose values a LUT can be built
// from (a slice with NaN, negative or absurd values, no valid sample, or θin out of range is
// dropped and named, like an incomplete one) to a new capture `output` as an
// unfinished but valid capture (header with the original metadata and planned θin list, the
// slices renumbered 0…n−1, no end chunk), so that resuming `output` captures exactly the
// missing slices. The file appears atomically (written beside `output` under a temporary name
// and renamed). `output` must not be `input`, and must not exist unless `overwrite`
// (brdf::CheckWritableOutput: OutputExistsError, kForceOverwrite). An intact capture has nothing
// to repair: InvalidArgument. Throws FormatError when not even the header is readable, IoError.
RepairReport RepairCapture(const std::string& input, const std::string& output,
                           bool overwrite = false);

}  // namespace brdf::sources
