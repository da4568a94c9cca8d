// `brdf info FILE [--json]`: what a file holds. Dispatches on the file extension; each format
// has one describer below that fills a JSON document, and the text form is printed from the
// same document so the two views can never disagree. A .json is told apart by its content
// (material file, LUT sidecar, atlas manifest).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/csv.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/gonio.h"
#include "brdf/core/importers.h"
#include "brdf/core/lighttools.h"
#include "brdf/core/measurement.h"
#include "brdf/core/merl.h"
#include "brdf/core/models.h"
#include "brdf/core/rgl.h"
#include "brdf/core/text_format.h"
#include "brdf/core/zemax.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/exporter/rgb9e5.h"
#include "brdf/processing/resample.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kFlagNames[4] = {"saturated", "below_noise_floor", "interpolated", "invalid"};

// Non-finite statistics (a capture holding inf or NaN) become JSON null instead of invalid JSON.
Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json Triple(const std::array<double, 3>& v) { return {Number(v[0]), Number(v[1]), Number(v[2])}; }

Json MetadataJson(const Metadata& m) { return Json::parse(MetadataToJsonText(m)); }

const char* KindName(BpcProblemKind kind) {
  switch (kind) {
    case BpcProblemKind::kTruncated:
      return "truncated";
    case BpcProblemKind::kCorrupt:
      return "corrupt";
    case BpcProblemKind::kTrailingData:
      return "trailing_data";
  }
  return "unknown";
}

// Adds the slices, statistics and metadata of `m` (a .bpc capture or an imported table) under
// the keys of `brdf info --json`. `slice_indices` gives the file's chunk index of each slice.
void AddPointCloudJson(const Measurement& m, Json* j,
                       const std::vector<int>* slice_indices = nullptr) {
  std::array<std::size_t, 4> totals{};
  Json slices = Json::array();
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    const Slice& slice = m.slices[i];
    const SliceStats st = ComputeSliceStats(slice);
    Json s;
    s["index"] = slice_indices ? (*slice_indices)[i] : static_cast<int>(i);
    s["theta_in_deg"] = st.theta_in_deg;
    s["phi_in_deg"] = slice.phi_in_deg;
    s["samples"] = st.samples;
    s["complete"] = st.complete;
    s["has_sigma"] = slice.has_sigma;
    s["theta_out_deg"] = {Number(st.theta_out_min_deg), Number(st.theta_out_max_deg)};
    s["phi_out_deg"] = {Number(st.phi_out_min_deg), Number(st.phi_out_max_deg)};
    s["rgb_min"] = Triple(st.min);
    s["rgb_max"] = Triple(st.max);
    s["rgb_mean"] = Triple(st.mean);
    Json flags;
    for (int b = 0; b < 4; ++b) {
      flags[kFlagNames[b]] = st.flag_counts[b];
      totals[b] += st.flag_counts[b];
    }
    s["flag_counts"] = flags;
    slices.push_back(s);
  }
  (*j)["theta_in_deg"] = m.ThetaInDeg();
  (*j)["sample_count"] = m.SampleCount();
  (*j)["slices"] = slices;
  Json flags;
  for (int b = 0; b < 4; ++b) flags[kFlagNames[b]] = totals[b];
  (*j)["flag_counts"] = flags;
  (*j)["metadata"] = MetadataJson(m.metadata);
}

// The reasons `brdf convert` / `brdf eval` refuse a measurement (the same library checks they
// apply), as one line each, plus convert's own requirement of θin = k·Δin.
void AddRefusalsJson(const std::string& path, const std::vector<std::string>& refusals,
                     const Measurement* m, Json* j) {
  Json list = Json::array();
  for (const std::string& r : refusals) list.push_back(r);
  if (m != nullptr && !m->slices.empty() && refusals.empty()) {
    for (const processing::LutInputProblem& p : processing::FindLutInputProblems(*m))
      if (p.kind == processing::LutInputProblem::Kind::kThetaInNotUniform)
        list.push_back(path + ": 'brdf convert' refuses it: " + p.message);
  }
  (*j)["refusals"] = list;
  (*j)["usable"] = refusals.empty();
}

