// The describers behind brdf/sources/describe.h: one per kind of file, each filling the JSON
// document `brdf info --json` prints. The text form is printed from the same document, so the
// two views cannot disagree.
#include "brdf/sources/describe.h"

#include <algorithm>
#include <cmath>
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
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/exporter/rgb9e5.h"
#include "brdf/exporter/sidecar.h"
#include "brdf/processing/beyond.h"
#include "brdf/processing/resample.h"
#include "brdf/processing/sanity.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/material_library.h"
#include "brdf/sources/open.h"

namespace brdf::sources {

namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kFlagNames[4] = {"saturated", "below_noise_floor", "interpolated", "invalid"};

// Non-finite statistics (a capture holding inf or NaN) become JSON null instead of invalid JSON.
Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json Triple(const std::array<double, 3>& v) { return {Number(v[0]), Number(v[1]), Number(v[2])}; }

// The host's words for a remedy (DescribeFile's `phrase`), and an error's line with them.
struct Phrasing {
  const RemedyPhrasing& phrase;
  std::string operator()(const Remedy& r) const {
    return r.kind == RemedyKind::kNone || !phrase ? std::string() : phrase(r);
  }
  std::string Line(const Error& e) const {
    std::string line = e.what();
    const std::string remedy = (*this)(e.remedy());
    if (!remedy.empty()) line += "; " + remedy;
    return line;
  }
};

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

// The verdict (one rule, brdf/sources/capture.h): "refusals" lists every reason a reading
// command refuses the file, one line each; "usable" is true when none does; "evaluable" when
// eval, preview, fit and brdf-view accept it (they do unless `refusals` is not empty). For
// captures, "convertible": convert and atlas accept it too (`export_refusals` are theirs alone).
void AddRefusalsJson(const std::vector<std::string>& refusals,
                     const std::vector<std::string>* export_refusals, Json* j) {
  Json list = Json::array();
  for (const std::string& r : refusals) list.push_back(r);
  if (export_refusals)
    for (const std::string& r : *export_refusals) list.push_back(r);
  (*j)["refusals"] = list;
  (*j)["usable"] = list.empty();
  (*j)["evaluable"] = refusals.empty();
  if (export_refusals) (*j)["convertible"] = list.empty();
}

// A usable capture read as the commands read it (OpenForView: the LUT `brdf eval` samples,
// the default blind-spot fill included): "blind_spot_fill", the fill's record with its
// leave-last-slice-out error (processing::BeyondReportJson; null when nothing was filled), and
// "physical_sanity" (processing::PhysicalSanity, brdf/processing/sanity.h).
void AddFillAndSanityJson(const std::string& path, Json* j) {
  const OpenedForView opened = OpenForView(path);
  if (!opened.measurement || !opened.resample_report) return;
  const processing::BeyondReport& beyond = opened.resample_report->beyond;
  (*j)["blind_spot_fill"] = beyond.used == processing::BeyondMethod::kClamp
                                ? Json(nullptr)
                                : Json::parse(processing::BeyondReportJson(beyond));
  (*j)["physical_sanity"] = Json::parse(processing::SanityReportJson(
      processing::PhysicalSanity(opened.lut, *opened.measurement, opened.theta_b_deg)));
}

Json DescribeBpc(const std::string& path, const Phrasing& say) {
  const CaptureAssessment a = AssessCapture(path);
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
  std::vector<std::string> refusals, export_refusals;
  for (const CaptureRefusal& refusal : a.refusals)
    refusals.push_back(say.Line(refusal.ToError(path)));
  for (const CaptureRefusal& refusal : a.export_refusals)
    export_refusals.push_back(say.Line(refusal.ToError(path)));
  AddRefusalsJson(refusals, &export_refusals, &j);
  j["planned_theta_in_deg"] = a.planned_theta_in_deg;
  j["plan_recorded"] = a.plan_recorded;
  j["missing_theta_in_deg"] = a.missing_theta_in_deg;
  j["warnings"] = a.warnings;
  if (!r.finished) {
    if (r.intact_data_after_damage) {
      j["advice"] = "intact slices follow damaged data; a resume would discard them: " +
                    say(Remedy{RemedyKind::kRepairCapture, path});
    } else {
      j["advice"] =
          std::string(truncated ? "the capture was interrupted" : "the capture is unfinished") +
          ": " + say(Remedy{RemedyKind::kResumeCapture, path, r.valid_bytes});
    }
  }
  if (a.usable()) AddFillAndSanityJson(path, &j);
  return j;
}

Json DescribeMaterial(const std::string& path) {
  const Material material = LoadMaterialInput(path);
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

Json DescribeImported(const std::string& path, ImportFormat format, const Phrasing& say) {
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
                      "): transmission data, shown mirrored into the reflection hemisphere; " +
                      say(Remedy{RemedyKind::kAllowBtdf, path});
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
      // Parsed and checked exactly as every evaluating reader loads it.
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
      j["advice"] = "an evaluable BRDF, not a point cloud: " +
                    say(Remedy{RemedyKind::kCaptureEvaluable, path});
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
      j["advice"] = "an evaluable BRDF, not a point cloud: " +
                    say(Remedy{RemedyKind::kCaptureEvaluable, path}) +
                    " (a capture flags the samples in unmeasured bins invalid)";
      break;
    }
    case ImportFormat::kAuto:
      break;
  }
  if (table_m) {
    AddPointCloudJson(*table_m, &j);
    // An evaluation resamples a table like a capture: the same checks (any θin set).
    processing::ResampleOptions any_theta_in;
    any_theta_in.require_uniform_theta_in = false;
    std::vector<std::string> refusals;
    for (const processing::LutInputProblem& p :
         processing::FindLutInputProblems(*table_m, any_theta_in))
      refusals.push_back(path + ": " + p.message);
    AddRefusalsJson(refusals, nullptr, &j);
  }
  return j;
}

