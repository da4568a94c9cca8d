#include "brdf/exporter/sidecar.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "json_util.h"

namespace brdf::exporter {

using nlohmann::ordered_json;

namespace {

std::string SidecarText(const detail::PayloadSummary& payload,
                        const std::vector<double>& theta_in_deg, const TextureMetadata& metadata) {
  ordered_json j;
  j["kind"] = "brdf-lut-sidecar";
  j["format_version"] = 1;
  j["name"] = metadata.name;
  j["source"] = metadata.source;
  j["theta_in_deg"] = theta_in_deg;
  j["grid"] = detail::GridJson(payload, theta_in_deg);
  j["values"] = "f_r in 1/sr, linear Rec.709 RGB, not multiplied by cos(theta)";
  j["texel_convention"] = detail::TexelConventionJson(theta_in_deg);
  if (metadata.extrapolation) {
    j["extrapolation"] = detail::ExtrapolationJson(*metadata.extrapolation);
  } else {
    j["extrapolation"] = nullptr;
  }
  if (metadata.saturated_samples) {
    j["saturated_samples"] = detail::SaturatedCountsJson(*metadata.saturated_samples);
  }
  j["fitted_models"] = ordered_json::array();
  for (const std::string& text : metadata.fitted_models_json)
    j["fitted_models"].push_back(detail::ParseEmbeddedJson(text, "fitted model"));
  if (!metadata.beyond_json.empty())
    j["beyond"] = detail::ParseEmbeddedJson(metadata.beyond_json, "blind-spot fill record");
  j["tool"] = {
      {"name", "brdf-toolchain"},
      {"version", metadata.tool_version.empty() ? BrdfToolVersion() : metadata.tool_version}};
  j["payload"] = detail::PayloadJson(payload);
  if (metadata.certified_error)
    j["compression"] = detail::CertifiedErrorJson(*metadata.certified_error);
  j["files"] = metadata.companion_files;
  return j.dump(2) + "\n";
}

}  // namespace

std::string SidecarJson(const PackedVolume& payload, const std::vector<double>& theta_in_deg,
                        const TextureMetadata& metadata) {
  return SidecarText(detail::Summarize(payload), theta_in_deg, metadata);
}

std::string SidecarJson(const Bc6hVolume& payload, const std::vector<double>& theta_in_deg,
                        const TextureMetadata& metadata) {
  return SidecarText(detail::Summarize(payload), theta_in_deg, metadata);
}

std::string SidecarJson(const CompactLut& payload, const TextureMetadata& metadata) {
  return SidecarText(detail::Summarize(payload), payload.theta_in_deg, metadata);
}

void WriteSidecar(const std::string& path, const PackedVolume& payload,
                  const std::vector<double>& theta_in_deg, const TextureMetadata& metadata) {
  WriteFileAtomically(path, SidecarJson(payload, theta_in_deg, metadata));
}

void WriteSidecar(const std::string& path, const Bc6hVolume& payload,
                  const std::vector<double>& theta_in_deg, const TextureMetadata& metadata) {
  WriteFileAtomically(path, SidecarJson(payload, theta_in_deg, metadata));
}

SidecarInfo ParseSidecarJson(std::string_view json_text, const std::string& file) {
  const ordered_json j = detail::ParseJsonDocument(json_text, file);
  detail::JsonFields f(j, file);
  if (f.String("kind") != "brdf-lut-sidecar")
    throw FormatError(file, "member 'kind'", "\"brdf-lut-sidecar\"", j["kind"].dump());
  SidecarInfo info;
  info.name = f.String("name");
  info.source = f.String("source");
  info.theta_in_deg = f.NumberArray("theta_in_deg");
  const auto grid = f.Object("grid");
  detail::JsonFields g(grid, file, "grid.");
  info.width = g.Int("width");
  info.height = g.Int("height");
  info.slices = g.Int("slices");
  if (static_cast<std::size_t>(info.slices) != info.theta_in_deg.size())
    throw FormatError(
        file, "member 'grid.slices'",
        fmt::format("the number of theta_in_deg values ({})", info.theta_in_deg.size()),
        std::to_string(info.slices));
  // θin must be k·Δin (docs/design.md §5): the shader addresses slice k as θin/Δin, so a list
  // that is not 0, Δ, 2Δ, ... would put every value at the wrong incidence.
  {
    const std::vector<double>& t = info.theta_in_deg;
    const double delta = t.size() >= 2 ? t[1] - t[0] : 0.0;
    bool ok = !t.empty() && std::isfinite(delta) && (t.size() < 2 || delta > 0.0);
    for (std::size_t k = 0; ok && k < t.size(); ++k)
      ok = std::isfinite(t[k]) && std::abs(t[k] - static_cast<double>(k) * delta) <= 1e-3;
    if (ok && grid.contains("delta_in_deg") && t.size() >= 2)
      ok = std::abs(g.Number("delta_in_deg") - delta) <= 1e-3;
    if (!ok) {
      std::string got;
      for (const double v : t) got += (got.empty() ? "" : ", ") + fmt::format("{:g}", v);
      throw FormatError(file, "member 'theta_in_deg'",
                        "k * delta_in_deg for k = 0, 1, ... (e.g. 0, 20, 40, 60)", "[" + got + "]");
    }
  }
  if (j.contains("extrapolation") && !j["extrapolation"].is_null()) {
    detail::JsonFields e(f.Object("extrapolation"), file, "extrapolation.");
    info.extrapolation = ExtrapolationInfo{e.Number("p"), e.Number("l"), e.Number("theta_b_deg")};
  }
  if (j.contains("saturated_samples"))
    info.saturated_samples =
        detail::ParseSaturatedCounts(j["saturated_samples"], file, "saturated_samples");
  if (j.contains("fitted_models")) {
    if (!j["fitted_models"].is_array())
      throw FormatError(file, "member 'fitted_models'", "an array", j["fitted_models"].type_name());
    for (const auto& m : j["fitted_models"]) info.fitted_models_json.push_back(m.dump());
  }
  if (j.contains("beyond") && j["beyond"].is_object()) info.beyond_json = j["beyond"].dump();
  detail::JsonFields t(f.Object("tool"), file, "tool.");
  info.tool_version = t.String("version");
  detail::JsonFields p(f.Object("payload"), file, "payload.");
  info.payload_bytes = p.UInt64("bytes");
  const ordered_json& payload = f.Object("payload");
  if (payload.contains("format")) info.payload_format = p.String("format");
  if (info.payload_format != "rgb9e5" && info.payload_format != "bc6h_ufloat" &&
      info.payload_format != "compact_log_grid")
    throw FormatError(file, "member 'payload.format'",
                      "\"rgb9e5\", \"bc6h_ufloat\" or \"compact_log_grid\"",
                      "\"" + info.payload_format + "\"");
  const std::uint64_t w = static_cast<std::uint64_t>(std::max(info.width, 0)),
                      h = static_cast<std::uint64_t>(std::max(info.height, 0)),
                      d = static_cast<std::uint64_t>(std::max(info.slices, 0));
  if (info.payload_format == "compact_log_grid") {
    // Any size: the grid adapts to the data (the container checks itself).
  } else if (info.payload_format == "bc6h_ufloat") {
    const std::uint64_t blocks = (w + 3) / 4 * ((h + 3) / 4) * d;
    if (info.payload_bytes != blocks * 16)
      throw FormatError(file, "member 'payload.bytes'",
                        fmt::format("ceil(width/4) * ceil(height/4) * slices * 16 = {} * {} * {} "
                                    "* 16 = {} (BC6H blocks)",
                                    (w + 3) / 4, (h + 3) / 4, d, blocks * 16),
                        std::to_string(info.payload_bytes));
  } else if (info.payload_bytes != w * h * d * 4) {
    throw FormatError(file, "member 'payload.bytes'",
                      fmt::format("width * height * slices * 4 = {} * {} * {} * 4 = {}", info.width,
                                  info.height, info.slices, w * h * d * 4),
                      std::to_string(info.payload_bytes));
  }
  if (j.contains("compression"))
    info.certified_error = detail::ParseCertifiedError(f.Object("compression"), file);
  detail::JsonFields c(p.Object("checksum"), file, "payload.checksum.");
  if (c.String("algorithm") != "crc32")
    throw FormatError(file, "member 'payload.checksum.algorithm'", "\"crc32\"",
                      "\"" + c.String("algorithm") + "\"");
  info.payload_crc32 =
      detail::ParseHex32(c.String("value"), file, "member 'payload.checksum.value'");
  if (j.contains("files")) info.files = f.StringArray("files");
  return info;
}

SidecarInfo ReadSidecar(const std::string& path) {
  return ParseSidecarJson(ReadFileText(path, 16u << 20), path);
}

}  // namespace brdf::exporter
