#include "brdf/sources/detect.h"

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string_view>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/json_error.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"

namespace brdf::sources {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kMaxJsonBytes = 16u << 20;
// Each format's signature, from the format's own header.
template <std::size_t N>
bool StartsWith(std::string_view head, const std::array<std::uint8_t, N>& magic) {
  return head.size() >= N && std::memcmp(head.data(), magic.data(), N) == 0;
}

bool EndsWith(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string Lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

FileKind ClassifyJson(const std::string& path) {
  if (EndsWith(Lower(fs::path(path).filename().string()), kExtrapolationSuffix))
    return FileKind::kExtrapolation;
  const std::string text = ReadFileText(path, kMaxJsonBytes);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw JsonSyntaxError(path, text, e.byte);
  } catch (const nlohmann::json::out_of_range&) {
    throw JsonNumberTooLargeError(path, text);
  }
  if (!j.is_object()) return FileKind::kOtherJson;
  if (const auto kind = j.find("kind"); kind != j.end() && kind->is_string()) {
    if (*kind == "brdf-lut-sidecar") return FileKind::kSidecar;
    if (*kind == "brdf-atlas-manifest") return FileKind::kAtlasManifest;
  }
  if (j.contains("model")) return FileKind::kMaterial;
  return FileKind::kOtherJson;
}

}  // namespace

const char* FileKindName(FileKind kind) {
  switch (kind) {
    case FileKind::kCapture:
      return "capture (.bpc)";
    case FileKind::kMaterial:
      return "material file";
    case FileKind::kKtx2:
      return "KTX2 texture";
    case FileKind::kDds:
      return "DDS texture";
    case FileKind::kCompactLut:
      return "compact LUT (.brdfc)";
    case FileKind::kSidecar:
      return "LUT sidecar";
    case FileKind::kAtlasManifest:
      return "atlas manifest";
    case FileKind::kExtrapolation:
      return "extrapolation parameters";
    case FileKind::kOtherJson:
      return "JSON file of unknown purpose";
    case FileKind::kRgl:
      return "RGL .bsdf material";
    case FileKind::kMerl:
      return "MERL .binary material";
    case FileKind::kZemax:
      return "Zemax BSDF table";
    case FileKind::kLightTools:
      return "LightTools BSDF table";
    case FileKind::kCsv:
      return "CSV point cloud";
    case FileKind::kGonio:
      return "goniometer table";
    case FileKind::kUnknown:
      return "file of unknown type";
  }
  return "file";
}

FileKind DetectFileKind(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || status.type() == fs::file_type::not_found) throw IoError(path + ": no such file");
  if (status.type() != fs::file_type::regular) CheckRegularFile(path);  // names what it is
  const std::uint64_t size = fs::file_size(path, ec);
  if (ec) throw IoError(path + ": cannot read its size: " + ec.message());

  const std::string head = ReadDetectionHead(path);
  const std::string ext = Lower(fs::path(path).extension().string());

  // 1. Magic bytes.
  if (StartsWith(head, kBpcMagic)) return FileKind::kCapture;
  if (StartsWith(head, exporter::kKtx2Identifier)) return FileKind::kKtx2;
  if (StartsWith(head, exporter::kDdsMagic)) return FileKind::kDds;
  if (exporter::IsCompactLutFile(reinterpret_cast<const std::uint8_t*>(head.data()), head.size()))
    return FileKind::kCompactLut;
  const ImportFormat binary = DetectImportFormatFromHead(head, size, ext);
  if (binary == ImportFormat::kRgl || binary == ImportFormat::kMerl) return FileKindOf(binary);

  // 2. JSON.
  const std::size_t first = head.find_first_not_of(" \t\r\n");
  const bool json_text = first != std::string::npos && (head[first] == '{' || head[first] == '[');
  if (ext == ".json" || json_text) return ClassifyJson(path);

  // 3. A binary format's extension without its magic: that reader names the damage.
  if (ext == ".bpc") return FileKind::kCapture;
  if (ext == ".ktx2") return FileKind::kKtx2;
  if (ext == ".dds") return FileKind::kDds;
  if (ext == ".brdfc") return FileKind::kCompactLut;

  // 4. Text tables.
  return FileKindOf(binary);
}

std::optional<ImportFormat> ImportFormatOf(FileKind kind) {
  switch (kind) {
    case FileKind::kRgl:
      return ImportFormat::kRgl;
    case FileKind::kMerl:
      return ImportFormat::kMerl;
    case FileKind::kZemax:
      return ImportFormat::kZemax;
    case FileKind::kLightTools:
      return ImportFormat::kLightTools;
    case FileKind::kCsv:
      return ImportFormat::kCsv;
    case FileKind::kGonio:
      return ImportFormat::kGonio;
    default:
      return std::nullopt;
  }
}

FileKind FileKindOf(ImportFormat format) {
  switch (format) {
    case ImportFormat::kRgl:
      return FileKind::kRgl;
    case ImportFormat::kMerl:
      return FileKind::kMerl;
    case ImportFormat::kZemax:
      return FileKind::kZemax;
    case ImportFormat::kLightTools:
      return FileKind::kLightTools;
    case ImportFormat::kCsv:
      return FileKind::kCsv;
    case ImportFormat::kGonio:
      return FileKind::kGonio;
    case ImportFormat::kAuto:
      break;
  }
  return FileKind::kUnknown;
}

std::string OutputNameOf(const std::string& path) { return fs::path(path).stem().string(); }

std::string RecordedSourceName(const std::string& path) {
  return fs::path(path).filename().string();
}

}  // namespace brdf::sources
