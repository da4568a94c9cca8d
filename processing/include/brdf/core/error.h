// The one exception family of brdf-toolchain.
//
// Library code throws brdf::Error (or a subclass) for failures a caller cannot continue past:
// an unreadable file, a malformed header, a device that stopped answering. Outcomes that are
// part of normal operation (a frame that needs more bytes, a damaged tail after the last
// complete slice of a crash-interrupted capture) are returned as values instead.
//
// Every message names where the problem is and, for format errors, what was expected and what
// was found, so a user can fix the input without reading the source:
//   "cap.bpc: byte 1840: slice 2 chunk CRC32: expected 0x1c2d3e4f, got 0x00000000"
// Only tools/ turns these into exit codes and text on stderr.
//
// What the user can do about a failure is not spelled into the message: library code does not
// know the command-line flags of the tool that called it. An error carries a structured Remedy
// instead (resume the capture, repair it, overwrite with force, ...) and each tool renders it
// in its own words after the message.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace brdf {

// What the user can do to get past an error. Tools render it in their own terms (the `brdf`
// tool: "run 'brdf repair cap.bpc --out FIXED.bpc'").
enum class RemedyKind {
  kNone,
  kResumeCapture,      // continue the interrupted capture `file` (its first `valid_bytes` bytes are
                       // kept); `theta_in_deg` lists the slices still to capture
  kRepairCapture,      // write the intact slices of `file` to a new capture, then resume that one
  kRecapture,          // the data is lost (a slice stopped mid-way, damage beyond repair)
  kForceOverwrite,     // `file` exists and would be replaced only when the user insists
  kAllowBtdf,          // `file` holds transmission data, accepted only on request
  kNameFormat,         // the format of `file` could not be recognised; the user may name it
  kCaptureEvaluable,   // `file` is an evaluable BRDF (RGL, MERL): capture it virtually
  kEvaluateSingleLut,  // `file` is an atlas; evaluate one material's own LUT
};

struct Remedy {
  // Remedy{} is "nothing to suggest"; otherwise the kind, the file it acts on and, for the
  // capture remedies, the intact prefix and the missing slices. A constructor rather than
  // aggregate initialisation, so that `Remedy{kind, file}` states every member it leaves at its
  // default instead of relying on the aggregate rule (-Wmissing-field-initializers).
  Remedy() = default;
  Remedy(RemedyKind remedy_kind, std::string remedy_file, std::uint64_t intact_bytes = 0,
         std::vector<double> missing_theta_in_deg = {})
      : kind(remedy_kind),
        file(std::move(remedy_file)),
        valid_bytes(intact_bytes),
        theta_in_deg(std::move(missing_theta_in_deg)) {}

  RemedyKind kind = RemedyKind::kNone;
  std::string file;                  // the file the remedy acts on
  std::uint64_t valid_bytes = 0;     // kResumeCapture: the intact prefix kept by a resume
  std::vector<double> theta_in_deg;  // kResumeCapture / kRepairCapture: slices still missing
};

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, Remedy remedy = {})
      : std::runtime_error(message), remedy_(std::move(remedy)) {}

  const Remedy& remedy() const { return remedy_; }
  void set_remedy(Remedy remedy) { remedy_ = std::move(remedy); }

 private:
  Remedy remedy_;
};

// `error` with `remedy` attached, for `throw WithRemedy(FormatError(...), {...})`.
template <typename E>
E WithRemedy(E error, Remedy remedy) {
  error.set_remedy(std::move(remedy));
  return error;
}

// Bad command-line or API arguments: an out-of-range angle, an unknown model name.
class InvalidArgument : public Error {
 public:
  explicit InvalidArgument(const std::string& message, Remedy remedy = {})
      : Error(message, std::move(remedy)) {}
};

// The operating system refused: a missing file, a full disk, a failed rename.
class IoError : public Error {
 public:
  explicit IoError(const std::string& message, Remedy remedy = {})
      : Error(message, std::move(remedy)) {}
};

// A file's content does not follow its format. `position` is human readable and says which
// coordinate system it uses ("byte 1840", "line 12", "line 12, column 3", "field 'rgb'").
class FormatError : public Error {
 public:
  // `hint` is a short explanation in the format's terms (no command-line flags); what to do
  // goes into `remedy`.
  FormatError(std::string file, std::string position, std::string expected, std::string got,
              std::string hint = {}, Remedy remedy = {});

  const std::string& file() const { return file_; }
  const std::string& position() const { return position_; }
  const std::string& expected() const { return expected_; }
  const std::string& got() const { return got_; }
  const std::string& hint() const { return hint_; }

 private:
  std::string file_, position_, expected_, got_, hint_;
};

// The instrument (real or simulated) failed: timeout, disconnect, corrupt frame, refusal.
class DeviceError : public Error {
 public:
  explicit DeviceError(const std::string& message) : Error(message) {}
};

// "byte 1840" and "line 12": the two position spellings used by every reader.
std::string BytePosition(std::uint64_t offset);
std::string LinePosition(std::uint64_t line);
// A number as a user typed it in messages: "-10", "0.25", "1e+30" (%g, 9 significant digits),
// not std::to_string's "-10.000000".
std::string NumberText(double value);

}  // namespace brdf
