#include "json_util.h"

#include <cmath>
#include <limits>

#include "brdf/core/error.h"
#include "brdf/core/json_error.h"
#include "brdf/core/text_format.h"
#include "brdf/exporter/metadata.h"

namespace brdf::exporter::detail {

PayloadSummary Summarize(const PackedVolume& payload) {
  return {false, payload.width, payload.height, payload.depth, payload.ByteSize(), payload.Crc32()};
}

PayloadSummary Summarize(const Bc6hVolume& payload) {
  return {true, payload.width, payload.height, payload.depth, payload.ByteSize(), payload.Crc32()};
}

PayloadSummary Summarize(const CompactLut& payload) {
  PayloadSummary s{false,
                   Lut::kWidth,
                   Lut::kHeight,
                   payload.slices(),
                   payload.PayloadBytes(),
                   CompactPayloadCrc32(payload)};
  s.compact = true;
  return s;
}

ordered_json GridJson(const PayloadSummary& payload, const std::vector<double>& theta_in_deg) {
  const double delta = theta_in_deg.size() >= 2 ? theta_in_deg[1] - theta_in_deg[0] : 0.0;
  return ordered_json{
      {"frame",
       "specular frame of theta_in (docs/design.md §5): omega_d = S(theta_in) omega_out, "
       "S = [[-cos, 0, -sin], [0, -1, 0], [-sin, 0, cos]]; phi_in = 0"},
      {"width", payload.width},
      {"height", payload.height},
      {"slices", payload.depth},
      {"phi_d_deg", {{"first", 0}, {"step", 1}, {"count", 361}}},
      {"theta_d_deg", {{"first", 0}, {"step", 1}, {"count", 181}}},
      {"delta_in_deg", delta},
      {"seam", "column 360 repeats column 0 (phi_d = 360 deg = 0 deg)"},
      {"below_horizon",
       "edge extension: theta_out > 90 deg holds the value at theta_out = 90 deg "
       "with the same phi_out"}};
}

ordered_json TexelConventionJson(const std::vector<double>& theta_in_deg) {
  return ordered_json{{"centre_exact", TexelCentreFormula()},
                      {"published", PublishedFormula()},
                      {"glsl", ShaderSnippetGlsl(theta_in_deg)}};
}

std::uint32_t ParseHex32(const std::string& text, const std::string& file,
                         const std::string& position) {
  const bool ok = text.size() == 10 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X') &&
                  text.find_first_not_of("0123456789abcdefABCDEF", 2) == std::string::npos;
  if (!ok)
    throw FormatError(file, position, "a hexadecimal \"0x\" + 8 digits value", "\"" + text + "\"");
  return static_cast<std::uint32_t>(std::stoul(text.substr(2), nullptr, 16));
}

ordered_json PayloadJson(const PayloadSummary& payload) {
  ordered_json j;
  if (payload.compact) {
    j["format"] = "compact_log_grid";
    j["encoding"] =
        "per theta_in slice a grid of kept theta_d rows and phi_d columns holding half floats "
        "g = log2(f/S + eps), read bilinearly in g (docs/formats/compact.md)";
    j["texel_order"] =
        "the .brdfc container: header, theta_in list, per-slice row and column lists, then "
        "each slice's grid row by row, columns fastest, R, G, B";
  } else if (payload.bc6h) {
    j["format"] = "bc6h_ufloat";
    j["encoding"] =
        "BC6H_UF16 blocks per ARB_texture_compression_bptc (BPTC_FLOAT, unsigned): "
        "VK_FORMAT_BC6H_UFLOAT_BLOCK (131), DXGI_FORMAT_BC6H_UF16 (95); 16 bytes per 4 x 4 "
        "texels, each slice padded to ceil(width/4) x ceil(height/4) blocks with copies of its "
        "nearest texels";
    j["texel_order"] =
        "blocks left to right, block rows top first, then z (theta_in slices, ascending)";
  } else {
    j["encoding"] =
        "RGB9E5 per EXT_texture_shared_exponent (N=9, B=15, Emax=31): "
        "VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 (123), DXGI_FORMAT_R9G9B9E5_SHAREDEXP (67); "
        "R bits 0-8, G 9-17, B 18-26, exponent 27-31";
    j["texel_order"] =
        "32-bit little-endian words; x (phi_d) fastest, then y (theta_d rows, top "
        "first), then z (theta_in slices, ascending)";
  }
  j["bytes"] = payload.bytes;
  j["checksum"] = {{"algorithm", "crc32"},
                   {"definition",
                    "CRC-32 (IEEE 802.3, polynomial 0xEDB88320 reflected, as zlib crc32) of "
                    "the payload bytes as stored in the KTX2 level 0 image and the DDS data (of a "
                    ".brdfc file: its bytes from offset 36 to the end of the grid values)"},
                   {"value", Hex32Text(payload.crc32)}};
  return j;
}

namespace {

ordered_json StatisticsJson(const ErrorStatistics& s) {
  return ordered_json{{"max", s.max}, {"p99", s.p99}, {"median", s.median}, {"texels", s.texels}};
}

ErrorStatistics ParseStatistics(const ordered_json& object, const std::string& file,
                                const std::string& prefix) {
  JsonFields f(object, file, prefix);
  return {f.Number("max"), f.Number("p99"), f.Number("median"), f.UInt64("texels")};
}

}  // namespace

ordered_json CertifiedErrorJson(const CertifiedError& e) {
  ordered_json j{
      {"format", e.format},
      {"bytes", e.bytes},
      {"rgb9e5_bytes", e.rgb9e5_bytes},
      {"certified_error",
       {{"definition",
         "relative error of each texel of the payload as a GPU decodes it against the float "
         "LUT clamped to [0, 65504]: max over R, G, B of |decoded - reference| / max(largest "
         "reference channel, 1e-4 * the LUT's largest reference value, 2^-14)"},
        {"theta_b_deg", e.theta_b_deg},
        {"measured", StatisticsJson(e.measured)},
        {"filled", StatisticsJson(e.filled)}}}};
  if (e.max_error_bound > 0) {
    j["max_error_bound"] = e.max_error_bound;
    j["max_error_met"] = e.max_error_met;
  }
  return j;
}

CertifiedError ParseCertifiedError(const ordered_json& object, const std::string& file) {
  JsonFields f(object, file, "compression.");
  CertifiedError e;
  e.format = f.String("format");
  e.bytes = f.UInt64("bytes");
  e.rgb9e5_bytes = f.UInt64("rgb9e5_bytes");
  const ordered_json& c = f.Object("certified_error");
  JsonFields cf(c, file, "compression.certified_error.");
  e.theta_b_deg = cf.Number("theta_b_deg");
  e.measured =
      ParseStatistics(cf.Object("measured"), file, "compression.certified_error.measured.");
  e.filled = ParseStatistics(cf.Object("filled"), file, "compression.certified_error.filled.");
  if (object.contains("max_error_bound")) {
    e.max_error_bound = f.Number("max_error_bound");
    e.max_error_met = e.measured.max <= e.max_error_bound;
  }
  return e;
}

ordered_json ParseEmbeddedJson(const std::string& text, const std::string& what) {
  // The text comes from the caller (a fitted model to record), not from a file: a bad one is
  // a bad argument, described as a file's JSON would be.
  try {
    return ordered_json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InvalidArgument(JsonSyntaxError(what, text, e.byte).what());
  } catch (const nlohmann::json::out_of_range&) {
    throw InvalidArgument(JsonNumberTooLargeError(what, text).what());
  }
}

ordered_json ParseJsonDocument(std::string_view text, const std::string& file) {
  ordered_json j;
  try {
    j = ordered_json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw JsonSyntaxError(file, text, e.byte);
  } catch (const nlohmann::json::out_of_range&) {
    throw JsonNumberTooLargeError(file, text);
  }
  if (!j.is_object()) throw FormatError(file, "top level", "a JSON object", j.type_name());
  return j;
}

JsonFields::JsonFields(const ordered_json& object, std::string file, std::string prefix)
    : object_(object), file_(std::move(file)), prefix_(std::move(prefix)) {}

void JsonFields::Fail(const char* name, const std::string& expected) const {
  const std::string got =
      !object_.contains(name) ? std::string("nothing (member missing)") : object_[name].dump();
  throw FormatError(file_, "member '" + prefix_ + name + "'", expected,
                    got.size() > 80 ? got.substr(0, 77) + "..." : got);
}

const ordered_json& JsonFields::Get(const char* name) const {
  if (!object_.is_object() || !object_.contains(name)) Fail(name, "a value");
  return object_[name];
}

std::string JsonFields::String(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_string()) Fail(name, "a string");
  return object_[name].get<std::string>();
}

