// JSON texts that do not parse, reported in the user's terms.
//
// Every reader of a JSON file (material files, sidecars, manifests, extrapolation files, the
// header chunk of a .bpc) turns a parser failure into a FormatError with these two functions,
// so that the message says where the text is wrong (line and column, 1-based, counted in bytes
// as an editor's status bar shows them for ASCII text) and what stands there, and never the
// parser library's own wording:
//   "mat.json: line 4, column 12: expected valid JSON, got 'NaN, \"l\": 0.5}'"
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "brdf/core/error.h"

namespace brdf {

// "line L, column C" of the byte at `offset` (0-based) in `text`.
std::string TextPosition(std::string_view text, std::uint64_t offset);

// A syntax error: `parser_byte` is the 1-based offset of the character the parser stopped at
// (nlohmann::json::parse_error::byte); at or past the end of `text` it reads "the end of the
// text". `file` may carry a qualifier ("cap.bpc (HEAD chunk)").
FormatError JsonSyntaxError(const std::string& file, std::string_view text,
                            std::uint64_t parser_byte);

// A number literal too large for a double (1e309): JSON allows it, but the value would be
// infinite. The position is the first such literal in `text`.
FormatError JsonNumberTooLargeError(const std::string& file, std::string_view text);

}  // namespace brdf
