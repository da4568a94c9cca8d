#include "brdf/core/geometry.h"

#include <gtest/gtest.h>

namespace brdf {
namespace {

TEST(SpecularFrame, MapsMirrorDirectionToPole) {
  for (double theta_in : {0.0, 20.0, 40.0, 60.0, 75.0}) {
    const auto frame = SpecularFrame::FromThetaInDeg(theta_in);
    const Vec3 mirror = SphericalDirectionDeg(theta_in, 180.0);
    const Vec3 d = frame.ToSpecular(mirror);
    EXPECT_NEAR(d.z, 1.0, 1e-15) << theta_in;
    EXPECT_NEAR(d.x, 0.0, 1e-15);
    EXPECT_NEAR(d.y, 0.0, 1e-15);
  }
}

TEST(SpecularFrame, IsItsOwnInverseAndOrthogonal) {
  const auto frame = SpecularFrame::FromThetaInDeg(37.0);
  for (double t = 0; t <= 180; t += 15) {
    for (double p = 0; p < 360; p += 30) {
      const Vec3 w = SphericalDirectionDeg(t, p);
      const Vec3 d = frame.ToSpecular(w);
      EXPECT_NEAR(Dot(d, d), 1.0, 1e-14);
      const Vec3 back = frame.FromSpecular(d);
      EXPECT_NEAR(back.x, w.x, 1e-14);
      EXPECT_NEAR(back.y, w.y, 1e-14);
      EXPECT_NEAR(back.z, w.z, 1e-14);
    }
  }
}

TEST(SpecularFrame, MatchesDesignMatrixEntries) {
  // docs/design.md §5: S(θm) = [[−cosθm, 0, −sinθm], [0, −1, 0], [−sinθm, 0, cosθm]], applied to
  // the basis vectors gives its columns.
  const double tm = DegToRad(20.0);
  const auto frame = SpecularFrame::FromThetaInRad(tm);
  const Vec3 cx = frame.Apply({1, 0, 0}), cy = frame.Apply({0, 1, 0}), cz = frame.Apply({0, 0, 1});
  EXPECT_DOUBLE_EQ(cx.x, -std::cos(tm));
  EXPECT_DOUBLE_EQ(cx.z, -std::sin(tm));
  EXPECT_DOUBLE_EQ(cy.y, -1.0);
  EXPECT_DOUBLE_EQ(cz.x, -std::sin(tm));
  EXPECT_DOUBLE_EQ(cz.z, std::cos(tm));
}

TEST(Angles, PhiWrapsToZeroTo360) {
  EXPECT_DOUBLE_EQ(WrapDeg360(-90.0), 270.0);
  EXPECT_DOUBLE_EQ(WrapDeg360(360.0), 0.0);
  EXPECT_NEAR(RadToDeg(PhiOf({0.0, -1.0, 0.0})), 270.0, 1e-12);
}

}  // namespace
}  // namespace brdf
