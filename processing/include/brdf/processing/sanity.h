// The physical sanity report of a capture: what a researcher checks first in a measurement
// (`brdf info`, text and --json; docs/design.md §5, "Physical sanity report").
//
// Everything is read from the LUT the commands build of the capture (the one `brdf eval`
// samples: Lut::SampleAngles, measured slices, the blind-spot fill and the §6 band), per LUT
// slice θin with the light at (θin, φin = 0):
//  - directional albedo per channel, ∫ f(θin → ω) cosθ dω over the hemisphere, by the midpoint
//    rule on a 1° (θout) × 2° (φout) grid, split into the measured part (θout ≤ θb of a
//    measured slice) and the filled part (θout > θb, and all of a slice the fill added);
//  - the reciprocity residual over the pairs measured both ways: for measured slices a ≠ b with
//    b ≤ θb, |Σrgb f(a → b, Δφ) − Σrgb f(b → a, Δφ)| / mean of the two at equal azimuth
//    difference Δφ = 0, 5, …, 355°; median and largest over slice a's pairs;
//  - the energy flag: a channel's total albedo above 1 + the noise margin, max(2 %, the
//    slice's median reciprocity residual): a measurement's own inconsistency bounds how well
//    its albedo is known;
//  - the samples flagged saturated and below the noise floor (kFlagSaturated,
//    kFlagBelowNoiseFloor) in the measured slice.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/core/measurement.h"

namespace brdf::processing {

struct SliceSanity {
  double theta_in_deg = 0;
  bool measured = false;  // a slice of the capture (else the fill added it)
  std::array<double, 3> albedo_measured{}, albedo_filled{};
  std::size_t reciprocity_pairs = 0;  // 0: no pair measured both ways (or a filled slice)
  double reciprocity_median = 0, reciprocity_max = 0;
  double energy_margin = 0;                    // the noise margin of the energy flag
  bool energy_flag = false;                    // some channel's albedo > 1 + energy_margin
  std::size_t saturated = 0, below_noise = 0;  // samples of the measured slice
};

struct SanityReport {
  double theta_b_deg = 90;
  std::vector<SliceSanity> slices;  // one per LUT slice, ascending θin
};

// `lut` as BuildLut made it of `measurement` (whose slices' θin are the measured ones),
// `theta_b_deg` the last measured θout (ResampleReport::theta_b_deg).
SanityReport PhysicalSanity(const Lut& lut, const Measurement& measurement, double theta_b_deg);

// {"theta_b_deg", "slices": [{"theta_in", "measured", "albedo_measured": [r, g, b],
// "albedo_filled": [...], "albedo": [...], "reciprocity": {"pairs", "median_relative",
// "max_relative"} or null, "energy_margin", "energy_flag", "saturated", "below_noise_floor"}]}
std::string SanityReportJson(const SanityReport& report);

}  // namespace brdf::processing
