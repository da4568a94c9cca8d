#include "sources.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/importers.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/processing/measurement_brdf.h"
#include "cli_support.h"

namespace brdf::cli {

namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kMaxJsonBytes = 16u << 20;
constexpr const char* kExtrapolationSuffix = ".extrapolate.json";

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string Deg(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string DegList(const std::vector<double>& values) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : ", ") + Deg(v);
  return out;
}

bool ContainsAngle(const std::vector<double>& values, double v) {
  return std::any_of(values.begin(), values.end(),
                     [v](double x) { return std::fabs(x - v) <= 1e-3; });
}

// The planned θin list of a capture: its metadata's extra "theta_in_deg" if recorded, else the
// reference instrument's.
std::vector<double> PlannedThetaIn(const Measurement& m, const std::string& path) {
  const auto it = m.metadata.extra.find("theta_in_deg");
  if (it == m.metadata.extra.end()) return CaptureGeometry{}.theta_in_deg;
  std::vector<double> planned;
  std::string text = it->second;
  std::replace(text.begin(), text.end(), ',', ' ');
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    try {
      std::size_t used = 0;
      planned.push_back(std::stod(token, &used));
      if (used != token.size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw FormatError(path, "metadata extra 'theta_in_deg'",
                        "a list of angles in degrees such as \"0, 20, 40, 60\"",
                        "'" + it->second + "'");
    }
  }
  if (planned.empty())
    throw FormatError(path, "metadata extra 'theta_in_deg'", "at least one angle", "an empty list");
  return planned;
}

std::string CaptureCommandHint(const std::string& path) {
  return "to continue the capture, rerun the same 'brdf capture ... --out " + path +
         "' command with --resume";
}

}  // namespace

const char* FileKindName(FileKind kind) {
  switch (kind) {
    case FileKind::kCapture:
      return "capture (.bpc)";
    case FileKind::kMaterial:
      return "material file";
    case FileKind::kTexture:
      return "exported texture";
    case FileKind::kSidecar:
      return "LUT sidecar";
    case FileKind::kAtlasManifest:
      return "atlas manifest";
    case FileKind::kExtrapolation:
      return "extrapolation parameters";
    case FileKind::kOtherJson:
      return "JSON file of unknown purpose";
    case FileKind::kUnknown:
      return "file of unknown type";
  }
  return "file";
}

FileKind ClassifyFile(const std::string& path) {
  const std::string ext = LowerExtension(path);
  if (ext == ".bpc") return FileKind::kCapture;
  if (ext == ".ktx2" || ext == ".dds") return FileKind::kTexture;
  if (ext != ".json") return FileKind::kUnknown;
  if (EndsWith(fs::path(path).filename().string(), kExtrapolationSuffix))
    return FileKind::kExtrapolation;
  const std::string text = ReadFileText(path, kMaxJsonBytes);
  const auto j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded())
    throw FormatError(path, "JSON text", "valid JSON (a material file or an export sidecar)",
                      "text that does not parse as JSON");
  if (!j.is_object()) return FileKind::kOtherJson;
  if (const auto kind = j.find("kind"); kind != j.end() && kind->is_string()) {
    if (*kind == "brdf-lut-sidecar") return FileKind::kSidecar;
    if (*kind == "brdf-atlas-manifest") return FileKind::kAtlasManifest;
  }
  if (j.contains("model")) return FileKind::kMaterial;
  return FileKind::kOtherJson;
}

std::string OutputNameOf(const std::string& path) { return fs::path(path).stem().string(); }

