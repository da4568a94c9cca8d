#include "brdf/sources/open.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/merl.h"
#include "brdf/core/rgl.h"
#include "brdf/core/text_format.h"
#include "brdf/core/virtual_capture.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/exporter/rgb9e5.h"
#include "brdf/processing/measurement_brdf.h"
#include "brdf/sources/capture.h"
#include "text.h"

namespace brdf::sources {

namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kMaxJsonBytes = 16u << 20;

using detail::Deg;
using detail::DegList;

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return ext;
}

std::string ExtrapolationIgnored(const std::string& path) {
  return path +
         ": warning: the extrapolation given on the command line is ignored: it is baked "
         "into an exported LUT";
}

// A noise-free capture of an evaluable file, named after it.
Measurement CaptureFile(const BrdfSource& source, const std::string& path, FileKind kind) {
  Measurement m = CaptureNoiseFree(source);
  if (m.metadata.sample_name.empty()) m.metadata.sample_name = OutputNameOf(path);
  m.metadata.extra["source_file"] = RecordedSourceName(path);
  if (kind == FileKind::kMaterial) {
    m.metadata.extra["material_file"] = RecordedSourceName(path);
  } else if (const auto format = ImportFormatOf(kind)) {
    m.metadata.extra["source_format"] = ImportFormatName(*format);
  }
  return m;
}

// An exported texture that must hold one material's LUT: OpenExportedTexture, its warnings
// appended to `warnings`; an atlas is refused.
OpenedTexture OpenSingleLut(const std::string& path, std::vector<std::string>* warnings) {
  OpenedTexture t = OpenExportedTexture(path);
  for (std::string& w : t.warnings) warnings->push_back(std::move(w));
  if (!t.texture.IsSingleLut())
    throw InvalidArgument(path + ": an atlas, not a single material's LUT");
  return t;
}

}  // namespace

Material LoadMaterialInput(const std::string& path) {
  Material material = LoadMaterialFile(path);
  processing::ExtrapolationFromJson(ReadFileText(path, kMaxJsonBytes), path);
  return material;
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
      own = ExtrapolationChoice{*p, ExtrapolationChoice::Origin::kMaterialMember, input_path};
  }
  std::error_code ec;
  if (fs::is_regular_file(beside, ec)) {
    ExtrapolationChoice choice{processing::LoadExtrapolationJson(beside.string()),
                               ExtrapolationChoice::Origin::kBesideFile, beside.string()};
    if (own && !(own->params == choice.params) && warnings)
      warnings->push_back(input_path + ": warning: " + beside.string() +
                          " (p,l = " + processing::FormatExtrapolation(choice.params) +
                          ") overrides the material's own \"extrapolate\" (" +
                          processing::FormatExtrapolation(own->params) + ")");
    return choice;
  }
  if (own) return *own;
  if (command_line) return {*command_line, ExtrapolationChoice::Origin::kCommandLine, {}};
  return {processing::ExtrapolationParams{}, ExtrapolationChoice::Origin::kDefaults, {}};
}

