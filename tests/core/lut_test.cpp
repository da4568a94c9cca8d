#include "brdf/core/lut.h"

#include <gtest/gtest.h>

#include "brdf/core/geometry.h"

namespace brdf {
namespace {

Lut RampLut() {
  // Texel value = i + 1000 j + 1e6 k in red, so every tap is identifiable.
  Lut lut;
  lut.Resize(4);
  lut.theta_in_deg = {0, 20, 40, 60};
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) lut.Texel(k, j, i)[0] = float(i + 1000 * j + 1e6 * k);
  return lut;
}

TEST(LutSampling, TexelCentreReturnsTexel) {
  const Lut lut = RampLut();
  const double u = (17 + 0.5) / 361, v = (33 + 0.5) / 181, w = (2 + 0.5) / 4;
  EXPECT_FLOAT_EQ(lut.SampleTrilinear(u, v, w)[0], 17 + 33000 + 2e6);
}

TEST(LutSampling, HalfwayBetweenTexelsAverages) {
  const Lut lut = RampLut();
  const double u = (17 + 1.0) / 361, v = (33 + 0.5) / 181, w = (1 + 0.5) / 4;
  EXPECT_FLOAT_EQ(lut.SampleTrilinear(u, v, w)[0], 17.5f + 33000 + 1e6);
}

TEST(LutSampling, ClampsToEdge) {
  const Lut lut = RampLut();
  EXPECT_FLOAT_EQ(lut.SampleTrilinear(0.0, 0.0, 0.0)[0], 0.0f);
  EXPECT_FLOAT_EQ(lut.SampleTrilinear(1.0, 1.0, 1.0)[0], 360 + 180000 + 3e6);
}

TEST(LutSampling, AnglesAddressTheSpecularFrameTexel) {
  const Lut lut = RampLut();
  // The direction at (θd, φd) = (12°, 90°) in the specular frame of θin = 40° must land on
  // texel (i, j, k) = (90, 12, 2).
  const Vec3 w_out =
      SpecularFrame::FromThetaInDeg(40.0).FromSpecular(SphericalDirectionDeg(12, 90));
  const double theta_out = RadToDeg(ThetaOf(w_out)), phi_out = RadToDeg(PhiOf(w_out));
  EXPECT_NEAR(lut.SampleAngles(40.0, theta_out, phi_out)[0], 90 + 12000 + 2e6, 0.5);
}

}  // namespace
}  // namespace brdf
