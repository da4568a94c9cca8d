#include "brdf/processing/measurement_brdf.h"

#include <utility>

namespace brdf::processing {

LutBrdf MeasurementAsBrdf(const Measurement& measurement, const ExtrapolationParams& params,
                          ResampleOptions options, std::string name) {
  options.require_uniform_theta_in = false;  // tables measured at any θin evaluate too
  Lut lut = BuildLut(measurement, params, options);
  return LutBrdf(std::move(lut), name.empty() ? measurement.metadata.sample_name : std::move(name));
}

}  // namespace brdf::processing
