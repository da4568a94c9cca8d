// Physics checks of the analytic models of docs/design.md §9: reciprocity, energy conservation by
// numerical integration, and values against formulas written out independently here.
#include "brdf/core/models.h"

#include <gtest/gtest.h>

#include <cmath>

#include "brdf/core/error.h"

namespace brdf {
namespace {

Material Make(Model model, Rgb kd, Rgb ks, Rgb shape) {
  Material m;
  m.model = model;
  const Rgb parameters[] = {kd, ks, shape};
  for (std::size_t i = 0; i < DescribeModel(model).parameters.size(); ++i)
    m.SetParameter(static_cast<int>(i), parameters[i]);
  return m;
}

std::vector<Material> ValidMaterials() {
  return {
      Make(Model::kLambert, {0.9, 0.5, 0.1}, {}, {}),
      Make(Model::kLafortune, {0.2, 0.3, 0.4}, {0.7, 0.6, 0.5}, {20, 20, 20}),
      Make(Model::kLafortune, {0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, {3, 50, 400}),
      Make(Model::kBlinnPhong, {0.3, 0.3, 0.3}, {0.6, 0.6, 0.6}, {10, 100, 1000}),
      Make(Model::kGgx, {0.4, 0.2, 0.1}, {0.04, 0.04, 0.04}, {0.3, 0.3, 0.3}),
      Make(Model::kGgx, {0.0, 0.0, 0.0}, {0.95, 0.64, 0.54}, {0.1, 0.2, 0.6}),
      Make(Model::kWard, {0.2, 0.2, 0.2}, {0.1, 0.1, 0.1}, {0.1, 0.2, 0.3}),
  };
}

// Directional albedo ∫ f(l, v) cosθv dω by the midpoint rule in (cosθ, φ), with a grid fine
// enough for the narrowest lobe used here.
Rgb Albedo(const Material& m, double theta_in_deg, int n_theta = 1200, int n_phi = 1200) {
  const Vec3 l = SphericalDirectionDeg(theta_in_deg, 0.0);
  Rgb sum{};
  // Substitute μ = cosθ, so dω = dμ dφ; cluster samples where lobes are by using μ = 1 − s².
  for (int a = 0; a < n_theta; ++a) {
    const double s = (a + 0.5) / n_theta;
    const double mu = 1.0 - s * s;
    const double dmu = 2.0 * s / n_theta;
    const double sin_t = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    for (int b = 0; b < n_phi; ++b) {
      const double phi = 2.0 * kPi * (b + 0.5) / n_phi;
      const Vec3 v{sin_t * std::cos(phi), sin_t * std::sin(phi), mu};
      const Rgb f = m.Evaluate(l, v);
      for (int c = 0; c < 3; ++c) sum[c] += f[c] * mu * dmu * (2.0 * kPi / n_phi);
    }
  }
  return sum;
}

TEST(Models, AreReciprocal) {
  for (const Material& m : ValidMaterials()) {
    for (double ti = 1; ti < 90; ti += 11)
      for (double to = 2; to < 90; to += 13)
        for (double po = 0; po < 360; po += 37) {
          const Vec3 l = SphericalDirectionDeg(ti, 0), v = SphericalDirectionDeg(to, po);
          const Rgb a = m.Evaluate(l, v), b = m.Evaluate(v, l);
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a[c], b[c], 1e-12 * std::max(1.0, std::abs(a[c])))
                << ModelName(m.model) << " at " << ti << "," << to << "," << po;
        }
  }
}

TEST(Models, DirectionalAlbedoAtMostOne) {
  for (const Material& m : ValidMaterials()) {
    ASSERT_TRUE(PhysicalProblems(m).empty()) << ModelName(m.model);
    for (double ti : {0.0, 30.0, 60.0, 75.0}) {
      const Rgb a = Albedo(m, ti);
      // 5e-4 covers the quadrature error: the lobe-only Lafortune at normal incidence has
      // albedo exactly 1 (see LafortuneLobeIsNormalisedAtNormalIncidence).
      for (int c = 0; c < 3; ++c)
        EXPECT_LE(a[c], 1.0 + 5e-4) << ModelName(m.model) << " channel " << c << " θin " << ti;
    }
  }
}

TEST(Models, LambertAlbedoEqualsRho) {
  const Material m = Make(Model::kLambert, {0.9, 0.5, 0.1}, {}, {});
  const Rgb a = Albedo(m, 30.0, 400, 64);
  EXPECT_NEAR(a[0], 0.9, 1e-5);
  EXPECT_NEAR(a[1], 0.5, 1e-5);
  EXPECT_NEAR(a[2], 0.1, 1e-5);
}

TEST(Models, LafortuneLobeIsNormalisedAtNormalIncidence) {
  // At θin = 0 the mirror is the normal and ∫ (n+2)/(2π) cos^n θ cosθ dω = 1 exactly.
  const Material m = Make(Model::kLafortune, {0, 0, 0}, {1, 1, 1}, {3, 20, 200});
  const Rgb a = Albedo(m, 0.0, 4000, 16);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], 1.0, 2e-4) << c;
}

