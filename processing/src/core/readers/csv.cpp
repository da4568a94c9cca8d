#include "brdf/core/csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "readers/text_util.h"

namespace brdf {
namespace {

enum Column {
  kThetaIn,
  kPhiIn,
  kThetaOut,
  kPhiOut,
  kR,
  kG,
  kB,
  kSigmaR,
  kSigmaG,
  kSigmaB,
  kFlags,
  kColumnCount
};
constexpr const char* kColumnNames[kColumnCount] = {"theta_in", "phi_in",  "theta_out", "phi_out",
                                                    "r",        "g",       "b",         "sigma_r",
                                                    "sigma_g",  "sigma_b", "flags"};

int ColumnOf(std::string_view name) {
  for (int c = 0; c < kColumnCount; ++c) {
    const std::string_view known = kColumnNames[c];
    if (detail::EqualsIgnoreCase(name, known)) return c;
    if (c <= kPhiOut && name.size() == known.size() + 4 &&
        detail::EqualsIgnoreCase(name.substr(0, known.size()), known) &&
        detail::EqualsIgnoreCase(name.substr(known.size()), "_deg"))
      return c;
  }
  return -1;
}

std::string Escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else {
      out += c;
    }
  }
  return out;
}

std::string Unescape(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) {
      const char n = s[++i];
      out += n == 'n' ? '\n' : n == 'r' ? '\r' : n;
    } else {
      out += s[i];
    }
  }
  return out;
}

void SetMetadata(Metadata& md, const std::string& key, std::string value) {
  std::string* fields[] = {&md.sample_name,
                           &md.instrument_model,
                           &md.instrument_serial,
                           &md.firmware_version,
                           &md.protocol_version,
                           &md.calibration_reference,
                           &md.calibration_time,
                           &md.capture_start,
                           &md.capture_end,
                           &md.operator_notes,
                           &md.units,
                           &md.software_version};
  static const char* kNames[] = {"sample_name",
                                 "instrument_model",
                                 "instrument_serial",
                                 "firmware_version",
                                 "protocol_version",
                                 "calibration_reference",
                                 "calibration_time",
                                 "capture_start",
                                 "capture_end",
                                 "operator_notes",
                                 "units",
                                 "software_version"};
  for (std::size_t i = 0; i < std::size(kNames); ++i) {
    if (key == kNames[i]) {
      *fields[i] = std::move(value);
      return;
    }
  }
  if (key.rfind("extra.", 0) == 0) {
    md.extra[key.substr(6)] = std::move(value);
  } else {
    md.extra[key] = std::move(value);
  }
}

void AppendFloat(std::string& out, float v) {
  char buf[32];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? ptr : buf);
}

}  // namespace