Measurement CaptureMaterialNoiseFree(const Material& material, const std::string& source,
                                     const CaptureGeometry& geometry) {
  Measurement m;
  m.metadata.sample_name = material.name.empty() ? OutputNameOf(source) : material.name;
  m.metadata.instrument_model = "noise-free evaluation of an analytic material";
  m.metadata.capture_start = m.metadata.capture_end = UtcNowIso8601();
  m.metadata.software_version = SoftwareVersion();
  m.metadata.extra["material_file"] = source;
  m.metadata.extra["model"] = std::string(ModelName(material.model));
  for (double theta_in : geometry.theta_in_deg) {
    Slice slice;
    slice.theta_in_deg = theta_in;
    const Vec3 wi = SphericalDirectionDeg(theta_in, 0.0);
    slice.samples.reserve(static_cast<std::size_t>(geometry.theta_out_max_deg + 1) *
                          static_cast<std::size_t>(geometry.phi_out_count));
    for (int t = 0; t <= geometry.theta_out_max_deg; ++t) {
      for (int p = 0; p < geometry.phi_out_count; ++p) {
        const double phi = 360.0 * p / geometry.phi_out_count;
        const Rgb f = material.Evaluate(wi, SphericalDirectionDeg(t, phi));
        Sample s;
        s.theta_in_deg = static_cast<float>(theta_in);
        s.theta_out_deg = static_cast<float>(t);
        s.phi_out_deg = static_cast<float>(phi);
        s.rgb = {static_cast<float>(f[0]), static_cast<float>(f[1]), static_cast<float>(f[2])};
        slice.samples.push_back(s);
      }
    }
    m.slices.push_back(std::move(slice));
  }
  return m;
}

Measurement LoadCaptureForLut(const std::string& path, std::vector<std::string>* warnings) {
  BpcReadResult r = ReadBpc(path);
  const std::string intact = std::to_string(r.measurement.slices.size()) + " intact slice" +
                             (r.measurement.slices.size() == 1 ? "" : "s");
  bool tail_cut_outside_slices = false;
  for (const BpcProblem& p : r.problems) {
    if (p.kind == BpcProblemKind::kCorrupt) {
      const std::string advice =
          r.intact_data_after_damage
              ? "intact slices follow the damaged chunk, so a resume cannot repair it; "
                "recapture the material or rewrite its intact slices to a new file"
              : "recapture the damaged slice: cut the file back to its " +
                    std::to_string(r.valid_bytes) + " intact bytes with " +
                    CaptureCommandHint(path);
      throw FormatError(path,
                        BytePosition(p.offset) +
                            (p.slice_index >= 0 ? " (slice " + std::to_string(p.slice_index) + ")"
                                                : std::string()),
                        p.expected, p.got,
                        "corrupt chunk; a LUT needs every slice intact; " + intact + "; " + advice);
    }
    if (p.kind == BpcProblemKind::kTruncated) {
      if (p.slice_index >= 0)
        throw FormatError(
            path, BytePosition(p.offset) + " (slice " + std::to_string(p.slice_index) + ")",
            p.expected, p.got,
            "the capture was interrupted inside slice " + std::to_string(p.slice_index) +
                "; a LUT needs every slice; " + intact + " end at byte " +
                std::to_string(r.valid_bytes) + "; " + CaptureCommandHint(path));
      tail_cut_outside_slices = true;
    }
  }
  for (const Slice& s : r.measurement.slices)
    if (!s.complete)
      throw FormatError(path, "slice θin " + Deg(s.theta_in_deg) + "°", "a complete slice",
                        "a slice the instrument stopped before finishing (" +
                            std::to_string(s.samples.size()) + " samples)",
                        "a LUT needs every slice complete; recapture it");
  if (!r.finished) {
    const std::vector<double> planned = PlannedThetaIn(r.measurement, path);
    const std::vector<double> present = r.measurement.ThetaInDeg();
    std::vector<double> missing;
    for (double t : planned)
      if (!ContainsAngle(present, t)) missing.push_back(t);
    if (!missing.empty())
      throw FormatError(path, BytePosition(r.valid_bytes),
                        "slices for every planned θin (" + DegList(planned) + "°)",
                        "the end of an unfinished capture with θin " +
                            (present.empty() ? std::string("none") : DegList(present) + "°") +
                            " only (missing " + DegList(missing) + "°)",
                        CaptureCommandHint(path));
    if (warnings)
      warnings->push_back(
          path + ": warning: no intact end chunk (" +
          (tail_cut_outside_slices
               ? "the file is cut after the last slice, at byte " + std::to_string(r.valid_bytes)
               : std::string("the capture was never finalised")) +
          "), but all " + std::to_string(planned.size()) + " planned slices (θin " +
          DegList(planned) + "°) are intact: converting them");
  }
  for (const BpcProblem& p : r.problems)
    if (p.kind == BpcProblemKind::kTrailingData && warnings)
      warnings->push_back(path + ": warning: " + std::to_string(p.size) +
                          " unexpected bytes after the end chunk at byte " +
                          std::to_string(p.offset) + " were ignored");
  return std::move(r.measurement);
}

