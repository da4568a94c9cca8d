// The samples a fit uses, and the error statistics of a material on them (private to brdf_fit).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/fit/fit.h"

namespace brdf::processing {

struct FitSample {
  ShadingGeometry g;
  std::array<double, 3> m{};  // measured f_r, 1/sr
  double cos_in = 1;          // cosθin
  double sqrt_w = 0;          // √(normalised solid-angle weight)
  double theta_h_deg = 0;     // angle between the half vector and the normal
  int slice = 0;              // index into FitData::theta_in_deg
};

struct FitData {
  std::vector<FitSample> samples;
  std::vector<double> theta_in_deg;  // per slice of the measurement
  std::size_t excluded_invalid = 0, excluded_saturated = 0, excluded_theta_out = 0;
};

// Selects and weighs the samples (brdf/fit/fit.h). Throws FormatError when none is
// usable, InvalidArgument for a bad max_theta_out_deg.
FitData PrepareFitData(const Measurement& measurement, const FitOptions& options);

// Fills the error statistics, sample counts and the representability check of `report`.
void FillErrors(const FitData& data, const Material& material, FitReport* report);

}  // namespace brdf::processing
