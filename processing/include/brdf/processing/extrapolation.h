// Grazing-angle extrapolation: the restricted quadratic Bézier of docs/design.md §6.
//
// A contact scatterometer measures outgoing polar angles only up to some θb (75° for the
// reference instrument). The LUT needs values up to the horizon, so for every azimuth φout the
// value at θb is carried on towards 90° and scaled:
//
//   f(θ, φ) = f(θb, φ) · ((1 − α) + α·p),   α = b(min((θ − θb)/m, 1), l),   m = 90° − θb.
//
// b(x, l) is the ordinate of the point with abscissa x on the quadratic Bézier curve with
// control points P0 = (0, 0), P1 = (l, 1 − l), P2 = (1, 1). p is the fraction of f(θb) left at
// the horizon (p = 1 clamps, p < 1 darkens glossy materials towards grazing, p > 1 brightens),
// l bends the transition (l = ½ is linear in θ, l < ½ reaches p early, l > ½ late). The
// reference paper illustrates p = 0.2, l = 0.3. Defaults p = 1, l = ½: clamping.
//
// θb is never a constant of this code: callers pass the largest measured θout of their data.
// Angles here are degrees (they come from files and command lines).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace brdf::processing {

struct ExtrapolationParams {
  double p = 1.0;  // factor at the horizon relative to f(θb); p ≥ 0, finite
  double l = 0.5;  // Bézier shape, l ∈ [0, 1]

  // Throws brdf::InvalidArgument naming the bad parameter, its value and the allowed range.
  void Validate() const;

  friend bool operator==(const ExtrapolationParams&, const ExtrapolationParams&) = default;
};

// b(x, l): the y of the curve point whose x equals `x`, computed from the closed-form root
// t = x / (l + √(l² + (1 − 2l)x)) of x(t) = 2(1 − t)t·l + t² (no division by zero at l = ½;
// t = 0 at x = 0), then y(t) = 2(1 − t)t·(1 − l) + t².
// `x` outside [0, 1] is clamped to it. Throws InvalidArgument for NaN x or l outside [0, 1].
// Properties: b(0, l) = 0, b(1, l) = 1, b(x, ½) = x, monotone non-decreasing in x.
double BezierB(double x, double l);

// The factor (1 − α) + α·p that multiplies f(θb) at outgoing polar angle `theta_out_deg`.
// 1 for θout ≤ θb (inside the measured range); θout ≥ 90° gives the horizon factor p (below
// the horizon the LUT repeats the horizon, docs/design.md §5). If θb ≥ 90° nothing is extrapolated
// and the factor is 1. Throws InvalidArgument for θb outside [0°, 90°], NaN θout, or invalid
// params.
double ExtrapolationFactor(double theta_out_deg, double theta_b_deg,
                           const ExtrapolationParams& params);

// Parses the command-line form "P,L" (two decimal numbers separated by one comma; blanks around
// either number are allowed), e.g. "0.2,0.3". Throws InvalidArgument quoting the text and
// saying what was expected; the result is validated.
ExtrapolationParams ParseExtrapolation(std::string_view text);

// The inverse of ParseExtrapolation: "P,L" with enough digits to round-trip exactly.
std::string FormatExtrapolation(const ExtrapolationParams& params);

// Reads the per-material form {"extrapolate": {"p": 0.2, "l": 0.3}} from JSON text. Other
// top-level members are ignored (the object may be a material file or a sidecar); inside
// "extrapolate" only "p" and "l" are allowed and either may be omitted (it keeps its default).
// Returns nullopt when there is no "extrapolate" member. Throws brdf::FormatError naming `file`,
// the position (byte offset for syntax errors, member path otherwise), what was expected and
// what was found; values are validated.
std::optional<ExtrapolationParams> ExtrapolationFromJson(std::string_view json_text,
                                                         const std::string& file = "<json>");

// Reads a per-material extrapolation file (at most 1 MiB). Unlike ExtrapolationFromJson a file
// without an "extrapolate" member is an error here: the caller asked for this file by name.
// Throws IoError (unreadable) or FormatError.
ExtrapolationParams LoadExtrapolationJson(const std::string& path);

}  // namespace brdf::processing
