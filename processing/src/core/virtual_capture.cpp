#include "brdf/core/virtual_capture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/text_format.h"

namespace brdf {

std::vector<double> CaptureGeometry::ThetaOutDeg() const {
  // The simulator's rule: rows = ⌊max/step + 1e-6⌋ + 1, so 75/1 gives 76 rows (0…75).
  const int rows = static_cast<int>(std::floor(theta_out_max_deg / theta_out_step_deg + 1e-6)) + 1;
  std::vector<double> out(static_cast<std::size_t>(rows));
  for (int r = 0; r < rows; ++r) out[static_cast<std::size_t>(r)] = r * theta_out_step_deg;
  return out;
}

std::vector<double> CaptureGeometry::PhiOutDeg() const {
  const int columns = static_cast<int>(std::ceil(360.0 / phi_out_step_deg - 1e-6));
  std::vector<double> out(static_cast<std::size_t>(columns));
  for (int c = 0; c < columns; ++c) out[static_cast<std::size_t>(c)] = c * phi_out_step_deg;
  return out;
}

std::string CaptureGeometry::Describe() const {
  std::string thetas;
  for (double t : theta_in_deg) thetas += (thetas.empty() ? "" : ", ") + NumberText(t);
  const std::vector<double> phi = PhiOutDeg();
  std::string text = "theta_in " + thetas + "; theta_out 0-" + NumberText(ThetaOutDeg().back()) +
                     "; phi_out 0-" + NumberText(phi.back());
  if (theta_out_step_deg == phi_out_step_deg)
    return text + "; " + NumberText(theta_out_step_deg) + " deg steps";
  return text + "; steps " + NumberText(theta_out_step_deg) + " deg (theta_out), " +
         NumberText(phi_out_step_deg) + " deg (phi_out)";
}

void CaptureGeometry::Validate() const {
  if (theta_in_deg.empty()) throw InvalidArgument("capture geometry: no incidence angle θin");
  for (std::size_t i = 0; i < theta_in_deg.size(); ++i) {
    const double t = theta_in_deg[i];
    if (!(t >= 0.0 && t < 90.0))
      throw InvalidArgument("capture geometry: θin must be in [0, 90) degrees, got " +
                            NumberText(t));
    for (std::size_t j = 0; j < i; ++j)
      if (std::fabs(theta_in_deg[j] - t) <= 1e-6)
        throw InvalidArgument("capture geometry: θin " + NumberText(t) + "° is listed twice");
  }
  if (!(theta_out_max_deg >= 0.0 && theta_out_max_deg < 90.0))
    throw InvalidArgument("capture geometry: θout max must be in [0, 90) degrees, got " +
                          NumberText(theta_out_max_deg));
  if (!(theta_out_step_deg >= 0.01 && theta_out_step_deg <= 90.0))
    throw InvalidArgument("capture geometry: θout step must be in [0.01, 90] degrees, got " +
                          NumberText(theta_out_step_deg));
  if (!(phi_out_step_deg >= 0.01 && phi_out_step_deg <= 360.0))
    throw InvalidArgument("capture geometry: φout step must be in [0.01, 360] degrees, got " +
                          NumberText(phi_out_step_deg));
}

const CaptureGeometry& ReferenceGeometry() {
  static const CaptureGeometry kReference{};
  return kReference;
}

Measurement CaptureNoiseFree(const BrdfSource& source, const CaptureGeometry& geometry) {
  geometry.Validate();
  const std::vector<double> theta_out = geometry.ThetaOutDeg();
  const std::vector<double> phi_out = geometry.PhiOutDeg();
  Measurement m;
  m.metadata.sample_name = source.Name();
  m.metadata.instrument_model = "virtual noise-free capture";
  m.metadata.capture_start = m.metadata.capture_end = UtcNowIso8601();
  m.metadata.software_version = SoftwareVersion();
  m.metadata.extra["capture"] = "virtual, noise-free: f_r evaluated at " + geometry.Describe();
  m.metadata.extra[kPlannedThetaInKey] = EncodeThetaInList(geometry.theta_in_deg);
  for (const double theta_in : geometry.theta_in_deg) {
    Slice slice;
    slice.theta_in_deg = theta_in;
    const Vec3 wi = SphericalDirectionDeg(theta_in, 0.0);
    slice.samples.reserve(theta_out.size() * phi_out.size());
    for (const double t : theta_out) {
      for (const double p : phi_out) {
        const Vec3 wo = SphericalDirectionDeg(t, p);
        const Rgb f = source.Eval(wi, wo);
        Sample s;
        s.theta_in_deg = static_cast<float>(theta_in);
        s.theta_out_deg = static_cast<float>(t);
        s.phi_out_deg = static_cast<float>(p);
        for (int c = 0; c < 3; ++c) s.rgb[c] = static_cast<float>(f[c]);
        if (!source.HasValue(wi, wo)) s.flags = kFlagInvalid;
        slice.samples.push_back(s);
      }
    }
    m.slices.push_back(std::move(slice));
  }
  return m;
}

std::string EncodeThetaInList(const std::vector<double>& theta_in_deg) {
  std::string out;
  for (double t : theta_in_deg) {
    std::string text = ShortNumberText(t);
    // %g keeps 6 significant digits; fall back to the round-trip form when that loses bits.
    if (std::strtod(text.c_str(), nullptr) != t) text = ExactNumberText(t);
    out += (out.empty() ? "" : ",") + text;
  }
  return out;
}

std::optional<std::vector<double>> PlannedThetaInDeg(const Metadata& metadata,
                                                     const std::string& file) {
  const auto it = metadata.extra.find(kPlannedThetaInKey);
  if (it == metadata.extra.end()) return std::nullopt;
  const auto fail = [&](const std::string& got) -> FormatError {
    return FormatError(file, std::string("metadata extra '") + kPlannedThetaInKey + "'",
                       "a list of incidence angles in [0, 90) degrees such as \"0,20,40,60\"", got);
  };
  std::vector<double> planned;
  std::string text = it->second;
  std::replace(text.begin(), text.end(), ',', ' ');
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !(v >= 0.0 && v < 90.0))
      throw fail("'" + it->second + "'");
    planned.push_back(v);
  }
  if (planned.empty()) throw fail("an empty list");
  return planned;
}

}  // namespace brdf