Json DescribeBpc(const std::string& path) {
  const sources::CaptureAssessment a = sources::AssessCapture(path);
  const BpcReadResult& r = a.read;
  const Measurement& m = r.measurement;
  Json j;
  j["file"] = path;
  j["format"] = "bpc";
  j["file_bytes"] = std::filesystem::file_size(path);
  j["finished"] = r.finished;
  j["valid_bytes"] = r.valid_bytes;
  AddPointCloudJson(m, &j, &r.slice_indices);
  j["problems"] = Json::array();
  bool truncated = false;
  for (const BpcProblem& p : r.problems) {
    truncated = truncated || p.kind != BpcProblemKind::kTrailingData;
    j["problems"].push_back({{"kind", KindName(p.kind)},
                             {"offset", p.offset},
                             {"size", p.size},
                             {"slice", p.slice_index},
                             {"message", p.message}});
  }
  std::vector<std::string> refusals;
  for (const sources::CaptureRefusal& refusal : a.refusals)
    refusals.push_back(ErrorLine(refusal.ToError(path), "info"));
  AddRefusalsJson(path, refusals, &m, &j);
  j["planned_theta_in_deg"] = a.planned_theta_in_deg;
  j["plan_recorded"] = a.plan_recorded;
  j["missing_theta_in_deg"] = a.missing_theta_in_deg;
  j["warnings"] = a.warnings;
  if (!r.finished) {
    if (r.intact_data_after_damage) {
      j["advice"] = "intact slices follow damaged data; a resume would discard them: " +
                    RemedyText(Remedy{RemedyKind::kRepairCapture, path});
    } else {
      j["advice"] =
          std::string(truncated ? "the capture was interrupted" : "the capture is unfinished") +
          ": " + RemedyText(Remedy{RemedyKind::kResumeCapture, path, r.valid_bytes});
    }
  }
  return j;
}

Json DescribeMaterial(const std::string& path) {
  const Material material = LoadMaterialFile(path);
  Json j;
  j["file"] = path;
  j["format"] = "material";
  j["model"] = std::string(ModelName(material.model));
  // The parameters in the model's order (brdf/core/models.h): RGB ones as triples, scalar
  // ones (the engine models' sliders) as numbers.
  Json parameters = Json::object();
  for (const ParameterInfo& p : DescribeModel(material.model).parameters) {
    const Rgb v = material.Parameter(std::string_view(p.name));
    parameters[std::string(p.name)] = p.rgb ? Json{v[0], v[1], v[2]} : Json(v[0]);
  }
  j["name"] = material.name;
  j["description"] = material.description;
  j["parameters"] = parameters;
  j["physical_problems"] = PhysicalProblems(material);
  return j;
}

// Third-party measurement files (brdf/core/importers.h), described as `brdf import` would
// store them plus what only the source format holds (header, Zemax TIS lines). .bsdf is shared
// by RGL and Zemax (and LightTools exports), .csv by point clouds and goniometer tables, so
// the format is decided by content with DetectImportFormat.

// The integrated scatter next to the file's TIS lines, per channel, rotation and incidence
// (IntegrateZemaxTis: "integrated" is the whole-hemisphere estimate, "covered" the part the
// table covers, a lower bound).
Json ZemaxTisJson(const ZemaxBsdf& z) {
  static constexpr const char* kXyzNames[3] = {"X", "Y", "Z"};
  Json rows = Json::array();
  for (std::size_t c = 0; c < z.channels(); ++c) {
    for (const ZemaxTis& t : IntegrateZemaxTis(z, c)) {
      Json r;
      r["channel"] = z.xyz ? kXyzNames[c] : "Monochrome";
      r["sample_rotation_deg"] = t.sample_rotation_deg;
      r["angle_of_incidence_deg"] = t.angle_of_incidence_deg;
      r["file_tis"] = Number(t.file_tis);
      r["integrated_tis"] = Number(t.filled_tis);
      r["covered_tis"] = Number(t.covered_tis);
      r["integrated_over_file"] = std::isfinite(t.file_tis) && t.file_tis > 0
                                      ? Number(t.filled_tis / t.file_tis)
                                      : Json(nullptr);
      rows.push_back(r);
    }
  }
  return rows;
}

