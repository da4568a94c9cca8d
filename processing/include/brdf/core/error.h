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
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace brdf {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Bad command-line or API arguments: an out-of-range angle, an unknown model name.
class InvalidArgument : public Error {
 public:
  explicit InvalidArgument(const std::string& message) : Error(message) {}
};

// The operating system refused: a missing file, a full disk, a failed rename.
class IoError : public Error {
 public:
  explicit IoError(const std::string& message) : Error(message) {}
};

// A file's content does not follow its format. `position` is human readable and says which
// coordinate system it uses ("byte 1840", "line 12", "line 12, column 3", "field 'rgb'").
class FormatError : public Error {
 public:
  FormatError(std::string file, std::string position, std::string expected, std::string got,
              std::string hint = {});

  const std::string& file() const { return file_; }
  const std::string& position() const { return position_; }
  const std::string& expected() const { return expected_; }
  const std::string& got() const { return got_; }

 private:
  std::string file_, position_, expected_, got_;
};

// The instrument (real or simulated) failed: timeout, disconnect, corrupt frame, refusal.
class DeviceError : public Error {
 public:
  explicit DeviceError(const std::string& message) : Error(message) {}
};

// "byte 1840" and "line 12": the two position spellings used by every reader.
std::string BytePosition(std::uint64_t offset);
std::string LinePosition(std::uint64_t line);

}  // namespace brdf