Measurement ParseCsv(std::string_view text_in, const std::string& file) {
  detail::LineCursor lines(text_in, file);
  Measurement m;
  std::string_view line;
  std::vector<std::string_view> fields;
  std::vector<std::pair<double, double>> incomplete;
  // Comments and metadata, then the header.
  bool have_header = false;
  std::array<int, kColumnCount> index;
  index.fill(-1);
  std::size_t field_count = 0;
  while (lines.Next(&line)) {
    if (lines.line_number() == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
    const std::string_view t = detail::Trim(line);
    if (t.empty()) continue;
    if (!detail::IsValidUtf8(t)) lines.Fail("UTF-8 text", detail::Printable(t));
    if (t.front() == '#') {
      const std::string_view body = detail::Trim(t.substr(1));
      const std::size_t eq = body.find('=');
      if (eq == std::string_view::npos || eq == 0) continue;  // a plain comment
      const std::string key(detail::Trim(body.substr(0, eq)));
      const std::string value = Unescape(detail::Trim(body.substr(eq + 1)));
      if (key == "incomplete_slice") {
        detail::SplitCsvLine(value, &fields);
        if (fields.size() != 2)
          lines.Fail("incomplete_slice=<theta_in>,<phi_in>", detail::Printable(value));
        incomplete.emplace_back(detail::ParseFiniteDouble(fields[0], file, lines.line_number(),
                                                          "incomplete_slice theta_in"),
                                detail::ParseFiniteDouble(fields[1], file, lines.line_number(),
                                                          "incomplete_slice phi_in"));
      } else if (key.find(' ') == std::string::npos) {
        SetMetadata(m.metadata, key, value);
      }
      continue;
    }
    detail::SplitCsvLine(t, &fields);
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const int c = ColumnOf(fields[i]);
      if (c < 0) {
        lines.Fail(
            "a header of known column names (theta_in, phi_in, theta_out, phi_out, r, g, "
            "b, sigma_r, sigma_g, sigma_b, flags)",
            "column " + std::to_string(i + 1) + " " + detail::Printable(fields[i]));
      }
      if (index[c] >= 0) lines.Fail("each column once", "a second " + detail::Printable(fields[i]));
      index[c] = static_cast<int>(i);
    }
    for (int c = kThetaIn; c <= kB; ++c) {
      if (index[c] < 0)
        lines.Fail(std::string("a header with a ") + kColumnNames[c] + " column",
                   detail::Printable(t));
    }
    const int sigmas = (index[kSigmaR] >= 0) + (index[kSigmaG] >= 0) + (index[kSigmaB] >= 0);
    if (sigmas != 0 && sigmas != 3)
      lines.Fail("all three of sigma_r, sigma_g, sigma_b or none",
                 std::to_string(sigmas) + " of them");
    field_count = fields.size();
    have_header = true;
    break;
  }
  if (!have_header)
    detail::Fail(file, lines.line_number() + 1,
                 "a header line 'theta_in,phi_in,theta_out,phi_out,r,g,b'", "end of file");
  const bool has_sigma = index[kSigmaR] >= 0;

  std::map<std::pair<float, float>, std::size_t> slice_of;
  std::vector<Slice> slices;
  while (lines.Next(&line)) {
    const std::string_view t = detail::Trim(line);
    if (t.empty()) continue;
    if (t.front() == '#') continue;
    detail::SplitCsvLine(t, &fields);
    const std::uint64_t ln = lines.line_number();
    if (fields.size() != field_count)
      lines.Fail(std::to_string(field_count) + " comma-separated fields",
                 std::to_string(fields.size()) + " fields");
    const auto number = [&](int c) {
      return detail::ParseFiniteDouble(fields[index[c]], file, ln, kColumnNames[c]);
    };
    const auto in_range = [&](int c, double lo, double hi, bool hi_open) {
      const double v = number(c);
      if (v < lo || v > hi || (hi_open && v == hi)) {
        lines.Fail(std::string(kColumnNames[c]) + " in [" + detail::FormatShortest(lo) + ", " +
                       detail::FormatShortest(hi) + (hi_open ? ")" : "]"),
                   detail::Printable(fields[index[c]]));
      }
      return v;
    };
    Sample s;
    s.theta_in_deg = static_cast<float>(in_range(kThetaIn, 0, 90, true));
    s.phi_in_deg = static_cast<float>(WrapDeg360(in_range(kPhiIn, -360, 360, false)));
    s.theta_out_deg = static_cast<float>(in_range(kThetaOut, 0, 90, false));
    s.phi_out_deg = static_cast<float>(WrapDeg360(in_range(kPhiOut, -360, 360, false)));
    if (s.phi_in_deg >= 360.0f) s.phi_in_deg = 0.0f;
    if (s.phi_out_deg >= 360.0f) s.phi_out_deg = 0.0f;
    for (int c = 0; c < 3; ++c) s.rgb[c] = static_cast<float>(number(kR + c));
    if (has_sigma) {
      for (int c = 0; c < 3; ++c) {
        const double v = number(kSigmaR + c);
        if (v < 0)
          lines.Fail(std::string("a non-negative ") + kColumnNames[kSigmaR + c],
                     detail::Printable(fields[index[kSigmaR + c]]));
        s.sigma[c] = static_cast<float>(v);
      }
    }
    if (index[kFlags] >= 0) {
      const std::string_view f = fields[index[kFlags]];
      unsigned v = 0;
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (ec != std::errc() || ptr != f.data() + f.size() || v > kKnownSampleFlags)
        lines.Fail("flags as a whole number in [0, 15]", detail::Printable(f));
      s.flags = static_cast<std::uint8_t>(v);
    }
    const auto key = std::make_pair(s.theta_in_deg, s.phi_in_deg);
    auto it = slice_of.find(key);
    if (it == slice_of.end()) {
      it = slice_of.emplace(key, slices.size()).first;
      Slice slice;
      slice.theta_in_deg = s.theta_in_deg;
      slice.phi_in_deg = s.phi_in_deg;
      slice.has_sigma = has_sigma;
      slices.push_back(std::move(slice));
    }
    slices[it->second].samples.push_back(s);
  }
  if (slices.empty())
    detail::Fail(file, lines.line_number() + 1, "at least one data row after the header",
                 "end of file");
  for (const auto& [theta, phi] : incomplete) {
    const auto it = slice_of.find({static_cast<float>(theta), static_cast<float>(phi)});
    if (it != slice_of.end()) slices[it->second].complete = false;
  }
  std::stable_sort(slices.begin(), slices.end(), [](const Slice& a, const Slice& b) {
    return a.theta_in_deg != b.theta_in_deg ? a.theta_in_deg < b.theta_in_deg
                                            : a.phi_in_deg < b.phi_in_deg;
  });
  m.slices = std::move(slices);
  return m;
}