namespace {

// PrepareMeasurement; for a file evaluable by itself (material, RGL, MERL) that is captured
// virtually, also the source it captured, in `*evaluable` when not null (so one read serves
// both the evaluation and the capture).
PreparedMeasurement Prepare(const std::string& path, FileKind kind,
                            const std::optional<processing::ExtrapolationParams>& command_line,
                            bool allow_btdf, std::shared_ptr<const BrdfSource>* evaluable) {
  PreparedMeasurement out;
  std::shared_ptr<const BrdfSource> source;
  switch (kind) {
    case FileKind::kCapture:
      out.measurement = LoadCaptureForLut(path, &out.warnings, &out.export_refusals);
      break;
    case FileKind::kMaterial: {
      auto material = std::make_shared<AnalyticBrdf>(LoadMaterialInput(path));
      out.measurement = CaptureFile(*material, path, kind);
      out.measurement.metadata.extra["model"] = std::string(ModelName(material->material().model));
      source = std::move(material);
      break;
    }
    case FileKind::kRgl:
      source = std::make_shared<RglBrdf>(RglBrdf::Load(path));
      out.measurement = CaptureFile(*source, path, kind);
      break;
    case FileKind::kMerl:
      source = std::make_shared<MerlBrdf>(MerlBrdf::Load(path));
      out.measurement = CaptureFile(*source, path, kind);
      break;
    case FileKind::kKtx2:
    case FileKind::kDds:
    case FileKind::kSidecar: {
      // Sampled as a GPU samples the texture (LutBrdf), on the reference geometry.
      OpenedTexture t = OpenSingleLut(path, &out.warnings);
      out.measurement =
          CaptureFile(LutBrdf(std::move(t.texture.lut), OutputNameOf(path)), path, kind);
      break;
    }
    case FileKind::kZemax:
    case FileKind::kLightTools:
    case FileKind::kCsv:
    case FileKind::kGonio: {
      ImportOptions import_options;
      import_options.allow_btdf = allow_btdf;
      out.measurement = ImportFile(path, *ImportFormatOf(kind), import_options);
      // The values, by the rule every evaluation of a table applies (BuildLut with any θin):
      // a fit or a virtual capture refuses what `eval` refuses.
      processing::ResampleOptions any_theta_in;
      any_theta_in.require_uniform_theta_in = false;
      if (const auto problems = processing::FindLutInputProblems(out.measurement, any_theta_in);
          !problems.empty())
        throw InvalidArgument(path + ": " + problems.front().message);
      const auto it = out.measurement.metadata.extra.find("scatter_type");
      if (it != out.measurement.metadata.extra.end() && it->second.rfind("BTDF", 0) == 0)
        out.warnings.push_back(path +
                               ": warning: transmission (BTDF) table, used mirrored into the "
                               "reflection hemisphere");
      break;
    }
    default:
      throw InvalidArgument(path +
                            ": expected a capture (.bpc), a material file, a measured "
                            "table or an exported LUT, got a " +
                            std::string(FileKindName(kind)));
  }
  out.extrapolation = ChooseExtrapolation(path, kind, command_line, &out.warnings);
  out.measured = kind == FileKind::kCapture || kind == FileKind::kZemax ||
                 kind == FileKind::kLightTools || kind == FileKind::kCsv ||
                 kind == FileKind::kGonio;
  if (evaluable) *evaluable = std::move(source);
  return out;
}

}  // namespace

PreparedMeasurement PrepareMeasurement(
    const std::string& path, FileKind kind,
    const std::optional<processing::ExtrapolationParams>& command_line, bool allow_btdf) {
  return Prepare(path, kind, command_line, allow_btdf, nullptr);
}

