// `brdf eval FILE --in T,P --out T,P`: f_r of any evaluable file for one pair of directions.
// Material files are evaluated analytically, captures interpolated (processing::MeasurementBrdf,
// with the extrapolation `brdf convert` would use), exported LUTs sampled exactly as a GPU
// samples the texture (sources.h, LutBrdf), so a texel can be checked against its source.
#include <cstdio>
#include <memory>
#include <optional>

#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "commands.h"
#include "sources.h"

namespace brdf::cli {

namespace {

void CheckPolar(double theta_deg, const char* which) {
  if (!(theta_deg >= 0.0 && theta_deg <= 90.0))
    throw InvalidArgument(std::string("--") + which +
                          ": polar angle must be in [0, 90] degrees, got " +
                          std::to_string(theta_deg));
}

}  // namespace

int RunEval(const EvalOptions& options) {
  CheckPolar(options.theta_in_deg, "in");
  CheckPolar(options.theta_out_deg, "out");
  std::optional<processing::ExtrapolationParams> extrapolate;
  if (!options.extrapolate.empty())
    extrapolate = processing::ParseExtrapolation(options.extrapolate);
  std::vector<std::string> warnings;
  const std::unique_ptr<BrdfSource> source = OpenEvalSource(options.file, extrapolate, &warnings);
  for (const std::string& w : warnings) std::fprintf(stderr, "%s\n", w.c_str());
  const Vec3 wi = SphericalDirectionDeg(options.theta_in_deg, options.phi_in_deg);
  const Vec3 wo = SphericalDirectionDeg(options.theta_out_deg, options.phi_out_deg);
  const Rgb f = source->Eval(wi, wo);
  std::printf("%.9g %.9g %.9g\n", f[0], f[1], f[2]);
  return 0;
}

}  // namespace brdf::cli
