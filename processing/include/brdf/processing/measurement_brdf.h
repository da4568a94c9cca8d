// A captured measurement (or an imported table) evaluated as a BrdfSource, through the one
// evaluation path of measured data: the float LUT that `brdf convert` builds
// (BuildLut, resample.h), sampled by Lut::SampleAngles (brdf/core/lut_brdf.h). So `brdf eval`
// and `brdf preview` of a capture, its exported texture (up to the RGB9E5 rounding of the
// texels), the viewer and every test that evaluates a capture get the same value.
//
// What that value is (docs/design.md §5, §6):
//  - at a measured θin: the slice's samples interpolated at the LUT's 1° texel centres of the
//    specular frame (regular-grid bilinear or scattered moving least squares, resample.h), then
//    bilinear between texels; the §6 extrapolation between θb and 90°;
//  - between measured θin: linear in θin at the same specular-frame coordinates (θd, φd), so a
//    glossy peak moves with the mirror direction instead of fading between two positions;
//  - θin outside the measured range: reciprocity when the view lies nearer to the range (light
//    and view exchanged), otherwise the nearest slice at the same (θd, φd).
#pragma once

#include <string>

#include "brdf/core/lut_brdf.h"
#include "brdf/core/measurement.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/processing/resample.h"

namespace brdf::processing {

// Resamples `measurement` with BuildLut(measurement, params, options) and wraps the LUT. Unlike
// the exported textures it accepts any set of distinct θin in [0°, 90°) (options'
// require_uniform_theta_in is ignored: an evaluation-only LUT, interpolated between its
// neighbouring θin). `name` defaults to the measurement's sample name. Throws InvalidArgument
// (BuildLut's requirements).
LutBrdf MeasurementAsBrdf(const Measurement& measurement, const ExtrapolationParams& params = {},
                          ResampleOptions options = {}, std::string name = {});

}  // namespace brdf::processing