Json DescribeImported(const std::string& path, ImportFormat format) {
  Json j;
  std::optional<Measurement> table_m;  // a point-cloud format, as `brdf import` stores it
  j["file"] = path;
  j["format"] = ImportFormatName(format);
  j["file_bytes"] = std::filesystem::file_size(path);
  switch (format) {
    case ImportFormat::kZemax: {
      const ZemaxBsdf z = ReadZemaxBsdf(path);
      Json h;
      h["source"] = z.source;
      h["symmetry"] = z.plane_symmetric ? "PlaneSymmetrical" : "Asymmetrical";
      h["spectral_content"] = z.xyz ? "XYZ" : "Monochrome";
      h["scatter_type"] = z.btdf ? "BTDF" : "BRDF";
      h["sample_rotation_deg"] = z.sample_rotation_deg;
      h["angle_of_incidence_deg"] = z.angle_of_incidence_deg;
      h["scatter_azimuth_deg"] = z.scatter_azimuth_deg;
      h["scatter_radial_deg"] = z.scatter_radial_deg;
      j["header"] = h;
      // A BTDF table is described as `brdf import --allow-btdf` stores it.
      table_m = ZemaxToMeasurement(z, path, ZemaxImportOptions{true});
      j["tis"] = ZemaxTisJson(z);
      if (z.btdf)
        j["advice"] = "ScatterType BTDF (line " + std::to_string(z.scatter_type_line) +
                      "): transmission data; the slices are shown mirrored into the reflection "
                      "hemisphere, as 'brdf import --allow-btdf' stores them";
      break;
    }
    case ImportFormat::kLightTools: {
      const LightToolsBsdf lt = ReadLightToolsBsdf(path);
      Json h;
      h["symmetry"] = lt.plane_symmetric ? "PlaneSymmetrical" : "Asymmetrical";
      h["spectral_content"] = lt.spectral == LightToolsSpectral::kXyz   ? "XYZ"
                              : lt.spectral == LightToolsSpectral::kRgb ? "RGB"
                                                                        : "Monochrome";
      h["scatter_azimuth_deg"] = lt.scatter_azimuth_deg;
      h["scatter_radial_deg"] = lt.scatter_radial_deg;
      h["blocks"] = lt.blocks.size();
      j["header"] = h;
      table_m = LightToolsToMeasurement(lt, path, LightToolsImportOptions{true});
      break;
    }
    case ImportFormat::kGonio: {
      const GonioTable table = ReadGonioTable(path);
      Json h;
      h["wavelengths_nm"] = table.wavelengths_nm;
      h["rows"] = table.rows.size();
      j["header"] = h;
      table_m = GonioToMeasurement(table, path);
      break;
    }
    case ImportFormat::kCsv:
      table_m = ReadCsv(path);
      break;
    case ImportFormat::kRgl: {
      // Parsed and checked exactly as 'brdf eval' and 'brdf import' load it.
      const RglBrdf rgl = RglBrdf::Load(path);
      const RglInfo& info = rgl.info();
      const TensorFile tensor = TensorFile::Read(path);
      Json h;
      h["description"] = info.description;
      std::vector<double> theta_i_deg, phi_i_deg;
      for (double t : info.theta_i_rad) theta_i_deg.push_back(RadToDeg(t));
      for (double p : info.phi_i_rad) phi_i_deg.push_back(RadToDeg(p));
      h["theta_i_deg"] = theta_i_deg;
      h["phi_i_deg"] = phi_i_deg;
      h["isotropic"] = info.isotropic ? "yes" : "no";
      h["jacobian"] = info.jacobian ? "yes" : "no";
      h["vndf_resolution"] =
          std::to_string(info.vndf_theta_res) + " x " + std::to_string(info.vndf_phi_res);
      h["rgb_resolution"] = std::to_string(info.rgb_res) + " x " + std::to_string(info.rgb_res);
      h["negative_rgb_values"] =
          std::to_string(info.negative_rgb_values) + " of " + std::to_string(info.rgb_values);
      std::string fields;
      for (const TensorField& f : tensor.fields())
        fields += (fields.empty() ? "" : ", ") + f.name + " " + f.ShapeString();
      h["fields"] = fields;
      j["header"] = h;
      j["theta_in_deg"] = theta_i_deg;
      j["advice"] =
          "an evaluable BRDF, not a point cloud: 'brdf eval' evaluates it, 'brdf import " + path +
          " --out FILE.bpc' captures it noise-free at the reference geometry";
      break;
    }
    case ImportFormat::kMerl: {
      const MerlBrdf merl = MerlBrdf::Load(path);
      const auto& u = merl.info().unmeasured_bins;
      constexpr std::uint64_t kBins =
          static_cast<std::uint64_t>(kMerlThetaHalfBins) * kMerlThetaDiffBins * kMerlPhiDiffBins;
      Json h;
      h["resolution"] =
          std::to_string(kMerlThetaHalfBins) + " x " + std::to_string(kMerlThetaDiffBins) + " x " +
          std::to_string(kMerlPhiDiffBins) + " bins (theta_half, theta_diff, phi_diff)";
      h["unmeasured_bins"] = "red " + std::to_string(u[0]) + ", green " + std::to_string(u[1]) +
                             ", blue " + std::to_string(u[2]) + " of " + std::to_string(kBins);
      j["header"] = h;
      j["unmeasured_bins"] = {u[0], u[1], u[2]};
      j["advice"] =
          "an evaluable BRDF, not a point cloud: 'brdf eval' evaluates it, 'brdf import " + path +
          " --out FILE.bpc' captures it noise-free at the reference geometry "
          "(samples in unmeasured bins flagged invalid)";
      break;
    }
    case ImportFormat::kAuto:
      break;
  }
  if (table_m) {
    AddPointCloudJson(*table_m, &j);
    // 'brdf eval' resamples a table like a capture: the same checks (any θin set).
    processing::ResampleOptions any_theta_in;
    any_theta_in.require_uniform_theta_in = false;
    std::vector<std::string> refusals;
    for (const processing::LutInputProblem& p :
         processing::FindLutInputProblems(*table_m, any_theta_in))
      refusals.push_back(path + ": " + p.message);
    AddRefusalsJson(path, refusals, nullptr, &j);
  }
  return j;
}

