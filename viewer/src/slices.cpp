#include "brdf/viewer/slices.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"

namespace brdf::viewer {
namespace {

void CheckSlice(const ViewSource& source, int slice) {
  if (slice < 0 || slice >= source.lut.slices()) {
    throw InvalidArgument("slice " + std::to_string(slice) + " does not exist: the LUT has " +
                          std::to_string(source.lut.slices()) + " slices");
  }
}

}  // namespace

SliceImage BuildSliceImage(const ViewSource& source, int slice, Channel channel) {
  CheckSlice(source, slice);
  SliceImage image;
  image.slice = slice;
  image.theta_in_deg = source.lut.theta_in_deg[slice];
  image.values.resize(static_cast<std::size_t>(image.width) * image.height);
  image.min_value = std::numeric_limits<float>::max();
  image.max_value = 0;
  for (int j = 0; j < image.height; ++j) {
    for (int i = 0; i < image.width; ++i) {
      const float v = static_cast<float>(ChannelValue(source.lut.Texel(slice, j, i), channel));
      image.values[static_cast<std::size_t>(j) * image.width + i] = v;
      image.min_value = std::min(image.min_value, v);
      image.max_value = std::max(image.max_value, v);
    }
  }
  return image;
}

SliceProbe ProbeSlice(const ViewSource& source, int slice, Channel channel, double phi_d_deg,
                      double theta_d_deg) {
  CheckSlice(source, slice);
  SliceProbe probe;
  probe.i =
      std::clamp(static_cast<int>(std::lround(phi_d_deg / Lut::kTexelDeg)), 0, Lut::kWidth - 1);
  probe.j =
      std::clamp(static_cast<int>(std::lround(theta_d_deg / Lut::kTexelDeg)), 0, Lut::kHeight - 1);
  probe.phi_d_deg = probe.i * Lut::kTexelDeg;
  probe.theta_d_deg = probe.j * Lut::kTexelDeg;
  const float* texel = source.lut.Texel(slice, probe.j, probe.i);
  probe.rgb = {texel[0], texel[1], texel[2]};
  probe.value = ChannelValue(texel, channel);
  const double theta_in = source.lut.theta_in_deg[slice];
  const Vec3 w_out = SpecularFrame::FromThetaInDeg(theta_in).FromSpecular(
      SphericalDirectionDeg(probe.theta_d_deg, probe.phi_d_deg));
  probe.theta_out_deg = RadToDeg(ThetaOf(w_out));
  probe.phi_out_deg = RadToDeg(PhiOf(w_out));
  probe.below_horizon = probe.theta_out_deg > 90.0 + 1e-9;
  probe.coverage = probe.below_horizon
                       ? Coverage::kExtrapolated
                       : source.CoverageAt(theta_in, probe.theta_out_deg, probe.phi_out_deg);
  return probe;
}

}  // namespace brdf::viewer