Measurement ReadCsv(const std::string& path) {
  return ParseCsv(detail::ReadTextFile(path, detail::kMaxCsvBytes), path);
}

std::string FormatCsv(const Measurement& m) {
  bool has_sigma = false;
  for (const Slice& s : m.slices) has_sigma = has_sigma || s.has_sigma;
  std::string out =
      "# brdf-toolchain point cloud: f_r in 1/sr, linear Rec.709, angles in degrees\n";
  const Metadata& md = m.metadata;
  const std::pair<const char*, const std::string*> fields[] = {
      {"sample_name", &md.sample_name},
      {"instrument_model", &md.instrument_model},
      {"instrument_serial", &md.instrument_serial},
      {"firmware_version", &md.firmware_version},
      {"protocol_version", &md.protocol_version},
      {"calibration_reference", &md.calibration_reference},
      {"calibration_time", &md.calibration_time},
      {"capture_start", &md.capture_start},
      {"capture_end", &md.capture_end},
      {"operator_notes", &md.operator_notes},
      {"units", &md.units},
      {"software_version", &md.software_version}};
  for (const auto& [name, value] : fields) {
    if (!value->empty()) out += std::string("# ") + name + "=" + Escape(*value) + "\n";
  }
  for (const auto& [key, value] : md.extra)
    out += "# extra." + Escape(key) + "=" + Escape(value) + "\n";
  for (const Slice& s : m.slices) {
    if (!s.complete) {
      out += "# incomplete_slice=";
      AppendFloat(out, static_cast<float>(s.theta_in_deg));
      out += ",";
      AppendFloat(out, static_cast<float>(s.phi_in_deg));
      out += "\n";
    }
  }
  out += has_sigma ? "theta_in,phi_in,theta_out,phi_out,r,g,b,sigma_r,sigma_g,sigma_b,flags\n"
                   : "theta_in,phi_in,theta_out,phi_out,r,g,b,flags\n";
  out.reserve(out.size() + m.SampleCount() * (has_sigma ? 120 : 80));
  for (const Slice& s : m.slices) {
    for (const Sample& smp : s.samples) {
      AppendFloat(out, smp.theta_in_deg);
      out += ',';
      AppendFloat(out, smp.phi_in_deg);
      out += ',';
      AppendFloat(out, smp.theta_out_deg);
      out += ',';
      AppendFloat(out, smp.phi_out_deg);
      for (int c = 0; c < 3; ++c) {
        out += ',';
        AppendFloat(out, smp.rgb[c]);
      }
      if (has_sigma) {
        for (int c = 0; c < 3; ++c) {
          out += ',';
          AppendFloat(out, s.has_sigma ? smp.sigma[c] : 0.0f);
        }
      }
      out += ',';
      out += std::to_string(smp.flags);
      out += '\n';
    }
  }
  return out;
}

void WriteCsv(const std::string& path, const Measurement& m) {
  WriteFileAtomically(path, FormatCsv(m));
}

}  // namespace brdf