bool IsImportedFormat(const Json& j) {
  const std::string f = j["format"].get<std::string>();
  return f == "zemax" || f == "lighttools" || f == "csv" || f == "gonio" || f == "rgl" ||
         f == "merl";
}

Json CertifiedErrorJson(const exporter::CertifiedError& e) {
  const auto stats = [](const exporter::ErrorStatistics& s) {
    return Json{{"max", s.max}, {"p99", s.p99}, {"median", s.median}, {"texels", s.texels}};
  };
  return {{"format", e.format},
          {"bytes", e.bytes},
          {"rgb9e5_bytes", e.rgb9e5_bytes},
          {"theta_b_deg", e.theta_b_deg},
          {"measured", stats(e.measured)},
          {"filled", stats(e.filled)}};
}

// An exported LUT or atlas (.ktx2, .dds) or the sidecar / manifest describing one. Value ranges
// are of the RGB9E5 values as stored (decoded exactly), per θin slice; for an atlas over the
// cells that hold a material.
Json DescribeTexture(const std::string& path) {
  const sources::OpenedTexture t = sources::OpenExportedTexture(path);
  const exporter::LoadedTexture& tex = t.texture;
  const exporter::PackedVolume& v = tex.volume;
  Json j;
  j["file"] = path;
  j["format"] = t.manifest || !tex.IsSingleLut() ? "atlas" : "lut";
  j["texture_file"] = t.texture_path;
  const bool bc6h = tex.format == exporter::TexelFormat::kBc6hUfloat;
  if (tex.container == exporter::TextureContainer::kKtx2)
    j["container"] = bc6h ? "KTX2 (vkFormat 131, VK_FORMAT_BC6H_UFLOAT_BLOCK)"
                          : "KTX2 (vkFormat 123, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32)";
  else
    j["container"] =
        bc6h ? "DDS (DXGI_FORMAT_BC6H_UF16, 95)" : "DDS (DXGI_FORMAT_R9G9B9E5_SHAREDEXP, 67)";
  j["texel_format"] = tex.FormatName();
  j["file_bytes"] = std::filesystem::file_size(t.texture_path);
  if (!t.sidecar_path.empty()) j["json_file"] = t.sidecar_path;
  j["width"] = v.width;
  j["height"] = v.height;
  j["slices"] = v.depth;
  j["theta_in_deg"] = tex.theta_in_deg;
  j["theta_in_from_metadata"] = tex.theta_in_from_metadata;
  j["payload_bytes"] = tex.PayloadBytes();
  j["payload_crc32"] = Hex32Text(tex.PayloadCrc32());
  j["checksum"] = t.checksum_verified ? "verified against the recorded CRC-32"
                                      : "not verified (no sidecar or manifest)";
  if (t.sidecar) {
    j["name"] = t.sidecar->name;
    j["source"] = t.sidecar->source;
    j["tool_version"] = t.sidecar->tool_version;
    if (t.sidecar->extrapolation)
      j["extrapolation"] = {{"p", t.sidecar->extrapolation->p},
                            {"l", t.sidecar->extrapolation->l},
                            {"theta_b_deg", t.sidecar->extrapolation->theta_b_deg}};
    else
      j["extrapolation"] = nullptr;
    j["files"] = t.sidecar->files;
    if (t.sidecar->certified_error)
      j["certified_error"] = CertifiedErrorJson(*t.sidecar->certified_error);
  }
  // Cells holding data: the whole texture for a LUT, the materials' cells for an atlas.
  std::vector<std::array<int, 2>> origins = {{0, 0}};
  int cell_w = v.width, cell_h = v.height;
  if (t.manifest) {
    j["materials"] = Json::array();
    origins.clear();
    for (const auto& m : t.manifest->materials) {
      j["materials"].push_back({{"index", m.index},
                                {"name", m.name},
                                {"source", m.source},
                                {"column", m.column},
                                {"row", m.row},
                                {"x0", m.x0},
                                {"y0", m.y0}});
      if (m.certified_error)
        j["materials"].back()["certified_error"] = CertifiedErrorJson(*m.certified_error);
      origins.push_back({m.x0, m.y0});
    }
    cell_w = Lut::kWidth;
    cell_h = Lut::kHeight;
  }
  j["value_ranges"] = Json::array();
  for (int k = 0; k < v.depth; ++k) {
    std::array<double, 3> lo{}, hi{}, sum{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    std::size_t n = 0;
    for (const auto& [x0, y0] : origins)
      for (int y = y0; y < std::min(y0 + cell_h, v.height); ++y)
        for (int x = x0; x < std::min(x0 + cell_w, v.width); ++x, ++n) {
          const std::array<float, 3> rgb = tex.TexelValue(x, y, k);
          for (int c = 0; c < 3; ++c) {
            lo[c] = std::min<double>(lo[c], rgb[c]);
            hi[c] = std::max<double>(hi[c], rgb[c]);
            sum[c] += rgb[c];
          }
        }
    std::array<double, 3> mean{};
    for (int c = 0; c < 3; ++c) mean[c] = n ? sum[c] / static_cast<double>(n) : 0.0;
    j["value_ranges"].push_back(
        {{"theta_in_deg", Number(k < static_cast<int>(tex.theta_in_deg.size()) ? tex.theta_in_deg[k]
                                                                               : std::nan(""))},
         {"rgb_min", Triple(lo)},
         {"rgb_max", Triple(hi)},
         {"rgb_mean", Triple(mean)}});
  }
  j["warnings"] = t.warnings;
  return j;
}

std::string Fixed(const Json& v, const char* format = "%.6g") {
  if (v.is_null()) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v.get<double>());
  return buf;
}

