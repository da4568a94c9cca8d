// Lobe geometry (brdf::viewer::BuildLobe) against analytic expectations: a Lambertian lobe is
// a sphere of radius ρ/π (f_r) or the sphere of diameter ρ/π through the origin (f_r·cosθo);
// a glossy lobe peaks at the mirror direction for every θin, also between measured slices.
#include "brdf/viewer/lobe.h"

#include <gtest/gtest.h>

#include <cmath>

#include "brdf/core/bpc.h"
#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/models.h"

namespace brdf::viewer {
namespace {

ViewSource FromJson(const std::string& json) {
  return ViewSourceFromBrdf(AnalyticBrdf(ParseMaterialJson(json)), "test");
}

double AngleDeg(const Vec3& a, const Vec3& b) {
  const double c = Dot(a, b) / std::sqrt(Dot(a, a) * Dot(b, b));
  return RadToDeg(std::acos(std::fmax(-1.0, std::fmin(1.0, c))));
}

// The mirror of the light (θin, φin = 0) about z, written out from docs/design.md §4.
Vec3 MirrorOf(double theta_in_deg) {
  const double t = DegToRad(theta_in_deg);
  return {-std::sin(t), 0.0, std::cos(t)};
}

TEST(Lobe, LambertianIsASphereOfRadiusRhoOverPi) {
  const double rho[3] = {0.8, 0.5, 0.2};
  const ViewSource source = FromJson(R"({"model": "lambert", "rho": [0.8, 0.5, 0.2]})");
  for (double theta_in : {0.0, 30.0, 60.0}) {
    for (Channel ch : {Channel::kRed, Channel::kGreen, Channel::kBlue, Channel::kLuminance}) {
      LobeOptions options;
      options.theta_in_deg = theta_in;
      options.channel = ch;
      const LobeMesh mesh = BuildLobe(source, options);
      const double want =
          (ch == Channel::kLuminance ? 0.2126 * rho[0] + 0.7152 * rho[1] + 0.0722 * rho[2]
                                     : rho[static_cast<int>(ch)]) /
          kPi;
      ASSERT_EQ(mesh.points.size(), 91u * 180u);
      for (const Vec3& p : mesh.points) {
        ASSERT_NEAR(std::sqrt(Dot(p, p)), want, 1e-6 * want) << "θin " << theta_in;
      }
      EXPECT_NEAR(mesh.max_radius, want, 1e-6 * want);
    }
  }
}

TEST(Lobe, CosineWeightedLambertianIsTheSphereOfDiameterRhoOverPiThroughTheOrigin) {
  const ViewSource source = FromJson(R"({"model": "lambert", "rho": 0.6})");
  LobeOptions options;
  options.theta_in_deg = 40;
  options.channel = Channel::kRed;
  options.cosine_weighted = true;
  const LobeMesh mesh = BuildLobe(source, options);
  // r = (ρ/π) cosθ is the sphere |p − c| = ρ/2π with c = (0, 0, ρ/2π).
  const double half = 0.6 / kPi / 2;
  for (const Vec3& p : mesh.points) {
    const Vec3 d = p - Vec3{0, 0, half};
    ASSERT_NEAR(std::sqrt(Dot(d, d)), half, 1e-6);
  }
}

TEST(Lobe, LogScaleRadiusCountsDecadesAboveTheFloor) {
  const ViewSource source = FromJson(R"({"model": "lambert", "rho": 1.0})");
  LobeOptions options;
  options.channel = Channel::kGreen;
  options.scale = RadiusScale::kLog;
  options.log_floor = 1.0 / kPi / 100.0;  // two decades below f_r = 1/π
  const LobeMesh mesh = BuildLobe(source, options);
  for (const Vec3& p : mesh.points) ASSERT_NEAR(std::sqrt(Dot(p, p)), 2.0, 1e-5);
}

// Lafortune's lobe max(v·r, 0)^n peaks exactly at the mirror direction r (docs/design.md §9).
TEST(Lobe, GlossyLobePeaksAtTheMirrorDirectionForEveryThetaIn) {
  const ViewSource source = FromJson(R"({"model": "lafortune", "kd": 0.05, "ks": 0.9, "n": 300})");
  for (double theta_in = 0; theta_in <= 60; theta_in += 5) {  // measured and in between
    LobeOptions options;
    options.theta_in_deg = theta_in;
    const LobeMesh mesh = BuildLobe(source, options);
    const int far = mesh.FarthestVertex();
    EXPECT_LT(AngleDeg(mesh.directions[far], MirrorOf(theta_in)), 2.0) << "θin " << theta_in;
    EXPECT_LT(AngleDeg(mesh.mirror, MirrorOf(theta_in)), 1e-9);
  }
}

// Gold (GGX, α = 0.15) from the sample library's form: a real microfacet lobe.
TEST(Lobe, GgxLobePeaksWithinTwoDegreesOfTheMirror) {
  const ViewSource source =
      FromJson(R"({"model": "ggx", "kd": 0.0, "f0": [0.96, 0.79, 0.41], "alpha": 0.1})");
  for (double theta_in = 0; theta_in <= 60; theta_in += 10) {
    LobeOptions options;
    options.theta_in_deg = theta_in;
    options.theta_rows = 180;
    options.phi_columns = 360;
    const LobeMesh mesh = BuildLobe(source, options);
    const int far = mesh.FarthestVertex();
    EXPECT_LT(AngleDeg(mesh.directions[far], MirrorOf(theta_in)), 2.0) << "θin " << theta_in;
  }
}

// A real capture from the simulated scatterometer (gold, with detector noise), checked into
// data-samples/: the measured lobe still peaks at the mirror direction, between slices too.
TEST(Lobe, CapturedGoldPeaksWithinTwoDegreesOfTheMirror) {
  const Measurement m = LoadBpc(std::string(BRDF_SOURCE_DIR) + "/data-samples/captures/gold.bpc");
  const ViewSource source = ViewSourceFromMeasurement(m, {}, "gold");
  for (double theta_in = 0; theta_in <= 60; theta_in += 10) {
    LobeOptions options;
    options.theta_in_deg = theta_in;
    const LobeMesh mesh = BuildLobe(source, options);
    const int far = mesh.FarthestVertex();
    EXPECT_LT(AngleDeg(mesh.directions[far], MirrorOf(theta_in)), 2.0) << "θin " << theta_in;
  }
}

TEST(Lobe, ExtrapolatedBandStartsAtTheLastMeasuredAngle) {
  // ViewSourceFromBrdf captures θout 0–75° (the reference instrument): beyond is extrapolated.
  const ViewSource source = FromJson(R"({"model": "lambert", "rho": 0.5})");
  LobeOptions options;
  options.theta_in_deg = 20;
  const LobeMesh mesh = BuildLobe(source, options);
  for (std::size_t n = 0; n < mesh.directions.size(); ++n) {
    const double theta = RadToDeg(ThetaOf(mesh.directions[n]));
    ASSERT_EQ(mesh.coverage[n], theta > 75.0 + 1e-9 ? Coverage::kExtrapolated : Coverage::kMeasured)
        << "θo " << theta;
  }
}

TEST(Lobe, TrianglesFaceOutwards) {
  const ViewSource source = FromJson(R"({"model": "lambert", "rho": 0.5})");
  const LobeMesh mesh = BuildLobe(source, LobeOptions{});
  ASSERT_EQ(mesh.triangles.size(), mesh.triangle_coverage.size());
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.points[t[0]], b = mesh.points[t[1]], c = mesh.points[t[2]];
    const Vec3 u = b - a, v = c - a;
    const Vec3 n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    ASSERT_GT(Dot(n, (a + b + c) * (1.0 / 3)), 0.0);
  }
}

TEST(Lobe, RejectsBadOptions) {
  const ViewSource source = FromJson(R"({"model": "lambert", "rho": 0.5})");
  LobeOptions options;
  options.theta_in_deg = 95;
  EXPECT_THROW(BuildLobe(source, options), InvalidArgument);
  options = {};
  options.phi_columns = 1;
  EXPECT_THROW(BuildLobe(source, options), InvalidArgument);
}

// The starting camera sees every vertex and arrow tip: projected with a pinhole model written
// here from the camera's position, focal point, up vector and vertical view angle.
TEST(LobeCamera, FramesTheLobeAndItsArrows) {
  const ViewSource source = FromJson(R"({"model": "lafortune", "kd": 0.1, "ks": 0.8, "n": 40})");
  for (double aspect : {0.75, 1.0, 16.0 / 9.0}) {
    LobeOptions options;
    options.theta_in_deg = 50;
    const LobeMesh mesh = BuildLobe(source, options);
    const double arrow = 1.3 * mesh.max_radius;
    const CameraSetup cam = LobeCamera(mesh, arrow, aspect);
    const Vec3 f = Normalize(cam.focal_point - cam.position);
    const Vec3 up = Normalize(cam.view_up);
    const Vec3 right{f.y * up.z - f.z * up.y, f.z * up.x - f.x * up.z, f.x * up.y - f.y * up.x};
    EXPECT_NEAR(Dot(f, up), 0.0, 1e-9);
    const double t = std::tan(DegToRad(cam.view_angle_deg / 2));
    auto check = [&](const Vec3& p) {
      const Vec3 d = p - cam.position;
      const double z = Dot(d, f);
      ASSERT_GT(z, 0);
      EXPECT_LE(std::fabs(Dot(d, up) / (z * t)), 1.0);
      EXPECT_LE(std::fabs(Dot(d, right) / (z * t * aspect)), 1.0);
    };
    for (const Vec3& p : mesh.points) check(p);
    for (const Vec3& a : {mesh.normal, mesh.light, mesh.mirror}) check(a * arrow);
  }
}

}  // namespace
}  // namespace brdf::viewer
