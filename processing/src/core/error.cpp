#include "brdf/core/error.h"

#include <utility>

namespace brdf {
namespace {

std::string ComposeFormatMessage(const std::string& file, const std::string& position,
                                 const std::string& expected, const std::string& got,
                                 const std::string& hint) {
  std::string message = file.empty() ? std::string("<input>") : file;
  if (!position.empty()) message += ": " + position;
  message += ": expected " + expected + ", got " + got;
  if (!hint.empty()) message += " (" + hint + ")";
  return message;
}

}  // namespace

FormatError::FormatError(std::string file, std::string position, std::string expected,
                         std::string got, std::string hint, Remedy remedy)
    : Error(ComposeFormatMessage(file, position, expected, got, hint), std::move(remedy)),
      file_(std::move(file)),
      position_(std::move(position)),
      expected_(std::move(expected)),
      got_(std::move(got)),
      hint_(std::move(hint)) {}

std::string BytePosition(std::uint64_t offset) { return "byte " + std::to_string(offset); }
std::string LinePosition(std::uint64_t line) { return "line " + std::to_string(line); }

}  // namespace brdf
