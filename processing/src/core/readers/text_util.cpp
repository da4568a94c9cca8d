#include "readers/text_util.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"

namespace brdf::detail {

std::string ReadTextFile(const std::string& path, std::uint64_t max_bytes) {
  return ReadFileText(path, max_bytes);
}

namespace {

// Length of the valid UTF-8 sequence starting at s[i], or 0 if it is not valid (overlong
// forms, surrogates and code points above U+10FFFF are invalid, per RFC 3629).
std::size_t Utf8SequenceLength(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return 1;
  std::size_t n;
  std::uint32_t cp;
  if ((c & 0xE0) == 0xC0) {
    n = 2;
    cp = c & 0x1F;
  } else if ((c & 0xF0) == 0xE0) {
    n = 3;
    cp = c & 0x0F;
  } else if ((c & 0xF8) == 0xF0) {
    n = 4;
    cp = c & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3F);
  }
  static constexpr std::uint32_t kMin[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

}  // namespace

bool IsValidUtf8(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = Utf8SequenceLength(s, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::string Printable(std::string_view s) {
  constexpr std::size_t kMaxChars = 40;
  std::string out = "'";
  std::size_t chars = 0;
  for (std::size_t i = 0; i < s.size();) {
    if (chars == kMaxChars) {
      out += "...";
      break;
    }
    const std::size_t n = Utf8SequenceLength(s, i);
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (n == 0 || (n == 1 && (c < 0x20 || c == 0x7F))) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
      i += 1;
    } else {
      out.append(s.substr(i, n));
      i += n;
    }
    ++chars;
  }
  out += "'";
  return out;
}

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

void Fail(const std::string& file, std::uint64_t line, std::string_view expected,
          std::string_view got) {
  throw FormatError(file, LinePosition(line), std::string(expected), std::string(got));
}

double ParseFiniteDouble(std::string_view token, const std::string& file, std::uint64_t line,
                         std::string_view what) {
  std::string_view t = token;
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  double v = 0;
  const char* first = t.data();
  const char* last = t.data() + t.size();
  const auto [ptr, ec] = std::from_chars(first, last, v, std::chars_format::general);
  if (t.empty() || ec == std::errc::invalid_argument || ptr != last)
    Fail(file, line, std::string(what) + " (a number)", Printable(token));
  if (ec == std::errc::result_out_of_range || !std::isfinite(v))
    Fail(file, line, std::string(what) + " (a finite number)", Printable(token));
  // Measurements are stored as float32: a finite double beyond its range would become inf
  // and the capture could not be written back (found by csv_fuzzer).
  if (!FitsFloat(v))
    Fail(file, line, std::string(what) + " (a number within the float32 range, |v| <= 3.4e38)",
         Printable(token));
  return v;
}

TokenStream::TokenStream(std::string_view text, std::string file)
    : text_(text), file_(std::move(file)) {}

void TokenStream::SkipBlanksAndComments() {
  bool at_line_start = pos_ == 0 || text_[pos_ - 1] == '\n';
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
      at_line_start = true;
    } else if (IsBlank(c)) {
      ++pos_;
    } else if (c == '#' && at_line_start) {
      const std::size_t end = text_.find('\n', pos_);
      std::string_view comment =
          text_.substr(pos_ + 1, (end == std::string_view::npos ? text_.size() : end) - pos_ - 1);
      comment = Trim(comment);
      if (!IsValidUtf8(comment)) detail::Fail(file_, line_, "a UTF-8 comment", Printable(comment));
      comments_.emplace_back(comment);
      pos_ = end == std::string_view::npos ? text_.size() : end;
    } else {
      return;
    }
  }
}

bool TokenStream::AtEnd() {
  SkipBlanksAndComments();
  return pos_ >= text_.size();
}

TokenStream::Token TokenStream::Peek() {
  SkipBlanksAndComments();
  std::size_t end = pos_;
  while (end < text_.size() && !IsBlank(text_[end]) && text_[end] != '\n') ++end;
  return {text_.substr(pos_, end - pos_), line_};
}

TokenStream::Token TokenStream::Next(std::string_view expected) {
  const Token t = Peek();
  if (t.text.empty()) detail::Fail(file_, line_, expected, "end of file");
  pos_ += t.text.size();
  line_of_last_ = t.line;
  return t;
}

void TokenStream::Expect(std::string_view keyword) {
  const Token t = Next(keyword);
  if (!EqualsIgnoreCase(t.text, keyword)) FailAt(t.line, keyword, Printable(t.text));
}

std::string TokenStream::RestOfLine(std::string_view what) {
  const std::size_t end = text_.find('\n', pos_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  const std::string_view rest = Trim(text_.substr(pos_, stop - pos_));
  if (!IsValidUtf8(rest)) FailAt(line_, std::string(what) + " as UTF-8 text", Printable(rest));
  pos_ = stop;
  return std::string(rest);
}

double TokenStream::NextDouble(std::string_view what) {
  const Token t = Next(what);
  return ParseFiniteDouble(t.text, file_, t.line, what);
}

double TokenStream::NextInRange(std::string_view what, double min, double max, bool max_open) {
  const Token t = Next(what);
  const double v = ParseFiniteDouble(t.text, file_, t.line, what);
  if (v < min || v > max || (max_open && v == max)) {
    FailAt(t.line,
           std::string(what) + " in [" + FormatShortest(min) + ", " + FormatShortest(max) +
               (max_open ? ")" : "]"),
           Printable(t.text));
  }
  return v;
}

std::size_t TokenStream::NextCount(std::string_view what, std::size_t min_count,
                                   std::size_t max_count, std::size_t bytes_per_item) {
  const Token t = Next(what);
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
  if (ec != std::errc() || ptr != t.text.data() + t.text.size()) {
    if (!t.text.empty() && t.text.front() == '-')
      FailAt(t.line, std::string(what) + " (a non-negative count)", Printable(t.text));
    FailAt(t.line, std::string(what) + " (a whole number)", Printable(t.text));
  }
  if (v < min_count || v > max_count) {
    FailAt(t.line,
           std::string(what) + " between " + std::to_string(min_count) + " and " +
               std::to_string(max_count),
           Printable(t.text));
  }
  const std::uint64_t room = remaining_bytes() / std::max<std::size_t>(bytes_per_item, 1) + 1;
  if (v > room) {
    FailAt(t.line,
           std::string(what) + " that the rest of the file can hold (at most " +
               std::to_string(room) + ")",
           Printable(t.text));
  }
  return static_cast<std::size_t>(v);
}

void TokenStream::Fail(std::string_view expected, std::string_view got) const {
  detail::Fail(file_, line_of_last_, expected, got);
}

void TokenStream::FailAt(std::uint64_t line, std::string_view expected,
                         std::string_view got) const {
  detail::Fail(file_, line, expected, got);
}

bool LineCursor::Next(std::string_view* line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t end = text_.find('\n', pos_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  std::string_view l = text_.substr(pos_, stop - pos_);
  if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
  pos_ = end == std::string_view::npos ? text_.size() : end + 1;
  ++line_;
  *line = l;
  return true;
}

void SplitCsvLine(std::string_view line, std::vector<std::string_view>* out) {
  out->clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      out->push_back(Trim(line.substr(start)));
      return;
    }
    out->push_back(Trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (IsBlank(s.front()) || s.front() == '\n')) s.remove_prefix(1);
  while (!s.empty() && (IsBlank(s.back()) || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

std::string FormatShortest(double v) {
  char buf[32];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, ptr) : std::to_string(v);
}

}  // namespace brdf::detail