std::string TripleText(const Json& v) {
  return Fixed(v[0]) + " " + Fixed(v[1]) + " " + Fixed(v[2]);
}

// Which commands the "usable" verdict speaks for: convert reads captures (and material files),
// a third-party table is evaluated directly and converted only after 'brdf import'.
const char* JudgingCommands(const Json& j) {
  return IsImportedFormat(j) ? "'brdf eval'" : "'brdf convert' and 'brdf eval'";
}

void PrintRefusalsText(const Json& j) {
  if (j.contains("warnings"))
    for (const auto& w : j["warnings"]) std::printf("%s\n", w.get<std::string>().c_str());
  if (!j.contains("refusals")) return;
  const char* verb_s = IsImportedFormat(j) ? "s" : "";  // one command, or two
  if (j["refusals"].empty()) {
    std::printf("usable: yes (%s accept%s it)\n", JudgingCommands(j), verb_s);
    return;
  }
  std::printf("usable: no; %s refuse%s it: %zu reason%s\n", JudgingCommands(j), verb_s,
              j["refusals"].size(), j["refusals"].size() == 1 ? "" : "s");
  for (const auto& r : j["refusals"]) std::printf("  %s\n", r.get<std::string>().c_str());
}

void PrintBpcText(const Json& j) {
  std::printf("%s: .bpc capture, %s, %s bytes\n", j["file"].get<std::string>().c_str(),
              j["finished"].get<bool>() ? "finished" : "unfinished (no end chunk)",
              std::to_string(j["file_bytes"].get<std::uint64_t>()).c_str());
  const Json& md = j["metadata"];
  const auto line = [&](const char* label, const std::string& value) {
    if (!value.empty()) std::printf("  %-22s %s\n", label, value.c_str());
  };
  for (const auto& [key, value] : md.items())
    if (value.is_string()) line(key.c_str(), value.get<std::string>());
  for (const auto& [key, value] : md["extra"].items())
    line(("extra." + key).c_str(), value.get<std::string>());
  std::string thetas;
  for (const auto& t : j["theta_in_deg"]) thetas += (thetas.empty() ? "" : ", ") + Fixed(t, "%g");
  std::printf("slices: %zu (theta_in %s deg), samples: %s\n", j["slices"].size(), thetas.c_str(),
              std::to_string(j["sample_count"].get<std::uint64_t>()).c_str());
  for (const Json& s : j["slices"]) {
    std::printf("  slice %d: theta_in %s deg, phi_in %s deg, %s samples%s%s\n",
                s["index"].get<int>(), Fixed(s["theta_in_deg"], "%g").c_str(),
                Fixed(s["phi_in_deg"], "%g").c_str(),
                std::to_string(s["samples"].get<std::uint64_t>()).c_str(),
                s["has_sigma"].get<bool>() ? ", with sigma" : "",
                s["complete"].get<bool>() ? "" : ", INCOMPLETE (capture stopped mid-slice)");
    std::printf("    theta_out %s..%s deg, phi_out %s..%s deg\n",
                Fixed(s["theta_out_deg"][0], "%g").c_str(),
                Fixed(s["theta_out_deg"][1], "%g").c_str(),
                Fixed(s["phi_out_deg"][0], "%g").c_str(), Fixed(s["phi_out_deg"][1], "%g").c_str());
    std::printf("    f_r (1/sr, r g b)  min %s  max %s  mean %s\n",
                TripleText(s["rgb_min"]).c_str(), TripleText(s["rgb_max"]).c_str(),
                TripleText(s["rgb_mean"]).c_str());
    const Json& f = s["flag_counts"];
    std::printf("    flags: saturated %s, below noise floor %s, interpolated %s, invalid %s\n",
                f["saturated"].dump().c_str(), f["below_noise_floor"].dump().c_str(),
                f["interpolated"].dump().c_str(), f["invalid"].dump().c_str());
  }
  if (j["problems"].empty()) {
    std::printf("problems: none\n");
  } else {
    std::printf("problems: %zu\n", j["problems"].size());
    for (const Json& p : j["problems"])
      std::printf("  %s\n", p["message"].get<std::string>().c_str());
  }
  PrintRefusalsText(j);
  if (j.contains("advice")) std::printf("note: %s\n", j["advice"].get<std::string>().c_str());
}