TEST(Models, GgxMatchesTheTanSquaredFormOfDesign) {
  // docs/design.md §9 written literally: D = α² / (π cos⁴θh (α² + tan²θh)²),
  // G1 = 2 / (1 + √(1 + α² tan²θ)), F = f0 + (1 − f0)(1 − v·h)⁵.
  const double alpha = 0.3, f0 = 0.04, kd = 0.25;
  const Material m = Make(Model::kGgx, {kd, kd, kd}, {f0, f0, f0}, {alpha, alpha, alpha});
  for (double ti = 5; ti < 85; ti += 17)
    for (double to = 3; to < 85; to += 19)
      for (double po = 0; po < 360; po += 45) {
        const Vec3 l = SphericalDirectionDeg(ti, 0), v = SphericalDirectionDeg(to, po);
        Vec3 h = l + v;
        h = h * (1.0 / std::sqrt(Dot(h, h)));
        const double ch = h.z, th2 = (1 - ch * ch) / (ch * ch);
        const double d = alpha * alpha / (kPi * std::pow(ch, 4) * std::pow(alpha * alpha + th2, 2));
        auto g1 = [&](double c) {
          const double t2 = (1 - c * c) / (c * c);
          return 2.0 / (1.0 + std::sqrt(1.0 + alpha * alpha * t2));
        };
        const double f = f0 + (1 - f0) * std::pow(1 - Dot(v, h), 5);
        const double expected = kd / kPi + f * g1(l.z) * g1(v.z) * d / (4 * l.z * v.z);
        EXPECT_NEAR(m.Evaluate(l, v)[0], expected, 1e-12 * expected);
      }
}

TEST(Models, WardAtMirrorDirection) {
  // At the mirror direction h = n, tanθh = 0, so f = ρd/π + ρs / (4π α² cosθi).
  const Material m = Make(Model::kWard, {0.1, 0.1, 0.1}, {0.2, 0.2, 0.2}, {0.15, 0.15, 0.15});
  const double ti = DegToRad(35.0);
  const Vec3 l = SphericalDirection(ti, 0), v = SphericalDirection(ti, kPi);
  const double expected = 0.1 / kPi + 0.2 / (4 * kPi * 0.15 * 0.15 * std::cos(ti));
  EXPECT_NEAR(m.Evaluate(l, v)[1], expected, 1e-12 * expected);
}

TEST(Models, ZeroBelowHorizon) {
  for (const Material& m : ValidMaterials()) {
    const Rgb f = m.Evaluate(SphericalDirectionDeg(30, 0), SphericalDirectionDeg(95, 180));
    EXPECT_EQ(f[0], 0.0);
  }
}

TEST(MaterialJson, RoundTripsAndAcceptsScalarsForRgb) {
  const Material m = ParseMaterialJson(
      R"({"name":"x","model":"ggx","kd":[0.1,0.2,0.3],"f0":0.04,"alpha":0.3,"fit":{"rmse":1}})");
  EXPECT_EQ(m.model, Model::kGgx);
  EXPECT_DOUBLE_EQ(m.Parameter(1)[2], 0.04);
  EXPECT_DOUBLE_EQ(m.Parameter(2)[1], 0.3);
  const Material again = ParseMaterialJson(MaterialToJson(m));
  EXPECT_EQ(again.Parameter(0), m.Parameter(0));
  EXPECT_EQ(again.Parameter(1), m.Parameter(1));
  EXPECT_NE(MaterialToJson(again).find("\"fit\""), std::string::npos);
}

TEST(MaterialJson, ErrorsNameMemberExpectedAndFound) {
  try {
    ParseMaterialJson(R"({"model":"ggx","kd":[0.1,0.2],"f0":0.04,"alpha":0.3})", "m.json");
    FAIL() << "no exception";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), "m.json");
    EXPECT_NE(std::string(e.what()).find("'kd'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[0.1,0.2]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseMaterialJson(R"({"model":"phong"})"), FormatError);
  EXPECT_THROW(ParseMaterialJson(R"({"model":"lambert","rho":[1,2,)"), FormatError);
  EXPECT_THROW(ParseMaterialJson(R"({"model":"ward","rho_d":0.1,"rho_s":0.1,"alpha":0})"),
               FormatError);
}

}  // namespace
}  // namespace brdf
