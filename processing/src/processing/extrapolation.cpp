#include "brdf/processing/extrapolation.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/json_error.h"
#include "brdf/core/text_format.h"

namespace brdf::processing {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Parses one whole decimal number; false if anything but a finite number is there.
bool ParseNumber(std::string_view text, double& out) {
  const std::string s(Trim(text));
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
  out = v;
  return true;
}

constexpr std::uint64_t kMaxJsonBytes = 1u << 20;

}  // namespace

void ExtrapolationParams::Validate() const {
  if (!(std::isfinite(p) && p >= 0.0))
    throw InvalidArgument(
        "extrapolation parameter p must be a finite number >= 0 (docs/design.md §6), got " +
        ExactNumberText(p));
  if (!(l >= 0.0 && l <= 1.0))
    throw InvalidArgument("extrapolation parameter l must be in [0, 1] (docs/design.md §6), got " +
                          ExactNumberText(l));
}

double BezierB(double x, double l) {
  if (std::isnan(x)) throw InvalidArgument("BezierB: x must be a number in [0, 1], got NaN");
  if (!(l >= 0.0 && l <= 1.0))
    throw InvalidArgument("BezierB: l must be in [0, 1] (docs/design.md §6), got " +
                          ExactNumberText(l));
  x = std::clamp(x, 0.0, 1.0);
  if (x == 0.0) return 0.0;  // t = 0; also avoids 0/0 when l = 0
  // Root of x(t) = (1 − 2l)t² + 2l·t in the conjugate form of docs/design.md §6: well defined at l
  // = ½ where the quadratic degenerates, and l² + (1 − 2l)x ≥ min(l², (1 − l)²) ≥ 0 on [0, 1].
  const double t = std::clamp(x / (l + std::sqrt(l * l + (1.0 - 2.0 * l) * x)), 0.0, 1.0);
  return 2.0 * (1.0 - t) * t * (1.0 - l) + t * t;
}

double ExtrapolationFactor(double theta_out_deg, double theta_b_deg,
                           const ExtrapolationParams& params) {
  params.Validate();
  if (!(theta_b_deg >= 0.0 && theta_b_deg <= 90.0))
    throw InvalidArgument("extrapolation: θb must be in [0°, 90°], got " +
                          ExactNumberText(theta_b_deg));
  if (std::isnan(theta_out_deg)) throw InvalidArgument("extrapolation: θout is NaN");
  if (theta_out_deg <= theta_b_deg || theta_b_deg >= 90.0) return 1.0;
  const double m = 90.0 - theta_b_deg;
  const double x = std::min((theta_out_deg - theta_b_deg) / m, 1.0);
  const double alpha = BezierB(x, params.l);
  return (1.0 - alpha) + alpha * params.p;
}

ExtrapolationParams ParseExtrapolation(std::string_view text) {
  const auto fail = [&](const std::string& why) -> ExtrapolationParams {
    throw InvalidArgument("extrapolation parameters '" + std::string(text) +
                          "': expected P,L (two numbers, e.g. 0.2,0.3): " + why);
  };
  const auto comma = text.find(',');
  if (comma == std::string_view::npos) return fail("no comma");
  if (text.find(',', comma + 1) != std::string_view::npos) return fail("more than one comma");
  ExtrapolationParams params;
  if (!ParseNumber(text.substr(0, comma), params.p)) return fail("P is not a finite number");
  if (!ParseNumber(text.substr(comma + 1), params.l)) return fail("L is not a finite number");
  try {
    params.Validate();
  } catch (const InvalidArgument& e) {
    return fail(e.what());
  }
  return params;
}

std::string FormatExtrapolation(const ExtrapolationParams& params) {
  return ExactNumberText(params.p) + "," + ExactNumberText(params.l);
}

std::optional<ExtrapolationParams> ExtrapolationFromJson(std::string_view json_text,
                                                         const std::string& file) {
  using nlohmann::json;
  json doc;
  try {
    doc = json::parse(json_text.begin(), json_text.end());
  } catch (const json::parse_error& e) {
    throw JsonSyntaxError(file, json_text, e.byte);
  } catch (const json::out_of_range&) {
    throw JsonNumberTooLargeError(file, json_text);
  }
  if (!doc.is_object()) throw FormatError(file, "top level", "a JSON object", doc.type_name());
  const auto it = doc.find("extrapolate");
  if (it == doc.end()) return std::nullopt;
  if (!it->is_object())
    throw FormatError(file, "member 'extrapolate'", "an object {\"p\": P, \"l\": L}",
                      it->type_name());
  ExtrapolationParams params;
  for (const auto& [key, value] : it->items()) {
    double* target = key == "p" ? &params.p : key == "l" ? &params.l : nullptr;
    if (target == nullptr)
      throw FormatError(file, "member 'extrapolate'", "only members \"p\" and \"l\"",
                        "member \"" + key + "\"");
    if (!value.is_number())
      throw FormatError(file, "member 'extrapolate." + key + "'", "a number",
                        std::string(value.type_name()) + " " + value.dump());
    *target = value.get<double>();
  }
  // Said per member, as a position, what was expected and the value (not Validate()'s sentence
  // after "expected p >= 0 and l in [0, 1], got").
  if (!(std::isfinite(params.p) && params.p >= 0.0))
    throw FormatError(file, "member 'extrapolate.p'", "a finite number >= 0 (docs/design.md §6)",
                      ExactNumberText(params.p));
  if (!(params.l >= 0.0 && params.l <= 1.0))
    throw FormatError(file, "member 'extrapolate.l'", "a number in [0, 1] (docs/design.md §6)",
                      ExactNumberText(params.l));
  return params;
}

ExtrapolationParams LoadExtrapolationJson(const std::string& path) {
  const std::string text = ReadFileText(path, kMaxJsonBytes);
  const std::optional<ExtrapolationParams> params = ExtrapolationFromJson(text, path);
  if (!params)
    throw FormatError(path, "top level", "a member \"extrapolate\": {\"p\": P, \"l\": L}",
                      "no such member");
  return *params;
}

}  // namespace brdf::processing
