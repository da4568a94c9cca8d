// Evaluating a BrdfSource at pairs of angles in degrees: the one path of `brdf eval` (--in/--out
// and --pairs) and of the Python module's Source.eval_deg, so that both give the same values,
// bit for bit.
//
// Pair i is the light at (theta_in[i], phi_in[i]) and the view at (theta_out[i], phi_out[i]),
// polar angles in [0, 90] (callers check; a polar angle outside gives zero, the horizon rule of
// BrdfSource), azimuths finite. rgb[3i..3i+2] receives f_r in 1/sr, not multiplied by cos.
//
// A LUT (LutBrdf: captures, tables, exported textures) is sampled in angle space, without
// building the two direction vectors and recovering the angles from them: Lut::SampleAngles at
// (θin, θout, φout − φin wrapped to [0°, 360°); φout alone when θin = 0), which is what
// LutBrdf::Eval computes from the directions of the same angles up to the rounding of that
// round trip (docs/design.md §5, isotropic: only the relative azimuth matters). It is about
// twice as fast (docs/benchmarks/python.md). Every other source is evaluated at
// SphericalDirectionDeg of both angle pairs through BrdfSource::Eval.
//
// Thread-safe (the sources are immutable): callers share a batch out in ranges.
#pragma once

#include <cstddef>

#include "brdf/core/brdf_source.h"

namespace brdf {

void EvalAnglePairsDeg(const BrdfSource& source, std::size_t count, const double* theta_in,
                       const double* phi_in, const double* theta_out, const double* phi_out,
                       double* rgb);

}  // namespace brdf