Json CertifiedErrorJson(const exporter::CertifiedError& e) {
  const auto stats = [](const exporter::ErrorStatistics& s) {
    return Json{{"max", s.max}, {"p99", s.p99}, {"median", s.median}, {"texels", s.texels}};
  };
  Json j{{"format", e.format},
         {"bytes", e.bytes},
         {"rgb9e5_bytes", e.rgb9e5_bytes},
         {"theta_b_deg", e.theta_b_deg},
         {"measured", stats(e.measured)},
         {"filled", stats(e.filled)}};
  if (e.max_error_bound > 0) {
    j["max_error_bound"] = e.max_error_bound;
    j["max_error_met"] = e.max_error_met;
  }
  return j;
}

// An exported LUT or atlas (.ktx2, .dds) or the sidecar / manifest describing one. Value ranges
// are of the RGB9E5 values as stored (decoded exactly), per θin slice; for an atlas over the
// cells that hold a material.
Json DescribeTexture(const std::string& path) {
  const OpenedTexture t = OpenExportedTexture(path);
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
    if (!t.sidecar->beyond_json.empty()) j["blind_spot_fill"] = Json::parse(t.sidecar->beyond_json);
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

// A compact LUT (.brdfc): the same members as DescribeTexture's for a LUT, from the container
// and its embedded sidecar; value ranges of the decoded texel centres.
Json DescribeCompact(const std::string& path) {
  const exporter::LoadedCompact c = exporter::ReadCompactLutFile(path);
  const exporter::CompactLut& lut = c.compact;
  Json j;
  j["file"] = path;
  j["format"] = "lut";
  j["texture_file"] = path;
  j["container"] = std::string("compact LUT (BRDFCLUT, log2 grid, ") +
                   (lut.mirrored ? "mirrored phi_d 0-180" : "phi_d 0-360") + ")";
  j["texel_format"] = "compact log grid";
  j["file_bytes"] = std::filesystem::file_size(path);
  j["width"] = Lut::kWidth;
  j["height"] = Lut::kHeight;
  j["slices"] = lut.slices();
  j["theta_in_deg"] = lut.theta_in_deg;
  j["theta_in_from_metadata"] = true;
  j["payload_bytes"] = lut.PayloadBytes();
  j["payload_crc32"] = Hex32Text(exporter::CompactPayloadCrc32(lut));
  j["checksum"] = "verified against the recorded CRC-32";
  j["grid"] = Json::array();
  for (int k = 0; k < lut.slices(); ++k)
    j["grid"].push_back({{"theta_in_deg", lut.theta_in_deg[k]},
                         {"rows", lut.rows[k].size()},
                         {"columns", lut.cols[k].size()}});
  if (!c.sidecar_json.empty()) {
    const exporter::SidecarInfo info = exporter::ParseSidecarJson(c.sidecar_json, path);
    j["name"] = info.name;
    j["source"] = info.source;
    j["tool_version"] = info.tool_version;
    if (info.extrapolation)
      j["extrapolation"] = {{"p", info.extrapolation->p},
                            {"l", info.extrapolation->l},
                            {"theta_b_deg", info.extrapolation->theta_b_deg}};
    else
      j["extrapolation"] = nullptr;
    j["files"] = info.files;
    if (info.certified_error) j["certified_error"] = CertifiedErrorJson(*info.certified_error);
  }
  const std::vector<float> texels = lut.DecodeTexels();
  j["value_ranges"] = Json::array();
  const std::size_t per_slice = static_cast<std::size_t>(Lut::kHeight) * Lut::kWidth;
  for (int k = 0; k < lut.slices(); ++k) {
    std::array<double, 3> lo{}, hi{}, sum{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t t = 0; t < per_slice; ++t)
      for (int ch = 0; ch < 3; ++ch) {
        const double v = texels[(k * per_slice + t) * 3 + ch];
        lo[ch] = std::min(lo[ch], v), hi[ch] = std::max(hi[ch], v), sum[ch] += v;
      }
    std::array<double, 3> mean{};
    for (int ch = 0; ch < 3; ++ch) mean[ch] = sum[ch] / static_cast<double>(per_slice);
    j["value_ranges"].push_back({{"theta_in_deg", Number(lut.theta_in_deg[k])},
                                 {"rgb_min", Triple(lo)},
                                 {"rgb_max", Triple(hi)},
                                 {"rgb_mean", Triple(mean)}});
  }
  j["warnings"] = Json::array();
  return j;
}

}  // namespace

