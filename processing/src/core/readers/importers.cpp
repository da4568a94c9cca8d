#include "brdf/core/importers.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "brdf/core/csv.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/gonio.h"
#include "brdf/core/lighttools.h"
#include "brdf/core/zemax.h"
#include "readers/rgl_internal.h"
#include "readers/text_util.h"

namespace brdf {
namespace {

constexpr std::uint64_t kMerlBytes = 12 + 3ull * 90 * 90 * 180 * 8;

struct Named {
  ImportFormat format;
  const char* name;
};
constexpr Named kNames[] = {
    {ImportFormat::kAuto, "auto"},   {ImportFormat::kRgl, "rgl"},
    {ImportFormat::kZemax, "zemax"}, {ImportFormat::kLightTools, "lighttools"},
    {ImportFormat::kMerl, "merl"},   {ImportFormat::kCsv, "csv"},
    {ImportFormat::kGonio, "gonio"}};

std::string Lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

bool HasToken(std::string_view head, std::string_view word) {
  // A whole-word, case-insensitive match at the start of a line or after blanks.
  const std::string h = Lower(std::string(head)), w = Lower(std::string(word));
  for (std::size_t pos = h.find(w); pos != std::string::npos; pos = h.find(w, pos + 1)) {
    const bool start_ok = pos == 0 || h[pos - 1] == ' ' || h[pos - 1] == '\t' ||
                          h[pos - 1] == '\n' || h[pos - 1] == '\r';
    const std::size_t end = pos + w.size();
    const bool end_ok =
        end == h.size() || h[end] == ' ' || h[end] == '\t' || h[end] == '\n' || h[end] == '\r';
    if (start_ok && end_ok) return true;
  }
  return false;
}

// First line of the text that is neither blank nor a '#' comment.
std::string_view FirstDataLine(std::string_view head) {
  detail::LineCursor lines(head, "");
  std::string_view line;
  while (lines.Next(&line)) {
    std::string_view t = detail::Trim(line);
    if (t.substr(0, 3) == "\xEF\xBB\xBF") t = detail::Trim(t.substr(3));
    if (!t.empty() && t.front() != '#') return t;
  }
  return {};
}

}  // namespace

std::string ImportFormatName(ImportFormat format) {
  for (const Named& n : kNames)
    if (n.format == format) return n.name;
  return "unknown";
}

ImportFormat ImportFormatFromName(std::string_view name) {
  for (const Named& n : kNames)
    if (detail::EqualsIgnoreCase(name, n.name)) return n.format;
  throw InvalidArgument("unknown import format '" + std::string(name) +
                        "' (known: auto, rgl, zemax, lighttools, merl, csv, gonio)");
}

ImportFormat DetectImportFormatFromHead(std::string_view head, std::uint64_t file_size,
                                        std::string_view extension) {
  const std::string ext = Lower(std::string(extension));
  if (head.size() >= 12 && std::memcmp(head.data(), kTensorFileMagic, sizeof kTensorFileMagic) == 0)
    return ImportFormat::kRgl;
  if (ext == ".binary") return ImportFormat::kMerl;
  if (file_size == kMerlBytes && head.size() >= 12) {
    const unsigned char* p = reinterpret_cast<const unsigned char*>(head.data());
    const auto i32 = [&](int k) {
      return static_cast<std::uint32_t>(p[4 * k]) |
             (static_cast<std::uint32_t>(p[4 * k + 1]) << 8) |
             (static_cast<std::uint32_t>(p[4 * k + 2]) << 16) |
             (static_cast<std::uint32_t>(p[4 * k + 3]) << 24);
    };
    if (i32(0) == 90 && i32(1) == 90 && i32(2) == 180) return ImportFormat::kMerl;
  }
  if (HasToken(head, "AngleOfIncidence") || HasToken(head, "SampleRotation"))
    return ImportFormat::kZemax;
  if ((HasToken(head, "ScatterAzimuth") || HasToken(head, "ScatterRadial")) &&
      (HasToken(head, "AOI") || HasToken(head, "DataBegin")))
    return ImportFormat::kLightTools;
  const std::string first = Lower(std::string(FirstDataLine(head)));
  std::vector<std::string_view> fields;
  detail::SplitCsvLine(first, &fields);
  if (fields.size() >= 2 && fields[0] == "incident_angle" && fields[1] == "measure_angle")
    return ImportFormat::kGonio;
  bool theta_in = false, theta_out = false;
  for (std::string_view fld : fields) {
    theta_in = theta_in || fld == "theta_in" || fld == "theta_in_deg";
    theta_out = theta_out || fld == "theta_out" || fld == "theta_out_deg";
  }
  if (theta_in && theta_out) return ImportFormat::kCsv;
  return ImportFormat::kAuto;
}

std::string ReadDetectionHead(const std::string& path) {
  return ReadFileHead(path, kImportDetectionBytes);  // refuses FIFOs and folders, never blocks
}

ImportFormat DetectImportFormat(const std::string& path) {
  const std::string head = ReadDetectionHead(path);
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  const std::string ext = Lower(std::filesystem::path(path).extension().string());
  const ImportFormat format = DetectImportFormatFromHead(head, ec ? 0 : size, ext);
  if (format != ImportFormat::kAuto) return format;
  throw FormatError(path, "file content",
                    "a known measurement format (RGL .bsdf, Zemax or LightTools BSDF text, MERL "
                    ".binary, CSV point cloud, goniometer table)",
                    "none recognised (extension '" + ext + "')", {},
                    Remedy{RemedyKind::kNameFormat, path});
}

Measurement ImportFile(const std::string& path, ImportFormat format, const ImportOptions& options) {
  if (format == ImportFormat::kAuto) format = DetectImportFormat(path);
  switch (format) {
    case ImportFormat::kZemax:
      return LoadZemaxBsdf(path, ZemaxImportOptions{options.allow_btdf});
    case ImportFormat::kLightTools:
      return LoadLightToolsBsdf(path, LightToolsImportOptions{options.allow_btdf});
    case ImportFormat::kCsv:
      return ReadCsv(path);
    case ImportFormat::kGonio:
      return LoadGonioTable(path);
    case ImportFormat::kRgl:
    case ImportFormat::kMerl:
      // Evaluable formats need a virtual capture (brdf/core/virtual_capture.h), which the
      // caller chooses the geometry of.
      throw InvalidArgument(
          path + ": " + ImportFormatName(format) + " files are evaluable BRDFs, not point clouds",
          Remedy{RemedyKind::kCaptureEvaluable, path});
    case ImportFormat::kAuto:
      break;
  }
  throw InvalidArgument(path + ": no reader for format " + ImportFormatName(format));
}

}  // namespace brdf
