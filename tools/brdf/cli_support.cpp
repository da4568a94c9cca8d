#include "cli_support.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"
#include "brdf/sources/capture.h"

namespace brdf::cli {

namespace fs = std::filesystem;

std::string RemedyText(const Remedy& remedy, const std::string& command) {
  const std::string& f = remedy.file;
  const std::string missing =
      remedy.theta_in_deg.empty()
          ? std::string()
          : " (it captures θin " + ShortNumberListText(remedy.theta_in_deg) + "°)";
  switch (remedy.kind) {
    case RemedyKind::kNone:
      return {};
    case RemedyKind::kResumeCapture:
      return "to continue the capture, rerun the 'brdf capture ... --out " + f +
             "' command that made it with --resume" + missing + "; it keeps the first " +
             std::to_string(remedy.valid_bytes) + " intact bytes";
    case RemedyKind::kRepairCapture:
      return "run 'brdf repair " + f +
             " --out FIXED.bpc' to keep every slice a LUT can use, then rerun the 'brdf capture' "
             "command with --out FIXED.bpc --resume" +
             missing;
    case RemedyKind::kRecapture:
      return "recapture the sample";
    case RemedyKind::kForceOverwrite:
      // An empty file: several outputs exist (the message names the first and counts the rest).
      return std::string("use --force to overwrite ") + (f.empty() ? "them" : "it");
    case RemedyKind::kAllowBtdf:
      return command == "import" ? "add --allow-btdf to store it mirrored into the reflection "
                                   "hemisphere; 'brdf info' reads it as it is"
                                 : "'brdf import --allow-btdf' stores it mirrored into the "
                                   "reflection hemisphere";
    case RemedyKind::kNameFormat:
      return command == "import" ? "name the format with --format"
                                 : "if you know its format, 'brdf import --format NAME' reads it";
    case RemedyKind::kCaptureEvaluable:
      return "'brdf import " + f +
             " --out FILE.bpc' captures it noise-free at the reference "
             "geometry; 'brdf eval' evaluates it directly";
    case RemedyKind::kEvaluateSingleLut:
      return "evaluate one material's own LUT (written by 'brdf convert')";
  }
  return {};
}

std::string ErrorLine(const std::exception& error, const std::string& command) {
  std::string line = error.what();
  if (const auto* e = dynamic_cast<const Error*>(&error)) {
    const std::string remedy = RemedyText(e->remedy(), command);
    if (!remedy.empty()) line += "; " + remedy;
  }
  return line;
}

processing::ExtrapolationParams ParseExtrapolationOption(const std::string& text) {
  try {
    return processing::ParseExtrapolation(text);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("--extrapolate: ") + e.what());
  }
}

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void CreateOutputFolder(const std::string& folder) {
  if (folder.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (!std::filesystem::is_directory(folder))
    throw IoError(folder + ": cannot create the output folder" +
                  (ec ? ": " + ec.message() : std::string()));
}

void CheckOutputPath(const std::string& out, const std::string& input, const char* extension,
                     bool force, const char* option, bool folders_created) {
  if (LowerExtension(out) != extension)
    throw InvalidArgument(std::string(option) + ": expected a file name ending in " + extension +
                          ", got '" + out + "'");
  std::error_code ec;
  if (fs::equivalent(out, input, ec))
    throw InvalidArgument(std::string(option) + ": '" + out + "' is the input file itself");
  ReportRemovedTemporaries(CheckWritableOutputs({out}, force, folders_created));
}

void ReportRemovedTemporaries(const std::vector<std::string>& removed) {
  if (removed.empty()) return;
  std::string list;
  for (const std::string& r : removed) list += (list.empty() ? "" : ", ") + r;
  std::fprintf(stderr, "note: removed %zu temporary file%s left by an interrupted run: %s\n",
               removed.size(), removed.size() == 1 ? "" : "s", list.c_str());
}

std::string JoinArguments(const std::vector<std::string>& arguments) {
  std::string joined;
  for (const std::string& a : arguments) joined += (joined.empty() ? "" : ", ") + a;
  return joined;
}

void WarnAboutVerdict(const std::string& out) {
  const sources::CaptureAssessment a = sources::AssessCapture(out);
  for (const sources::CaptureRefusal& refusal : a.refusals)
    std::fprintf(stderr, "brdf: warning: %s (every command that reads the capture refuses it)\n",
                 refusal.ToError(out).what());
  for (const sources::CaptureRefusal& refusal : a.export_refusals)
    std::fprintf(stderr,
                 "brdf: warning: %s; 'brdf convert' and 'brdf atlas' will refuse the capture "
                 "('brdf eval', 'brdf preview', 'brdf fit' and brdf-view accept it)\n",
                 refusal.ToError(out).what());
}

}  // namespace brdf::cli
