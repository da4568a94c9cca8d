// Tokenizer and line cursor shared by the text-format readers (Zemax, LightTools, CSV,
// goniometer tables). Private to brdf::core.
//
// Every failure is a FormatError naming the file, the 1-based line and what was expected and
// found (docs/design.md §4). Counts read from a file are bounded by what the rest of the file could
// possibly hold, so a hostile "ScatterAzimuth 4000000000" is refused before anything is
// allocated. Numbers must be finite; text that ends up in metadata must be valid UTF-8. Found
// text is quoted through Printable() so a message never carries raw control bytes or broken
// UTF-8 to a terminal.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace brdf::detail {

// Largest files the readers accept (checked before reading). Parsed data takes up to about
// four times the text size (8-byte doubles from 2-byte "0 " tokens, 44-byte samples from
// 14-byte CSV rows), so these caps also bound memory. Real files are far smaller: the shared
// Zemax file is 28 KB, a 110 k-row capture CSV 8 MB, a MiniDiff-sized LightTools export 4 MB.
inline constexpr std::uint64_t kMaxZemaxBytes = 64ull << 20;
inline constexpr std::uint64_t kMaxLightToolsBytes = 128ull << 20;
inline constexpr std::uint64_t kMaxCsvBytes = 128ull << 20;
inline constexpr std::uint64_t kMaxGonioBytes = 32ull << 20;
inline constexpr std::uint64_t kMaxTextFileBytes = kMaxLightToolsBytes;

// Reads a whole text file with the size cap above. Throws IoError / FormatError.
std::string ReadTextFile(const std::string& path, std::uint64_t max_bytes = kMaxTextFileBytes);

// A short, quoted, printable rendering of untrusted text for error messages: control bytes
// and invalid UTF-8 become \xNN escapes, long text is cut at 40 characters with "...".
std::string Printable(std::string_view s);

bool IsValidUtf8(std::string_view s);

// ASCII case-insensitive equality (file keywords are matched this way).
bool EqualsIgnoreCase(std::string_view a, std::string_view b);

// Throws FormatError(file, "line N", expected, got).
[[noreturn]] void Fail(const std::string& file, std::uint64_t line, std::string_view expected,
                       std::string_view got);

// Whether `v` rounds to a finite float32 (measurements are stored as float32).
inline bool FitsFloat(double v) { return std::isfinite(static_cast<float>(v)); }

// Parses a whole token as a finite double (decimal or scientific, optional leading '+').
// `what` names the quantity in the message ("ScatterRadial angle").
double ParseFiniteDouble(std::string_view token, const std::string& file, std::uint64_t line,
                         std::string_view what);

// Whitespace-separated tokens of a text, with line numbers. Lines whose first non-blank
// character is '#' are comments: they are collected (and must be valid UTF-8), never tokens.
class TokenStream {
 public:
  struct Token {
    std::string_view text;
    std::uint64_t line = 0;
  };

  TokenStream(std::string_view text, std::string file);

  const std::string& file() const { return file_; }
  // Line of the most recently returned token (or of the current position if none yet).
  std::uint64_t line() const { return line_of_last_; }
  // Bytes not yet consumed; bounds any count read from the file.
  std::size_t remaining_bytes() const { return text_.size() - pos_; }
  const std::vector<std::string>& comments() const { return comments_; }

  // True when only whitespace and comments remain.
  bool AtEnd();
  // The next token without consuming it; empty text at the end.
  Token Peek();
  // The next token; throws "expected <expected>, got end of file" at the end.
  Token Next(std::string_view expected);
  // Consumes the next token and requires it to equal `keyword` (case-insensitive).
  void Expect(std::string_view keyword);
  // The rest of the current line after the last token, trimmed; validated as UTF-8.
  std::string RestOfLine(std::string_view what);

  double NextDouble(std::string_view what);
  // A finite number within [min, max], or [min, max) when `max_open`.
  double NextInRange(std::string_view what, double min, double max, bool max_open = false);
  // A non-negative integer count in [min_count, max_count] that also fits in what is left
  // of the file at `bytes_per_item` bytes per item (an item needs at least a digit and a
  // separator, so 2 for one number).
  std::size_t NextCount(std::string_view what, std::size_t min_count, std::size_t max_count,
                        std::size_t bytes_per_item);

  [[noreturn]] void Fail(std::string_view expected, std::string_view got) const;
  [[noreturn]] void FailAt(std::uint64_t line, std::string_view expected,
                           std::string_view got) const;

 private:
  void SkipBlanksAndComments();

  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  std::uint64_t line_ = 1;          // line at pos_
  std::uint64_t line_of_last_ = 1;  // line of the last token returned
  std::vector<std::string> comments_;
};

// Iterates the lines of a text (LF or CRLF endings; a final line without newline counts).
class LineCursor {
 public:
  LineCursor(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}
  // Next line without its line ending; false at the end of the text.
  bool Next(std::string_view* line);
  std::uint64_t line_number() const { return line_; }  // of the line last returned
  const std::string& file() const { return file_; }
  [[noreturn]] void Fail(std::string_view expected, std::string_view got) const {
    detail::Fail(file_, line_, expected, got);
  }

 private:
  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  std::uint64_t line_ = 0;
};

// Splits a CSV line at commas (no quoting: the formats read here never quote) and trims
// blanks around each field. `out` is reused to avoid allocation per line.
void SplitCsvLine(std::string_view line, std::vector<std::string_view>* out);

std::string_view Trim(std::string_view s);

// Formats a double so that parsing it back gives the same double (shortest round-trip form).
std::string FormatShortest(double v);

}  // namespace brdf::detail
