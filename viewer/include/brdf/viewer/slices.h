// The LUT slices as heat-map images, and what lies under the cursor.
//
// Slice k of the LUT (docs/design.md §5) is an equirectangular image in the specular frame of
// θin,k: column i at φd = i·1° (i = 0…360, column 360 repeats column 0), row j at θd = j·1° (j =
// 0…180, row 0 at the top, θd = 0 is the mirror direction). A probe maps a texel back to the
// outgoing direction it holds, ω_out = S(θin)·ω_d (brdf::SpecularFrame), in the measurement frame.
// No VTK here.
#pragma once

#include <array>
#include <vector>

#include "brdf/viewer/lobe.h"
#include "brdf/viewer/view_source.h"

namespace brdf::viewer {

struct SliceImage {
  int width = Lut::kWidth, height = Lut::kHeight;
  int slice = 0;
  double theta_in_deg = 0;
  std::vector<float> values;  // height × width, row j (θd = j°) first, channel value in 1/sr
  float min_value = 0, max_value = 0;
  float At(int i, int j) const { return values[static_cast<std::size_t>(j) * width + i]; }
};

// Throws InvalidArgument for a slice index outside 0…K−1.
SliceImage BuildSliceImage(const ViewSource& source, int slice, Channel channel);

struct SliceProbe {
  int i = 0, j = 0;                           // nearest texel (column, row)
  double phi_d_deg = 0, theta_d_deg = 0;      // its centre
  std::array<float, 3> rgb{};                 // the texel, f_r in 1/sr
  double value = 0;                           // the channel value
  double theta_out_deg = 0, phi_out_deg = 0;  // the outgoing direction it holds
  // θout > 90°: below the horizon, the texel holds the value at θout = 90° (edge extension).
  bool below_horizon = false;
  Coverage coverage = Coverage::kMeasured;
};

// The texel nearest to (φd, θd) in degrees (clamped to the slice), and where it came from.
// Throws InvalidArgument for a slice index outside 0…K−1.
SliceProbe ProbeSlice(const ViewSource& source, int slice, Channel channel, double phi_d_deg,
                      double theta_d_deg);

}  // namespace brdf::viewer
