#include "brdf/core/error.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "brdf/core/json_error.h"

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
std::string NumberText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

std::string TextPosition(std::string_view text, std::uint64_t offset) {
  std::uint64_t line = 1, column = 1;
  for (std::uint64_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

namespace {

// Up to 24 characters of `text` from `offset`, on one line, quoted; bytes that are not
// printable ASCII (binary data read as text) as '?'.
std::string Excerpt(std::string_view text, std::uint64_t offset) {
  if (offset >= text.size()) return "the end of the text";
  std::string out = "'";
  for (std::uint64_t i = offset; i < text.size() && i < offset + 24; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') break;
    out += (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
  }
  return out + (offset + 24 < text.size() ? "...'" : "'");
}

}  // namespace

FormatError JsonSyntaxError(const std::string& file, std::string_view text,
                            std::uint64_t parser_byte) {
  const std::uint64_t offset = parser_byte > 0 ? parser_byte - 1 : 0;
  return FormatError(file, TextPosition(text, offset), "valid JSON", Excerpt(text, offset));
}

FormatError JsonNumberTooLargeError(const std::string& file, std::string_view text) {
  // The first number literal outside a string whose value overflows a double.
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;  // an escaped character, possibly a quote
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) {
      std::size_t end = i;
      while (end < text.size() && std::strchr("+-0123456789.eE", text[end]) != nullptr) ++end;
      const std::string literal(text.substr(i, end - i));
      if (std::isinf(std::strtod(literal.c_str(), nullptr)))
        return FormatError(file, TextPosition(text, i), "a finite number",
                           "'" + literal + "' (beyond the range of a double)");
      i = end - 1;
    }
  }
  return FormatError(file, "JSON text", "finite numbers", "a number beyond the range of a double");
}

}  // namespace brdf