ExtrapolationChoice ChooseExtrapolation(
    const std::string& input_path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line,
    std::vector<std::string>* warnings) {
  fs::path beside(input_path);
  beside.replace_filename(OutputNameOf(input_path) + kExtrapolationSuffix);
  std::optional<ExtrapolationChoice> own;
  if (kind == FileKind::kMaterial) {
    if (auto p =
            processing::ExtrapolationFromJson(ReadFileText(input_path, kMaxJsonBytes), input_path))
      own = ExtrapolationChoice{*p, input_path + " (its \"extrapolate\" member)"};
  }
  std::error_code ec;
  if (fs::is_regular_file(beside, ec)) {
    ExtrapolationChoice choice{processing::LoadExtrapolationJson(beside.string()), beside.string()};
    if (own && !(own->params == choice.params) && warnings)
      warnings->push_back(input_path + ": warning: " + beside.string() +
                          " (p,l = " + processing::FormatExtrapolation(choice.params) +
                          ") overrides the material's own \"extrapolate\" (" +
                          processing::FormatExtrapolation(own->params) + ")");
    return choice;
  }
  if (own) return *own;
  if (command_line) return {*command_line, "--extrapolate"};
  return {processing::ExtrapolationParams{}, "defaults"};
}

PreparedMeasurement PrepareMeasurement(
    const std::string& path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line) {
  PreparedMeasurement out;
  if (kind == FileKind::kCapture) {
    out.measurement = LoadCaptureForLut(path, &out.warnings);
  } else if (kind == FileKind::kMaterial) {
    out.measurement = CaptureMaterialNoiseFree(LoadMaterialFile(path), path);
  } else {
    throw InvalidArgument(path + ": expected a capture (.bpc) or a material file, got a " +
                          FileKindName(kind));
  }
  out.extrapolation = ChooseExtrapolation(path, kind, command_line, &out.warnings);
  return out;
}

