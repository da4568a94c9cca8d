// `brdf info FILE [--json]`: what a file holds. Dispatches on the file extension; each format
// has one describer below that fills a JSON document, and the text form is printed from the
// same document so the two views can never disagree.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kFlagNames[4] = {"saturated", "below_noise_floor", "interpolated", "invalid"};

// Non-finite statistics (a capture holding inf or NaN) become JSON null instead of invalid JSON.
Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json Triple(const std::array<double, 3>& v) { return {Number(v[0]), Number(v[1]), Number(v[2])}; }

Json MetadataJson(const Metadata& m) {
  Json j;
  j["sample_name"] = m.sample_name;
  j["instrument_model"] = m.instrument_model;
  j["instrument_serial"] = m.instrument_serial;
  j["firmware_version"] = m.firmware_version;
  j["protocol_version"] = m.protocol_version;
  j["calibration_reference"] = m.calibration_reference;
  j["calibration_time"] = m.calibration_time;
  j["capture_start"] = m.capture_start;
  j["capture_end"] = m.capture_end;
  j["operator_notes"] = m.operator_notes;
  j["units"] = m.units;
  j["software_version"] = m.software_version;
  j["extra"] = Json::object();
  for (const auto& [k, v] : m.extra) j["extra"][k] = v;
  return j;
}

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

Json DescribeBpc(const std::string& path) {
  const BpcReadResult r = ReadBpc(path);
  const Measurement& m = r.measurement;
  Json j;
  j["file"] = path;
  j["format"] = "bpc";
  j["file_bytes"] = std::filesystem::file_size(path);
  j["finished"] = r.finished;
  j["valid_bytes"] = r.valid_bytes;
  j["theta_in_deg"] = m.ThetaInDeg();
  j["sample_count"] = m.SampleCount();
  std::array<std::size_t, 4> totals{};
  j["slices"] = Json::array();
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    const Slice& slice = m.slices[i];
    const SliceStats st = ComputeSliceStats(slice);
    Json s;
    s["index"] = r.slice_indices[i];
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
    j["slices"].push_back(s);
  }
  Json flags;
  for (int b = 0; b < 4; ++b) flags[kFlagNames[b]] = totals[b];
  j["flag_counts"] = flags;
  j["metadata"] = MetadataJson(m.metadata);
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
  if (!r.finished) {
    if (r.intact_data_after_damage) {
      j["advice"] =
          "intact slices follow damaged data; a resume would discard them. Rewrite the "
          "intact slices to a new file instead.";
    } else {
      j["advice"] =
          std::string(truncated ? "the capture was interrupted" : "the capture is unfinished") +
          ": to continue it, rerun the same 'brdf capture ... --out " + path +
          "' command with --resume (the file is cut back to its " + std::to_string(r.valid_bytes) +
          " intact bytes first)";
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
  // The canonical form names the parameters as DESIGN §9 spells them (grey ones as a scalar);
  // they are listed here as RGB triples in that order.
  static const std::set<std::string> kParameterNames = {"rho", "kd",    "ks",    "n",
                                                        "f0",  "alpha", "rho_d", "rho_s"};
  const Json canonical = Json::parse(MaterialToJson(material));
  Json parameters = Json::object();
  for (const auto& [key, value] : canonical.items()) {
    if (kParameterNames.count(key) == 0) continue;
    parameters[key] = value.is_number() ? Json{value, value, value} : value;
  }
  j["name"] = material.name;
  j["description"] = material.description;
  j["parameters"] = parameters;
  j["physical_problems"] = PhysicalProblems(material);
  return j;
}

// Describers by extension. Other formats (.ktx2, .dds, export sidecars) add a row here; a
// .json is a material file when it has a "model" member.
struct Describer {
  const char* extension;
  Json (*describe)(const std::string& path);
};
constexpr Describer kDescribers[] = {
    {".bpc", DescribeBpc},
    {".json", DescribeMaterial},
};

std::string Fixed(const Json& v, const char* format = "%.6g") {
  if (v.is_null()) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v.get<double>());
  return buf;
}

std::string TripleText(const Json& v) {
  return Fixed(v[0]) + " " + Fixed(v[1]) + " " + Fixed(v[2]);
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
    std::printf("  %-12s %s\n", key.c_str(), TripleText(value).c_str());
  for (const auto& p : j["physical_problems"])
    std::printf("  not physical: %s\n", p.get<std::string>().c_str());
}

}  // namespace

int RunInfo(const InfoOptions& options) {
  const std::string ext = LowerExtension(options.file);
  for (const Describer& d : kDescribers) {
    if (ext != d.extension) continue;
    const Json j = d.describe(options.file);
    if (options.json) {
      std::printf("%s\n", j.dump(2, ' ', false, Json::error_handler_t::replace).c_str());
    } else if (j["format"] == "bpc") {
      PrintBpcText(j);
    } else {
      PrintMaterialText(j);
    }
    return 0;
  }
  std::string known;
  for (const Describer& d : kDescribers)
    known += (known.empty() ? "" : ", ") + std::string(d.extension);
  throw InvalidArgument(options.file + ": unknown file type '" + ext + "' (brdf info reads " +
                        known + ")");
}

}  // namespace brdf::cli