OpenedTexture OpenExportedTexture(const std::string& path) {
  OpenedTexture out;
  const FileKind kind = DetectFileKind(path);
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
    const std::uint32_t actual = out.texture.PayloadCrc32();
    if (bytes != out.texture.PayloadBytes() || crc != actual) {
      const std::string want = std::to_string(bytes) + " bytes, CRC-32 " + Hex32Text(crc);
      const std::string got =
          std::to_string(out.texture.PayloadBytes()) + " bytes, CRC-32 " + Hex32Text(actual);
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
  if (!IsTexture(kind))
    throw InvalidArgument(path +
                          ": expected a .ktx2 or .dds texture, a LUT sidecar or an atlas "
                          "manifest, got a " +
                          std::string(FileKindName(kind)));
  out.texture_path = path;
  out.texture = exporter::ReadTextureFile(path);
  // Metadata found beside a DDS is named by its own file, embedded metadata by the texture's.
  const std::string& beside = out.texture.metadata_file;
  out.sidecar_path = beside;
  if (!out.texture.sidecar_json.empty()) {
    out.sidecar = exporter::ParseSidecarJson(out.texture.sidecar_json,
                                             beside.empty() ? path + " (sidecar)" : beside);
    out.checksum_verified = true;  // FinishLoadedTexture compared it
  } else if (!out.texture.atlas_manifest_json.empty()) {
    out.manifest = exporter::ParseAtlasManifest(out.texture.atlas_manifest_json,
                                                beside.empty() ? path + " (manifest)" : beside);
    out.checksum_verified = true;
  } else {
    out.warnings.push_back(
        path + ": warning: no sidecar recorded or found beside it: θin " +
        DegList(out.texture.theta_in_deg) +
        "° assumed (the toolchain's layout for that slice count) and the checksum not verified");
  }
  return out;
}

std::optional<std::string> OpenedSource::BeyondMeasuredWarning(double theta_in_deg,
                                                               double theta_out_deg,
                                                               const std::string& path) const {
  if (measured_theta_in_deg.empty()) return std::nullopt;
  const double lo = measured_theta_in_deg.front(), hi = measured_theta_in_deg.back();
  constexpr double kTolDeg = Lut::kThetaInToleranceDeg;
  const auto inside = [&](double t) { return t >= lo - kTolDeg && t <= hi + kTolDeg; };
  if (inside(theta_in_deg)) return std::nullopt;
  // The light polar angle the LUT is read at after the reciprocity step (Lut::SampleAngles).
  const auto* lut = dynamic_cast<const LutBrdf*>(brdf.get());
  const bool exchanged = lut && lut->lut().ExchangesLightAndView(theta_in_deg, theta_out_deg);
  const double light = exchanged ? theta_out_deg : theta_in_deg;
  if (inside(light)) return std::nullopt;  // reciprocity: a measured slice answers
  const double nearest = light < lo ? lo : hi;
  if (lut && lut->lut().theta_in_deg.back() > hi + kTolDeg)
    return path + ": warning: θin " + Deg(theta_in_deg) + "° is outside the measured range " +
           Deg(lo) + "°–" + Deg(hi) + "° and so is θout " + Deg(theta_out_deg) +
           "°: the value is extrapolated from the measured slices (docs/design.md §5, "
           "\"Beyond the measured slices\"), not measured";
  return path + ": warning: θin " + Deg(theta_in_deg) + "° is outside the measured range " +
         Deg(lo) + "°–" + Deg(hi) + "° and so is θout " + Deg(theta_out_deg) +
         "°: the value is the θin " + Deg(nearest) +
         "° slice's at the same specular-frame angles (clamped, not measured)";
}

std::optional<std::string> OpenedSource::SphereCoverageNote(const std::string& path) const {
  if (measured_theta_in_deg.empty()) return std::nullopt;
  const double hi = measured_theta_in_deg.back();
  if (hi >= kSphereCoverageThetaInDeg - Lut::kThetaInToleranceDeg) return std::nullopt;
  const auto* lut = dynamic_cast<const LutBrdf*>(brdf.get());
  if (lut && lut->lut().theta_in_deg.back() > hi + Lut::kThetaInToleranceDeg)
    return path + ": note: θin measured up to " + Deg(hi) +
           "°: where the sphere is both lit and seen more than " + Deg(hi) +
           "° from its normal (towards its rim) the picture shows values extrapolated from the "
           "measured slices up to " +
           Deg(lut->lut().theta_in_deg.back()) +
           "°, not measured ones (docs/preview.md, \"Captures\")";
  return path + ": note: θin measured up to " + Deg(hi) +
         "°: where the sphere is both lit and seen more than " + Deg(hi) +
         "° from its normal (towards its rim) the picture shows the " + Deg(hi) +
         "° slice's values, not measured ones (docs/preview.md, \"Captures\")";
}

processing::ResampleOptions DefaultResampleOptions() {
  processing::ResampleOptions r;
  r.beyond.method = processing::kDefaultBeyondMethod;
  r.beyond.subdivisions = processing::kDefaultBeyondSubdivisions;
  return r;
}

namespace {

// An exported texture opened for evaluation: OpenExportedTexture, an atlas refused.
OpenedTexture OpenTextureToEvaluate(const std::string& path, const OpenOptions& options,
                                    std::vector<std::string>* warnings) {
  OpenedTexture t = OpenExportedTexture(path);
  for (std::string& w : t.warnings) warnings->push_back(std::move(w));
  if (!t.texture.IsSingleLut())
    throw InvalidArgument(path + ": an atlas (" + std::to_string(t.texture.volume.width) + " × " +
                              std::to_string(t.texture.volume.height) +
                              " texels) holds many materials",
                          Remedy{RemedyKind::kEvaluateSingleLut, path});
  if (options.extrapolation) warnings->push_back(ExtrapolationIgnored(path));
  return t;
}

[[noreturn]] void RefuseUnevaluable(const std::string& path, FileKind kind) {
  throw InvalidArgument(path + ": cannot evaluate a " + std::string(FileKindName(kind)) +
                        " (evaluable: material .json, .bpc capture, .ktx2 / .dds / .brdfc LUT, LUT "
                        "sidecar .json, RGL .bsdf, MERL .binary, Zemax or LightTools BSDF "
                        "table, CSV point cloud, goniometer table)");
}

}  // namespace

std::optional<std::string> CompactLutOfSidecar(const std::string& sidecar_path) {
  const exporter::SidecarInfo s = exporter::ReadSidecar(sidecar_path);
  if (s.payload_format != "compact_log_grid") return std::nullopt;
  for (const std::string& f : s.files)
    if (fs::path(f).extension() == ".brdfc") {
      const fs::path beside = fs::path(sidecar_path).parent_path() / f;
      std::error_code ec;
      if (fs::is_regular_file(beside, ec)) return beside.string();
    }
  throw IoError(
      sidecar_path +
      ": the compact LUT it describes is missing (looked for the .brdfc in its file list)");
}

OpenedSource OpenBrdf(const std::string& path_or_name, const OpenOptions& options) {
  std::string path = ResolveSource(path_or_name);
  OpenedSource out;
  out.kind = DetectFileKind(path);
  if (out.kind == FileKind::kSidecar)
    if (const std::optional<std::string> compact = CompactLutOfSidecar(path)) {
      path = *compact;  // the sidecar of a compact LUT stands for its .brdfc
      out.kind = FileKind::kCompactLut;
    }
  switch (out.kind) {
    case FileKind::kMaterial:
      out.brdf = std::make_unique<AnalyticBrdf>(LoadMaterialInput(path));
      out.evaluation = Evaluation::kAnalytic;
      return out;
    case FileKind::kRgl:
      out.brdf = std::make_unique<RglBrdf>(RglBrdf::Load(path));
      out.evaluation = Evaluation::kMeasuredDatabase;
      return out;
    case FileKind::kMerl:
      out.brdf = std::make_unique<MerlBrdf>(MerlBrdf::Load(path));
      out.evaluation = Evaluation::kMeasuredDatabase;
      return out;
    case FileKind::kCapture:
    case FileKind::kZemax:
    case FileKind::kLightTools:
    case FileKind::kCsv:
    case FileKind::kGonio: {
      PreparedMeasurement p =
          PrepareMeasurement(path, out.kind, options.extrapolation, /*allow_btdf=*/true);
      out.warnings = std::move(p.warnings);
      auto brdf = std::make_unique<LutBrdf>(processing::MeasurementAsBrdf(
          p.measurement, p.extrapolation.params, options.resample, OutputNameOf(path)));
      for (const Slice& s : p.measurement.slices)
        out.measured_theta_in_deg.push_back(s.theta_in_deg);
      std::sort(out.measured_theta_in_deg.begin(), out.measured_theta_in_deg.end());
      out.extrapolation = p.extrapolation;
      out.evaluation = Evaluation::kResampledLut;
      out.brdf = std::move(brdf);
      return out;
    }
    case FileKind::kKtx2:
    case FileKind::kDds:
    case FileKind::kSidecar:
    case FileKind::kAtlasManifest: {
      OpenedTexture t = OpenTextureToEvaluate(path, options, &out.warnings);
      out.measured_theta_in_deg = t.texture.lut.theta_in_deg;
      out.evaluation = Evaluation::kExportedLut;
      out.brdf = std::make_unique<LutBrdf>(std::move(t.texture.lut), OutputNameOf(path));
      return out;
    }
    case FileKind::kCompactLut: {
      // Reconstructed exactly as the shipped compact GLSL decoder does it.
      exporter::LoadedCompact c = exporter::ReadCompactLutFile(path);
      out.measured_theta_in_deg = c.compact.theta_in_deg;
      out.evaluation = Evaluation::kExportedLut;
      out.brdf = std::make_unique<exporter::CompactBrdf>(std::move(c.compact), OutputNameOf(path));
      return out;
    }
    default:
      RefuseUnevaluable(path, out.kind);
  }
}

OpenedForView OpenForView(const std::string& path_or_name, const OpenOptions& options) {
  OpenedForView out;
  out.path = ResolveSource(path_or_name);
  const std::string& path = out.path;
  const std::string name = OutputNameOf(path);
  out.kind = DetectFileKind(path);
  if (IsExportedLut(out.kind)) {
    OpenedTexture t = OpenTextureToEvaluate(path, options, &out.warnings);
    if (t.sidecar && t.sidecar->extrapolation)
      out.theta_b_deg = t.sidecar->extrapolation->theta_b_deg;
    out.lut = std::move(t.texture.lut);
    out.evaluation = Evaluation::kExportedLut;
    out.brdf = std::make_shared<LutBrdf>(out.lut, name);
    return out;
  }
  switch (out.kind) {
    case FileKind::kMaterial:
      out.evaluation = Evaluation::kAnalytic;
      break;
    case FileKind::kRgl:
    case FileKind::kMerl:
      out.evaluation = Evaluation::kMeasuredDatabase;
      break;
    case FileKind::kCapture:
    case FileKind::kZemax:
    case FileKind::kLightTools:
    case FileKind::kCsv:
    case FileKind::kGonio:
      out.evaluation = Evaluation::kResampledLut;
      break;
    default:
      RefuseUnevaluable(path, out.kind);
  }
  std::shared_ptr<const BrdfSource> evaluable;
  PreparedMeasurement p =
      Prepare(path, out.kind, options.extrapolation, /*allow_btdf=*/true, &evaluable);
  // Any distinct θin, as OpenBrdf evaluates them (processing::MeasurementAsBrdf).
  processing::ResampleOptions resample = options.resample;
  resample.require_uniform_theta_in = false;
  resample.check_measured_values = p.measured;
  processing::ResampleReport report;
  out.lut = processing::BuildLut(p.measurement, p.extrapolation.params, resample, &report);
  out.theta_b_deg = report.theta_b_deg;
  out.brdf = evaluable ? std::move(evaluable) : std::make_shared<LutBrdf>(out.lut, name);
  out.measurement = std::move(p.measurement);
  out.resample_report = std::move(report);
  out.extrapolation = p.extrapolation;
  out.warnings = std::move(p.warnings);
  return out;
}

InputLut LutFromInput(const std::string& path, FileKind kind,
                      const std::optional<processing::ExtrapolationParams>& command_line,
                      const processing::ResampleOptions& resample_options) {
  InputLut out;
  if (IsExportedLut(kind)) {
    OpenedTexture t = OpenSingleLut(path, &out.warnings);
    if (command_line) out.warnings.push_back(ExtrapolationIgnored(path));
    if (t.sidecar) {
      out.extrapolation = t.sidecar->extrapolation;
      out.saturated_samples = t.sidecar->saturated_samples;
      out.beyond_json = t.sidecar->beyond_json;
    }
    out.lut = std::move(t.texture.lut);
    return out;
  }
  PreparedMeasurement p = PrepareMeasurement(path, kind, command_line);
  // The one rule's sentence (capture.h), naming the file and its slices, for every command that
  // makes LUT textures (convert, atlas, brdf.convert), rather than BuildLut's own.
  if (!p.export_refusals.empty()) throw p.export_refusals.front().ToError(path);
  out.warnings = std::move(p.warnings);
  out.saturated_samples = CountSaturated(p.measurement);
  processing::ResampleOptions resample = resample_options;
  resample.check_measured_values = p.measured;
  processing::ResampleReport report;
  out.lut = processing::BuildLut(p.measurement, p.extrapolation.params, resample, &report);
  if (report.beyond.used != processing::BeyondMethod::kClamp) {
    out.beyond = report.beyond;
    out.beyond_json = processing::BeyondReportJson(report.beyond);
  }
  if (auto note = ClipNote(path, out.lut)) out.warnings.push_back(std::move(*note));
  if (report.theta_b_deg < 90.0)
    out.extrapolation = exporter::ExtrapolationInfo{p.extrapolation.params.p,
                                                    p.extrapolation.params.l, report.theta_b_deg};
  return out;
}

std::optional<std::string> ClipNote(const std::string& path, const Lut& lut) {
  std::size_t negative = 0, above = 0;
  for (float v : lut.texels) {
    negative += v < 0.0f;
    above += v > exporter::kRgb9e5MaxValue;
  }
  if (negative == 0 && above == 0) return std::nullopt;
  std::string what;
  if (negative > 0) what = std::to_string(negative) + " negative (written as 0)";
  if (above > 0)
    what += (what.empty() ? "" : ", ") + std::to_string(above) + " above " +
            NumberText(exporter::kRgb9e5MaxValue) + " (written as " +
            NumberText(exporter::kRgb9e5MaxValue) + ")";
  return path + ": warning: the RGB9E5 textures clip " + what + " of the LUT's " +
         std::to_string(lut.texels.size()) + " texel values (RGB9E5 holds [0, " +
         NumberText(exporter::kRgb9e5MaxValue) + "] 1/sr)";
}

std::vector<exporter::SaturatedCount> CountSaturated(const Measurement& m) {
  std::vector<exporter::SaturatedCount> counts;
  for (const Slice& slice : m.slices) {
    std::uint64_t n = 0;
    for (const Sample& sample : slice.samples) n += (sample.flags & kFlagSaturated) != 0;
    counts.push_back({slice.theta_in_deg, n});
  }
  return counts;
}

std::optional<std::string> SaturationNote(
    const std::string& path, const std::optional<std::vector<exporter::SaturatedCount>>& counts) {
  if (!counts) return std::nullopt;
  std::uint64_t total = 0;
  std::string per_slice;
  for (const exporter::SaturatedCount& c : *counts) {
    total += c.count;
    per_slice +=
        (per_slice.empty() ? "θin " : ", ") + Deg(c.theta_in_deg) + "°: " + std::to_string(c.count);
  }
  if (total == 0) return std::nullopt;
  return path + ": " + std::to_string(total) + " saturated sample" + (total == 1 ? "" : "s") +
         " (" + per_slice + "); their values are clipped";
}

std::optional<std::string> LeaveLastSliceOutNote(const std::string& path,
                                                 const std::optional<processing::BeyondReport>& b) {
  if (!b || !b->validation) return std::nullopt;
  const auto percent = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g %%", 100.0 * v);
    return std::string(buf);
  };
  std::string method(processing::BeyondMethodName(b->used));
  if (b->model) method += " (" + std::string(ModelName(b->model->material.model)) + ")";
  return path + ": blind-spot fill " + method + ": the θin " + Deg(b->validation->theta_in_deg) +
         "° slice predicted from the others within " + percent(b->validation->median) +
         " (median), " + percent(b->validation->p90) + " (p90)";
}

}  // namespace brdf::sources
