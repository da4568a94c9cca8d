// `brdf info FILE [--json]`: what a file holds. The description is the library's
// (brdf/sources/describe.h: one JSON document); --json prints it, the text form is printed from
// the same document, so the two views can never disagree.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "brdf/sources/describe.h"
#include "brdf/sources/material_library.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

namespace {

using Json = nlohmann::ordered_json;

bool IsImportedFormat(const Json& j) {
  const std::string f = j["format"].get<std::string>();
  return f == "zemax" || f == "lighttools" || f == "csv" || f == "gonio" || f == "rgl" ||
         f == "merl";
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

// Which commands the verdict speaks for: convert reads captures (and material files), a
// third-party table is evaluated directly and converted only after 'brdf import'; a capture
// refused by the LUT exports alone (θin not k·Δin) is evaluated by every other command.
const char* JudgingCommands(const Json& j) {
  if (IsImportedFormat(j)) return "'brdf eval'";
  if (j.value("evaluable", true) && !j.value("convertible", true))
    return "'brdf convert' and 'brdf atlas'";
  return "'brdf convert' and 'brdf eval'";
}

// "s" when JudgingCommands names one command.
const char* VerbS(const Json& j) { return IsImportedFormat(j) ? "s" : ""; }

void PrintRefusalsText(const Json& j) {
  if (j.contains("warnings"))
    for (const auto& w : j["warnings"]) std::printf("%s\n", w.get<std::string>().c_str());
  if (!j.contains("refusals")) return;
  if (j["refusals"].empty()) {
    std::printf("usable: yes (%s accept%s it)\n", JudgingCommands(j), VerbS(j));
    return;
  }
  std::printf("usable: no; %s refuse%s it: %zu reason%s\n", JudgingCommands(j), VerbS(j),
              j["refusals"].size(), j["refusals"].size() == 1 ? "" : "s");
  for (const auto& r : j["refusals"]) std::printf("  %s\n", r.get<std::string>().c_str());
  if (j.value("evaluable", false) && !j.value("convertible", true))
    std::printf(
        "evaluable: yes ('brdf eval', 'brdf preview', 'brdf fit' and brdf-view accept it; only "
        "the LUT textures need θin = k·Δin)\n");
}

std::string Percent(const Json& v) {
  return v.is_null() ? "-" : Fixed(Json(100.0 * v.get<double>()), "%.3g") + " %";
}

std::string DegreeList(const Json& v) {
  std::string out;
  for (const auto& t : v) out += (out.empty() ? "" : ", ") + Fixed(t, "%g");
  return out.empty() ? "none" : out;
}

// The blind-spot fill's record (a capture's, or a sidecar's): method, slices, validation.
void PrintFillText(const Json& j, const char* indent) {
  if (!j.contains("blind_spot_fill")) return;
  const Json& b = j["blind_spot_fill"];
  if (b.is_null()) {
    std::printf("%sblind-spot fill: none (clamp: the last slice is read beyond it)\n", indent);
    return;
  }
  std::string method = b["method"].get<std::string>();
  if (b["model"].is_object() && b["model"].contains("model"))
    method += " (" + b["model"]["model"].get<std::string>() + ")";
  std::printf("%sblind-spot fill: %s; theta_in measured %s deg, inserted %s, extrapolated %s\n",
              indent, method.c_str(), DegreeList(b["measured_theta_in"]).c_str(),
              DegreeList(b["inserted_theta_in"]).c_str(),
              DegreeList(b["extrapolated_theta_in"]).c_str());
  const Json& v = b["leave_last_slice_out"];
  if (v.is_object())
    std::printf(
        "%s  leave-last-slice-out: theta_in %s deg predicted from the others, relative error "
        "median %s, p90 %s over %s texels\n",
        indent, Fixed(v["theta_in"], "%g").c_str(), Percent(v["median_relative_error"]).c_str(),
        Percent(v["p90_relative_error"]).c_str(), v["texels"].dump().c_str());
  else
    std::printf("%s  leave-last-slice-out: not validated (fewer than 3 measured slices)\n", indent);
}

// The physical sanity report (brdf/processing/sanity.h), one line per LUT slice.
void PrintSanityText(const Json& j) {
  if (!j.contains("physical_sanity")) return;
  const Json& p = j["physical_sanity"];
  std::printf(
      "physical sanity (light at theta_in, phi_in 0; albedo r g b = measured part, theta_out "
      "<= %s deg, + filled part):\n",
      Fixed(p["theta_b_deg"], "%g").c_str());
  std::size_t flagged = 0;
  for (const Json& s : p["slices"]) {
    std::string recip = "no pair measured both ways";
    if (s["reciprocity"].is_object())
      recip = "reciprocity residual median " + Percent(s["reciprocity"]["median_relative"]) +
              ", max " + Percent(s["reciprocity"]["max_relative"]) + " over " +
              s["reciprocity"]["pairs"].dump() + " pairs";
    std::printf("  theta_in %s deg (%s): albedo %s + %s; %s", Fixed(s["theta_in"], "%g").c_str(),
                s["measured"].get<bool>() ? "measured" : "filled",
                TripleText(s["albedo_measured"]).c_str(), TripleText(s["albedo_filled"]).c_str(),
                recip.c_str());
    if (s["measured"].get<bool>())
      std::printf("; saturated %s, below noise %s", s["saturated"].dump().c_str(),
                  s["below_noise_floor"].dump().c_str());
    std::printf("%s\n", s["energy_flag"].get<bool>() ? "; ENERGY: albedo above 1" : "");
    flagged += s["energy_flag"].get<bool>();
  }
  std::printf("  energy: %s\n", flagged
                                    ? "albedo above 1 beyond the noise in the slices marked ENERGY"
                                    : "albedo within 1 + noise in every slice");
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
    // "none" only when nothing else is wrong either: the refusals follow.
    std::printf(j["refusals"].empty() ? "problems: none\n" : "damage: none (chunks intact)\n");
  } else {
    std::printf("problems: %zu\n", j["problems"].size());
    for (const Json& p : j["problems"])
      std::printf("  %s\n", p["message"].get<std::string>().c_str());
  }
  PrintRefusalsText(j);
  PrintFillText(j, "");
  PrintSanityText(j);
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
    if (e.contains("max_error_bound"))
      std::printf("  chosen by      --max-error %s: %s\n",
                  Fixed(e["max_error_bound"], "%g").c_str(),
                  e["max_error_met"].get<bool>() ? "met" : "NOT met (the most precise form)");
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
  PrintFillText(j, "  ");
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
        const Json& c = m["certified_error"];
        const Json& e = c["measured"];
        const std::string format = c["format"].get<std::string>();
        // An atlas is BC6H, or RGB9E5 when --max-error found BC6H above its bound.
        std::printf(
            "      certified %s error, measured range: max %.3g %%, p99 %.3g %%, median "
            "%.3g %%%s\n",
            format == "rgb9e5"        ? "RGB9E5"
            : format == "bc6h_ufloat" ? "BC6H"
                                      : format.c_str(),
            100.0 * e["max"].get<double>(), 100.0 * e["p99"].get<double>(),
            100.0 * e["median"].get<double>(),
            !c.contains("max_error_bound")   ? ""
            : c["max_error_met"].get<bool>() ? " (within --max-error)"
                                             : " (above --max-error)");
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
  const std::string file = sources::ResolveSource(options.file);
  const Json j = Json::parse(
      sources::DescribeFile(file, [](const Remedy& remedy) { return RemedyText(remedy, "info"); }));
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
                 n == 1 ? "" : "s", JudgingCommands(j), VerbS(j),
                 options.json ? " (listed under \"refusals\")" : " (listed above)");
    return 1;
  }
  return 0;
}

}  // namespace brdf::cli