void PrintMaterialText(const Json& j) {
  std::printf("%s: material, model %s\n", j["file"].get<std::string>().c_str(),
              j["model"].get<std::string>().c_str());
  if (!j["name"].get<std::string>().empty())
    std::printf("  name         %s\n", j["name"].get<std::string>().c_str());
  if (!j["description"].get<std::string>().empty())
    std::printf("  description  %s\n", j["description"].get<std::string>().c_str());
  for (const auto& [key, value] : j["parameters"].items())
    std::printf("  %-12s %s\n", key.c_str(),
                value.is_array() ? TripleText(value).c_str() : Fixed(value).c_str());
  for (const auto& p : j["physical_problems"])
    std::printf("  not physical: %s\n", p.get<std::string>().c_str());
}

const char* FormatTitle(const std::string& format) {
  if (format == "zemax") return "Zemax BSDF table";
  if (format == "lighttools") return "LightTools BSDF table";
  if (format == "csv") return "CSV point cloud";
  if (format == "gonio") return "goniometer table";
  if (format == "rgl") return "RGL .bsdf material";
  return "MERL .binary material";
}

// Multi-line metadata (a Zemax file's comment block) on one indented line.
std::string OneLine(std::string text) {
  for (std::size_t pos = 0; (pos = text.find('\n', pos)) != std::string::npos;)
    text.replace(pos, 1, " / ");
  return text;
}

void PrintImportedText(const Json& j) {
  const std::string format = j["format"].get<std::string>();
  std::printf("%s: %s, %s bytes\n", j["file"].get<std::string>().c_str(), FormatTitle(format),
              std::to_string(j["file_bytes"].get<std::uint64_t>()).c_str());
  if (j.contains("header")) {
    for (const auto& [key, value] : j["header"].items()) {
      std::string text;
      if (value.is_string()) {
        text = value.get<std::string>();
      } else if (value.is_array()) {
        text = std::to_string(value.size()) + ":";
        for (const auto& v : value) {
          text += ' ';
          text += Fixed(v, "%g");
        }
      } else {
        text = value.dump();
      }
      if (!text.empty()) std::printf("  %-22s %s\n", key.c_str(), text.c_str());
    }
  }
  if (j.contains("slices")) {
    for (const auto& [key, value] : j["metadata"].items())
      if (value.is_string() && !value.get<std::string>().empty())
        std::printf("  %-22s %s\n", key.c_str(), OneLine(value.get<std::string>()).c_str());
    for (const auto& [key, value] : j["metadata"]["extra"].items())
      std::printf("  %-22s %s\n", ("extra." + key).c_str(),
                  OneLine(value.get<std::string>()).c_str());
    std::string thetas;
    for (const auto& t : j["theta_in_deg"]) thetas += (thetas.empty() ? "" : ", ") + Fixed(t, "%g");
    std::printf("slices: %zu (theta_in %s deg), samples: %s\n", j["slices"].size(), thetas.c_str(),
                std::to_string(j["sample_count"].get<std::uint64_t>()).c_str());
    for (const Json& s : j["slices"]) {
      const std::uint64_t invalid = s["flag_counts"]["invalid"].get<std::uint64_t>();
      const std::string invalid_text =
          invalid > 0 ? " (" + std::to_string(invalid) + " invalid)" : std::string();
      std::printf(
          "  slice %d: theta_in %s deg, phi_in %s deg, %s samples%s%s, theta_out %s..%s "
          "deg\n",
          s["index"].get<int>(), Fixed(s["theta_in_deg"], "%g").c_str(),
          Fixed(s["phi_in_deg"], "%g").c_str(),
          std::to_string(s["samples"].get<std::uint64_t>()).c_str(), invalid_text.c_str(),
          s["complete"].get<bool>() ? "" : ", INCOMPLETE",
          Fixed(s["theta_out_deg"][0], "%g").c_str(), Fixed(s["theta_out_deg"][1], "%g").c_str());
      std::printf("    f_r (1/sr, r g b)  min %s  max %s  mean %s\n",
                  TripleText(s["rgb_min"]).c_str(), TripleText(s["rgb_max"]).c_str(),
                  TripleText(s["rgb_mean"]).c_str());
    }
  }
  if (j.contains("tis")) {
    std::printf(
        "integrated scatter per incidence (TIS = integral of f_r cos(theta) over the "
        "hemisphere):\n");
    std::printf("  %-10s %8s %6s %10s %12s %10s %8s\n", "channel", "rotation", "AOI", "file TIS",
                "integrated", "covered", "int/file");
    for (const Json& r : j["tis"]) {
      const Json& ratio = r["integrated_over_file"];
      const std::string deviation =
          ratio.is_null() ? "-" : Fixed(Json((ratio.get<double>() - 1) * 100), "%+.1f%%");
      std::printf("  %-10s %8s %6s %10s %12s %10s %8s\n", r["channel"].get<std::string>().c_str(),
                  Fixed(r["sample_rotation_deg"], "%g").c_str(),
                  Fixed(r["angle_of_incidence_deg"], "%g").c_str(),
                  Fixed(r["file_tis"], "%.5f").c_str(), Fixed(r["integrated_tis"], "%.5f").c_str(),
                  Fixed(r["covered_tis"], "%.5f").c_str(), deviation.c_str());
    }
    std::printf(
        "  (integrated: the table's zeros past the horizon and beyond its last radial "
        "angle edge-filled; covered: the table alone, a lower bound)\n");
  }
  PrintRefusalsText(j);
  if (j.contains("advice")) std::printf("note: %s\n", j["advice"].get<std::string>().c_str());
}