OpenedTexture OpenExportedTexture(const std::string& path) {
  OpenedTexture out;
  const FileKind kind = ClassifyFile(path);
  if (kind == FileKind::kSidecar || kind == FileKind::kAtlasManifest) {
    out.sidecar_path = path;
    const fs::path folder = fs::path(path).parent_path();
    // What the JSON records about its texture, and where the texture may be.
    int width = 0, height = 0, depth = 0;
    std::uint64_t bytes = 0;
    std::uint32_t crc = 0;
    std::vector<double> theta_in_deg;
    std::vector<std::string> candidates;
    if (kind == FileKind::kSidecar) {
      out.sidecar = exporter::ReadSidecar(path);
      const exporter::SidecarInfo& s = *out.sidecar;
      width = s.width, height = s.height, depth = s.slices;
      bytes = s.payload_bytes, crc = s.payload_crc32, theta_in_deg = s.theta_in_deg;
      for (const char* ext : {".ktx2", ".dds"})
        for (const std::string& f : s.files)
          if (LowerExtension(f) == ext) candidates.push_back((folder / f).string());
    } else {
      out.manifest = exporter::ParseAtlasManifest(ReadFileText(path, kMaxJsonBytes), path);
      const exporter::AtlasManifest& m = *out.manifest;
      width = m.texture_width, height = m.texture_height;
      depth = static_cast<int>(m.theta_in_deg.size());
      bytes = m.payload_bytes, crc = m.payload_crc32, theta_in_deg = m.theta_in_deg;
      for (const char* ext : {".ktx2", ".dds"})
        candidates.push_back((folder / (OutputNameOf(path) + ext)).string());
    }
    std::error_code ec;
    for (const std::string& c : candidates) {
      if (!fs::is_regular_file(c, ec)) continue;
      out.texture_path = c;
      break;
    }
    if (out.texture_path.empty()) {
      std::string list;
      for (const auto& c : candidates) list += (list.empty() ? "" : ", ") + c;
      throw IoError(path + ": the texture it describes is missing (looked for " +
                    (list.empty() ? std::string("a .ktx2 or .dds in its file list") : list) + ")");
    }
    out.texture = exporter::ReadTextureFile(out.texture_path);
    const exporter::PackedVolume& v = out.texture.volume;
    if (v.width != width || v.height != height || v.depth != depth)
      throw FormatError(
          path, "grid",
          "the size of " + out.texture_path + " (" + std::to_string(v.width) + " × " +
              std::to_string(v.height) + " × " + std::to_string(v.depth) + ")",
          std::to_string(width) + " × " + std::to_string(height) + " × " + std::to_string(depth));
    const std::uint32_t actual = v.Crc32();
    if (bytes != v.ByteSize() || crc != actual) {
      char want[64], got[64];
      std::snprintf(want, sizeof want, "%llu bytes, CRC-32 0x%08x",
                    static_cast<unsigned long long>(bytes), crc);
      std::snprintf(got, sizeof got, "%zu bytes, CRC-32 0x%08x", v.ByteSize(), actual);
      throw FormatError(out.texture_path, "payload",
                        "the payload " + path + " records (" + want + ")", got,
                        "the texture and its JSON do not belong together, or one is damaged");
    }
    if (!out.texture.theta_in_from_metadata) {
      out.texture.theta_in_deg = theta_in_deg;
      out.texture.theta_in_from_metadata = true;
      exporter::FinishLoadedTexture(out.texture);  // decodes the LUT with this θin list
    }
    out.checksum_verified = true;
    return out;
  }
  if (kind != FileKind::kTexture)
    throw InvalidArgument(path +
                          ": expected a .ktx2 or .dds texture, a LUT sidecar or an atlas "
                          "manifest, got a " +
                          std::string(FileKindName(kind)));
  out.texture_path = path;
  out.texture = exporter::ReadTextureFile(path);
  if (!out.texture.sidecar_json.empty()) {
    out.sidecar = exporter::ParseSidecarJson(out.texture.sidecar_json, path + " (sidecar)");
    out.checksum_verified = true;  // FinishLoadedTexture compared it
  } else if (!out.texture.atlas_manifest_json.empty()) {
    out.manifest =
        exporter::ParseAtlasManifest(out.texture.atlas_manifest_json, path + " (manifest)");
    out.checksum_verified = true;
  } else {
    out.warnings.push_back(path + ": warning: no sidecar recorded or found beside it: θin " +
                           DegList(out.texture.theta_in_deg) +
                           "° assumed (k·20°) and the checksum not verified");
  }
  return out;
}

Rgb LutBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return {0.0, 0.0, 0.0};
  const double theta_in_deg = RadToDeg(ThetaOf(wi));
  // Isotropic: only φout − φin matters, and the LUT stores the light at φin = 0.
  const double phi_deg = std::hypot(wi.x, wi.y) > 0.0
                             ? WrapDeg360(RadToDeg(PhiOf(wo)) - RadToDeg(PhiOf(wi)))
                             : RadToDeg(PhiOf(wo));
  const std::array<float, 3> f = lut_.SampleAngles(theta_in_deg, RadToDeg(ThetaOf(wo)), phi_deg);
  return {f[0], f[1], f[2]};
}