std::string DescribeFile(const std::string& file_or_name, const RemedyPhrasing& phrase) {
  // A library material name stands for its file (brdf/sources/material_library.h).
  const std::string file = ResolveSource(file_or_name);
  const FileKind kind = DetectFileKind(file);
  const Phrasing say{phrase};
  Json j;
  if (kind == FileKind::kCapture) {
    j = DescribeBpc(file, say);
  } else if (kind == FileKind::kMaterial) {
    j = DescribeMaterial(file);
  } else if (kind == FileKind::kSidecar && CompactLutOfSidecar(file)) {
    j = DescribeCompact(*CompactLutOfSidecar(file));
    j["json_file"] = file;
  } else if (IsExportedLut(kind)) {
    j = DescribeTexture(file);
  } else if (kind == FileKind::kCompactLut) {
    j = DescribeCompact(file);
  } else if (const std::optional<ImportFormat> format = ImportFormatOf(kind)) {
    j = DescribeImported(file, *format, say);
  } else {
    throw InvalidArgument(
        file + ": a " + std::string(FileKindName(kind)) +
        "; a description covers captures (.bpc), material files, exported "
        "LUTs (.ktx2, .dds, .brdfc, sidecar and atlas manifest .json), RGL .bsdf, MERL "
        ".binary, Zemax and LightTools BSDF tables, CSV point clouds and "
        "goniometer tables");
  }
  return j.dump(2, ' ', false, Json::error_handler_t::replace);
}

}  // namespace brdf::sources