void PrintTextureText(const Json& j) {
  const bool atlas = j["format"] == "atlas";
  std::printf("%s: %s, %s\n", j["file"].get<std::string>().c_str(),
              atlas ? "atlas texture" : "LUT texture", j["container"].get<std::string>().c_str());
  if (j.contains("json_file"))
    std::printf("  texture        %s (%s bytes)\n", j["texture_file"].get<std::string>().c_str(),
                std::to_string(j["file_bytes"].get<std::uint64_t>()).c_str());
  else
    std::printf("  file bytes     %s\n",
                std::to_string(j["file_bytes"].get<std::uint64_t>()).c_str());
  if (j.contains("name"))
    std::printf("  name           %s\n", j["name"].get<std::string>().c_str());
  if (j.contains("source"))
    std::printf("  source         %s\n", j["source"].get<std::string>().c_str());
  std::string thetas;
  for (const auto& t : j["theta_in_deg"]) thetas += (thetas.empty() ? "" : ", ") + Fixed(t, "%g");
  std::printf("  dimensions     %d × %d × %d texels (%s)\n", j["width"].get<int>(),
              j["height"].get<int>(), j["slices"].get<int>(),
              j["texel_format"].get<std::string>().c_str());
  std::printf("  theta_in       %s deg%s\n", thetas.c_str(),
              j["theta_in_from_metadata"].get<bool>() ? "" : " (assumed: no metadata)");
  std::printf("  payload        %s bytes, CRC-32 %s, %s\n",
              std::to_string(j["payload_bytes"].get<std::uint64_t>()).c_str(),
              j["payload_crc32"].get<std::string>().c_str(),
              j["checksum"].get<std::string>().c_str());
  if (j.contains("certified_error")) {
    const Json& e = j["certified_error"];
    const auto line = [&](const char* label, const Json& s) {
      std::printf("  %s max %s %%, p99 %s %%, median %s %% over %s texels\n", label,
                  Fixed(Json(100.0 * s["max"].get<double>()), "%.3g").c_str(),
                  Fixed(Json(100.0 * s["p99"].get<double>()), "%.3g").c_str(),
                  Fixed(Json(100.0 * s["median"].get<double>()), "%.3g").c_str(),
                  std::to_string(s["texels"].get<std::uint64_t>()).c_str());
    };
    std::printf(
        "  compression    %s, %s bytes (RGB9E5: %s, %.2fx smaller); certified relative "
        "error against the float LUT:\n",
        e["format"].get<std::string>().c_str(),
        std::to_string(e["bytes"].get<std::uint64_t>()).c_str(),
        std::to_string(e["rgb9e5_bytes"].get<std::uint64_t>()).c_str(),
        e["bytes"].get<double>() > 0 ? e["rgb9e5_bytes"].get<double>() / e["bytes"].get<double>()
                                     : 0.0);
    line("  measured     ", e["measured"]);
    line("  filled       ", e["filled"]);
    std::printf("                 (measured: theta_out <= %s deg; filled: beyond it)\n",
                Fixed(e["theta_b_deg"], "%g").c_str());
  }
  if (j.contains("extrapolation")) {
    if (j["extrapolation"].is_null())
      std::printf("  extrapolation  none (measured up to the horizon)\n");
    else
      std::printf("  extrapolation  p %s, l %s, beyond theta_b %s deg\n",
                  Fixed(j["extrapolation"]["p"], "%g").c_str(),
                  Fixed(j["extrapolation"]["l"], "%g").c_str(),
                  Fixed(j["extrapolation"]["theta_b_deg"], "%g").c_str());
  }
  if (j.contains("tool_version"))
    std::printf("  written by     brdf-toolchain %s\n",
                j["tool_version"].get<std::string>().c_str());
  if (atlas && j.contains("materials")) {
    std::printf("  materials      %zu\n", j["materials"].size());
    for (const Json& m : j["materials"]) {
      std::printf("    %d %s: cell column %d, row %d (texel origin %d, %d), from %s\n",
                  m["index"].get<int>(), m["name"].get<std::string>().c_str(),
                  m["column"].get<int>(), m["row"].get<int>(), m["x0"].get<int>(),
                  m["y0"].get<int>(), m["source"].get<std::string>().c_str());
      if (m.contains("certified_error")) {
        const Json& e = m["certified_error"]["measured"];
        std::printf(
            "      certified BC6H error, measured range: max %.3g %%, p99 %.3g %%, median "
            "%.3g %%\n",
            100.0 * e["max"].get<double>(), 100.0 * e["p99"].get<double>(),
            100.0 * e["median"].get<double>());
      }
    }
  }
  std::printf("  f_r (1/sr, r g b) per slice%s:\n", atlas ? " over the material cells" : "");
  for (const Json& r : j["value_ranges"])
    std::printf("    theta_in %s deg: min %s  max %s  mean %s\n",
                Fixed(r["theta_in_deg"], "%g").c_str(), TripleText(r["rgb_min"]).c_str(),
                TripleText(r["rgb_max"]).c_str(), TripleText(r["rgb_mean"]).c_str());
  for (const auto& w : j["warnings"]) std::printf("%s\n", w.get<std::string>().c_str());
}

}  // namespace