double JsonFields::Number(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_number()) Fail(name, "a number");
  return object_[name].get<double>();
}

int JsonFields::Int(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_number_integer()) Fail(name, "an integer");
  const auto v = object_[name].get<std::int64_t>();
  if (v < 0 || v > std::numeric_limits<int>::max()) Fail(name, "a non-negative integer");
  return static_cast<int>(v);
}

std::uint64_t JsonFields::UInt64(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_number_unsigned())
    Fail(name, "a non-negative integer");
  return object_[name].get<std::uint64_t>();
}

const ordered_json& JsonFields::Object(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_object()) Fail(name, "an object");
  return object_[name];
}

std::vector<double> JsonFields::NumberArray(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_array()) Fail(name, "an array of numbers");
  std::vector<double> out;
  for (const auto& v : object_[name]) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) Fail(name, "an array of numbers");
    out.push_back(v.get<double>());
  }
  return out;
}

std::vector<std::string> JsonFields::StringArray(const char* name) const {
  if (!object_.contains(name) || !object_[name].is_array()) Fail(name, "an array of strings");
  std::vector<std::string> out;
  for (const auto& v : object_[name]) {
    if (!v.is_string()) Fail(name, "an array of strings");
    out.push_back(v.get<std::string>());
  }
  return out;
}

ordered_json ExtrapolationJson(const ExtrapolationInfo& e) {
  return {{"method",
           "restricted quadratic Bezier beyond the last measured theta_out (docs/design.md §6)"},
          {"p", e.p},
          {"l", e.l},
          {"theta_b_deg", e.theta_b_deg}};
}

ordered_json SaturatedCountsJson(const std::vector<SaturatedCount>& counts) {
  ordered_json a = ordered_json::array();
  for (const SaturatedCount& c : counts)
    a.push_back({{"theta_in_deg", c.theta_in_deg}, {"count", c.count}});
  return a;
}

std::vector<SaturatedCount> ParseSaturatedCounts(const ordered_json& array, const std::string& file,
                                                 const std::string& member) {
  if (!array.is_array())
    throw FormatError(file, "member '" + member + "'", "an array", array.type_name());
  std::vector<SaturatedCount> counts;
  for (std::size_t k = 0; k < array.size(); ++k) {
    const std::string item = member + "[" + std::to_string(k) + "]";
    if (!array[k].is_object())
      throw FormatError(file, "member '" + item + "'", "an object with theta_in_deg and count",
                        array[k].type_name());
    JsonFields f(array[k], file, item + ".");
    counts.push_back({f.Number("theta_in_deg"), f.UInt64("count")});
  }
  return counts;
}

}  // namespace brdf::exporter::detail