std::unique_ptr<BrdfSource> OpenEvalSource(
    const std::string& path, const std::optional<processing::ExtrapolationParams>& command_line,
    std::vector<std::string>* warnings) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw IoError(path + ": no such file");
  const FileKind kind = ClassifyFile(path);
  switch (kind) {
    case FileKind::kMaterial:
      return std::make_unique<AnalyticBrdf>(LoadMaterialFile(path));
    case FileKind::kCapture: {
      PreparedMeasurement p = PrepareMeasurement(path, kind, command_line);
      if (warnings) warnings->insert(warnings->end(), p.warnings.begin(), p.warnings.end());
      return std::make_unique<processing::MeasurementBrdf>(
          p.measurement, p.extrapolation.params, processing::ResampleOptions{}, OutputNameOf(path));
    }
    case FileKind::kTexture:
    case FileKind::kSidecar:
    case FileKind::kAtlasManifest: {
      OpenedTexture t = OpenExportedTexture(path);
      if (warnings) warnings->insert(warnings->end(), t.warnings.begin(), t.warnings.end());
      if (!t.texture.IsSingleLut())
        throw InvalidArgument(path + ": an atlas (" + std::to_string(t.texture.volume.width) +
                              " × " + std::to_string(t.texture.volume.height) +
                              " texels) holds many materials; evaluate one material's own LUT");
      if (command_line && warnings)
        warnings->push_back(path +
                            ": warning: --extrapolate ignored: the extrapolation is baked into "
                            "an exported LUT");
      return std::make_unique<LutBrdf>(std::move(t.texture.lut), OutputNameOf(path));
    }
    case FileKind::kUnknown: {
      // .bsdf is shared by RGL and Zemax/LightTools tables and .csv by point clouds and
      // goniometer tables, so the format is decided by content. Evaluable databases (RGL,
      // MERL) open directly; tabulated measurements are interpolated like a capture.
      const ImportFormat format = DetectImportFormat(path);
      if (format == ImportFormat::kRgl || format == ImportFormat::kMerl)
        return OpenBrdfSource(path);
      ImportOptions import_options;
      import_options.allow_btdf = true;
      Measurement m = ImportFile(path, format, import_options);
      if (warnings && m.metadata.extra.count("scatter_type") &&
          m.metadata.extra.at("scatter_type").rfind("BTDF", 0) == 0)
        warnings->push_back(path +
                            ": warning: transmission (BTDF) table, evaluated mirrored into the "
                            "reflection hemisphere");
      return std::make_unique<processing::MeasurementBrdf>(
          std::move(m), command_line.value_or(processing::ExtrapolationParams{}),
          processing::ResampleOptions{}, OutputNameOf(path));
    }
    default:
      throw InvalidArgument(path + ": cannot evaluate a " + std::string(FileKindName(kind)) +
                            " (brdf eval reads material .json, .bpc, .ktx2, .dds, LUT "
                            "sidecar .json, and the measured formats of brdf::OpenBrdfSource)");
  }
}

InputLut LutFromInput(const std::string& path, FileKind kind,
                      const std::optional<processing::ExtrapolationParams>& command_line,
                      const processing::ResampleOptions& resample_options) {
  InputLut out;
  if (kind == FileKind::kCapture || kind == FileKind::kMaterial) {
    PreparedMeasurement p = PrepareMeasurement(path, kind, command_line);
    out.warnings = std::move(p.warnings);
    processing::ResampleReport report;
    out.lut =
        processing::BuildLut(p.measurement, p.extrapolation.params, resample_options, &report);
    if (report.theta_b_deg < 90.0)
      out.extrapolation = exporter::ExtrapolationInfo{p.extrapolation.params.p,
                                                      p.extrapolation.params.l, report.theta_b_deg};
    return out;
  }
  if (kind == FileKind::kTexture || kind == FileKind::kSidecar) {
    OpenedTexture t = OpenExportedTexture(path);
    out.warnings = std::move(t.warnings);
    if (!t.texture.IsSingleLut())
      throw InvalidArgument(path + ": an atlas, not a single material's LUT");
    if (command_line)
      out.warnings.push_back(path +
                             ": warning: --extrapolate ignored: the extrapolation is baked into "
                             "an exported LUT");
    if (t.sidecar) out.extrapolation = t.sidecar->extrapolation;
    out.lut = std::move(t.texture.lut);
    return out;
  }
  throw InvalidArgument(path +
                        ": expected a capture (.bpc), a material file, or an exported LUT "
                        "(.ktx2, .dds, sidecar .json), got a " +
                        std::string(FileKindName(kind)));
}

}  // namespace brdf::cli