int RunInfo(const InfoOptions& options) {
  using sources::FileKind;
  // A library material name stands for its file (brdf/sources/material_library.h).
  const std::string file = sources::ResolveSource(options.file);
  const FileKind kind = sources::DetectFileKind(file);
  Json j;
  if (kind == FileKind::kCapture) {
    j = DescribeBpc(file);
  } else if (kind == FileKind::kMaterial) {
    j = DescribeMaterial(file);
  } else if (sources::IsExportedLut(kind)) {
    j = DescribeTexture(file);
  } else if (const std::optional<ImportFormat> format = sources::ImportFormatOf(kind)) {
    j = DescribeImported(file, *format);
  } else {
    throw InvalidArgument(file + ": a " + std::string(sources::FileKindName(kind)) +
                          "; brdf info reads captures (.bpc), material files, exported LUTs "
                          "(.ktx2, .dds, sidecar and atlas manifest .json), RGL .bsdf, MERL "
                          ".binary, Zemax and LightTools BSDF tables, CSV point clouds and "
                          "goniometer tables");
  }
  if (options.json) {
    std::printf("%s\n", j.dump(2, ' ', false, Json::error_handler_t::replace).c_str());
  } else if (j["format"] == "bpc") {
    PrintBpcText(j);
  } else if (IsImportedFormat(j)) {
    PrintImportedText(j);
  } else if (j["format"] == "lut" || j["format"] == "atlas") {
    PrintTextureText(j);
  } else {
    PrintMaterialText(j);
  }
  // A file that convert or eval would refuse is damaged: say so on stderr and fail, so scripts
  // can check files with `brdf info`.
  if (j.contains("usable") && !j["usable"].get<bool>()) {
    const std::size_t n = j["refusals"].size();
    std::fprintf(stderr, "brdf: %s: %zu problem%s that %s refuse%s%s\n", file.c_str(), n,
                 n == 1 ? "" : "s", JudgingCommands(j), IsImportedFormat(j) ? "s" : "",
                 options.json ? " (listed under \"refusals\")" : " (listed above)");
    return 1;
  }
  return 0;
}

}  // namespace brdf::cli
