// docs/design.md §6: the restricted quadratic Bézier b(x, l), the extrapolation factor and the ways
// a user supplies p and l. Reference values come from a bisection on the curve written in
// synthetic_capture.h, never from the closed-form root under test.
#include "brdf/processing/extrapolation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "brdf/core/error.h"
#include "synthetic_capture.h"
#include "test_support.h"

namespace brdf::processing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(BezierB, IsIdentityAtLHalf) {
  for (int n = 0; n <= 1000; ++n) {
    const double x = n / 1000.0;
    EXPECT_NEAR(BezierB(x, 0.5), x, 1e-15) << "x = " << x;
  }
}

TEST(BezierB, IsZeroAtZeroAndOneAtOne) {
  for (int n = 0; n <= 100; ++n) {
    const double l = n / 100.0;
    EXPECT_EQ(BezierB(0.0, l), 0.0) << "l = " << l;
    EXPECT_NEAR(BezierB(1.0, l), 1.0, 1e-15) << "l = " << l;
  }
}

TEST(BezierB, IsMonotoneInX) {
  for (double l : {0.0, 0.05, 0.3, 0.5, 0.7, 0.95, 1.0}) {
    double prev = -1.0;
    for (int n = 0; n <= 20000; ++n) {
      const double y = BezierB(n / 20000.0, l);
      EXPECT_GE(y, prev) << "x = " << n / 20000.0 << ", l = " << l;
      prev = y;
    }
  }
}

TEST(BezierB, MatchesBisectionOnTheCurve) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int checked = 0;
  for (int n = 0; n < 20000; ++n) {
    const double x = n < 10000 ? u(rng) : (n % 101) / 100.0;
    const double l = n < 10000 ? u(rng) : (n / 101 % 101) / 100.0;
    EXPECT_NEAR(BezierB(x, l), test::BezierByBisection(x, l), 1e-12)
        << "x = " << x << ", l = " << l;
    ++checked;
  }
  EXPECT_EQ(checked, 20000);
  // The paper's illustrated curve, l = 0.3, at a few abscissae.
  for (double x : {0.01, 0.1, 0.25, 0.5, 0.9})
    EXPECT_NEAR(BezierB(x, 0.3), test::BezierByBisection(x, 0.3), 1e-12);
}

TEST(BezierB, BendsTowardsControlPoint) {
  // l < ½ puts P1 above the diagonal (the curve rises early), l > ½ below it.
  EXPECT_GT(BezierB(0.3, 0.2), 0.3);
  EXPECT_LT(BezierB(0.3, 0.8), 0.3);
}

TEST(BezierB, ClampsXAndRejectsBadArguments) {
  EXPECT_EQ(BezierB(-0.5, 0.3), 0.0);
  EXPECT_NEAR(BezierB(1.5, 0.3), 1.0, 1e-15);
  EXPECT_THROW(BezierB(kNaN, 0.3), InvalidArgument);
  EXPECT_THROW(BezierB(0.5, -0.01), InvalidArgument);
  EXPECT_THROW(BezierB(0.5, 1.01), InvalidArgument);
  EXPECT_THROW(BezierB(0.5, kNaN), InvalidArgument);
}

TEST(ExtrapolationFactor, MatchesDesignFormula) {
  for (double theta_b : {60.0, 70.0, 75.0, 80.0})
    for (double p : {0.0, 0.2, 1.0, 1.7})
      for (double l : {0.0, 0.3, 0.5, 1.0})
        for (double theta = 50.0; theta <= 100.0; theta += 0.37) {
          const ExtrapolationParams params{p, l};
          EXPECT_NEAR(ExtrapolationFactor(theta, theta_b, params),
                      test::FactorReference(theta, theta_b, p, l), 1e-12)
              << "θ = " << theta << ", θb = " << theta_b << ", p = " << p << ", l = " << l;
        }
}

TEST(ExtrapolationFactor, PEqualOneClamps) {
  for (double l : {0.0, 0.3, 0.5, 0.9, 1.0})
    for (double theta = 0.0; theta <= 120.0; theta += 0.5)
      EXPECT_NEAR(ExtrapolationFactor(theta, 75.0, {1.0, l}), 1.0, 1e-15) << "θ = " << theta;
  EXPECT_EQ(ExtrapolationParams{}.p, 1.0);
  EXPECT_EQ(ExtrapolationParams{}.l, 0.5);
}

TEST(ExtrapolationFactor, IsContinuousAtThetaB) {
  for (double l : {0.0, 0.3, 0.5, 1.0}) {
    const ExtrapolationParams params{0.2, l};
    EXPECT_EQ(ExtrapolationFactor(75.0, 75.0, params), 1.0);
    // l = 0 has a square-root start (t = √x), the slowest approach to 1; still continuous.
    EXPECT_NEAR(ExtrapolationFactor(75.0 + 1e-12, 75.0, params), 1.0, 1e-5) << "l = " << l;
    EXPECT_NEAR(ExtrapolationFactor(75.0 + 1e-6, 75.0, params), 1.0, 1e-2) << "l = " << l;
  }
}

TEST(ExtrapolationFactor, ReachesPAtTheHorizonAndStaysThere) {
  const ExtrapolationParams params{0.2, 0.3};
  EXPECT_NEAR(ExtrapolationFactor(90.0, 75.0, params), 0.2, 1e-15);
  EXPECT_NEAR(ExtrapolationFactor(135.0, 75.0, params), 0.2, 1e-15);
  // Nothing to extrapolate when the data reaches the horizon.
  EXPECT_EQ(ExtrapolationFactor(90.0, 90.0, params), 1.0);
}

TEST(ExtrapolationFactor, RejectsBadThetaB) {
  EXPECT_THROW(ExtrapolationFactor(80, -1, {}), InvalidArgument);
  EXPECT_THROW(ExtrapolationFactor(80, 91, {}), InvalidArgument);
  EXPECT_THROW(ExtrapolationFactor(80, kNaN, {}), InvalidArgument);
  EXPECT_THROW(ExtrapolationFactor(kNaN, 75, {}), InvalidArgument);
}

TEST(ExtrapolationParams, ValidateNamesTheBadParameter) {
  EXPECT_NO_THROW((ExtrapolationParams{0.0, 0.0}.Validate()));
  EXPECT_NO_THROW((ExtrapolationParams{5.0, 1.0}.Validate()));
  for (const ExtrapolationParams& bad :
       {ExtrapolationParams{-0.1, 0.5}, ExtrapolationParams{kInf, 0.5},
        ExtrapolationParams{kNaN, 0.5}}) {
    try {
      bad.Validate();
      ADD_FAILURE() << "p = " << bad.p << " accepted";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("parameter p"), std::string::npos) << e.what();
    }
  }
  for (const ExtrapolationParams& bad :
       {ExtrapolationParams{1.0, -0.01}, ExtrapolationParams{1.0, 1.01},
        ExtrapolationParams{1.0, kNaN}}) {
    try {
      bad.Validate();
      ADD_FAILURE() << "l = " << bad.l << " accepted";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("parameter l"), std::string::npos) << e.what();
    }
  }
}

TEST(ParseExtrapolation, ReadsPAndL) {
  EXPECT_EQ(ParseExtrapolation("0.2,0.3"), (ExtrapolationParams{0.2, 0.3}));
  EXPECT_EQ(ParseExtrapolation(" 1 , 0.5 "), (ExtrapolationParams{1.0, 0.5}));
  EXPECT_EQ(ParseExtrapolation("1e-1,0"), (ExtrapolationParams{0.1, 0.0}));
  EXPECT_EQ(ParseExtrapolation("2,1"), (ExtrapolationParams{2.0, 1.0}));
}

TEST(ParseExtrapolation, RejectsMalformedTextQuotingIt) {
  for (const char* bad : {"", "0.2", "0.2,", ",0.3", "a,b", "0.2,0.3,0.4", "0.2;0.3", "-1,0.5",
                          "1,2", "nan,0.5", "inf,0.5", "0.2x,0.3", "1e999,0.5"}) {
    try {
      ParseExtrapolation(bad);
      ADD_FAILURE() << "'" << bad << "' accepted";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("P,L"), std::string::npos) << e.what();
    }
  }
}

TEST(FormatExtrapolation, RoundTripsThroughParse) {
  for (const ExtrapolationParams& p :
       {ExtrapolationParams{0.2, 0.3}, ExtrapolationParams{1.0 / 3.0, 0.1}, ExtrapolationParams{}})
    EXPECT_EQ(ParseExtrapolation(FormatExtrapolation(p)), p);
}

TEST(ExtrapolationJson, ReadsTheExtrapolateMember) {
  const auto p = ExtrapolationFromJson(R"({"model": "ggx", "extrapolate": {"p": 0.2, "l": 0.3}})");
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(*p, (ExtrapolationParams{0.2, 0.3}));
}

TEST(ExtrapolationJson, MissingMembersKeepDefaults) {
  EXPECT_EQ(*ExtrapolationFromJson(R"({"extrapolate": {"p": 0.4}})"),
            (ExtrapolationParams{0.4, 0.5}));
  EXPECT_EQ(*ExtrapolationFromJson(R"({"extrapolate": {"l": 0.1}})"),
            (ExtrapolationParams{1.0, 0.1}));
  EXPECT_FALSE(ExtrapolationFromJson(R"({"model": "lambert"})").has_value());
}

void ExpectJsonError(const std::string& text, const std::string& needle) {
  try {
    ExtrapolationFromJson(text, "mat.json");
    ADD_FAILURE() << text << " accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), "mat.json");
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(ExtrapolationJson, RejectsBadContentNamingIt) {
  ExpectJsonError(R"({"extrapolate": {"p": 0.2, "L": 0.3}})", "\"L\"");
  ExpectJsonError(R"({"extrapolate": {"p": "0.2"}})", "extrapolate.p");
  ExpectJsonError(R"({"extrapolate": [0.2, 0.3]})", "'extrapolate'");
  ExpectJsonError(R"({"extrapolate": {"p": -0.2}})",
                  "member 'extrapolate.p': expected a finite number >= 0");
  ExpectJsonError(
      R"({"extrapolate": {"l": 1.5}})",
      "member 'extrapolate.l': expected a number in [0, 1] (docs/design.md §6), got 1.5");
  ExpectJsonError(R"([1, 2])", "a JSON object");
  try {
    ExtrapolationFromJson(R"({"extrapolate": {"p": 0.2,, }})", "mat.json");
    ADD_FAILURE();
  } catch (const FormatError& e) {
    // The second comma is the 27th character of the only line.
    EXPECT_EQ(e.position(), "line 1, column 27") << e.position();
  }
}

class ExtrapolationFile : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& text) {
    static const std::filesystem::path dir = brdf::test::NewTempDir("extrapolation");
    const auto path = (dir / name).string();
    std::ofstream(path) << text;
    return path;
  }
};

TEST_F(ExtrapolationFile, LoadsParameters) {
  EXPECT_EQ(LoadExtrapolationJson(Write("a.json", R"({"extrapolate": {"p": 0.2, "l": 0.3}})")),
            (ExtrapolationParams{0.2, 0.3}));
}

TEST_F(ExtrapolationFile, RequiresTheMemberAndAReadableFile) {
  const std::string path = Write("b.json", R"({"model": "lambert"})");
  try {
    LoadExtrapolationJson(path);
    ADD_FAILURE();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("extrapolate"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadExtrapolationJson(path + ".missing"), IoError);
}

}  // namespace
}  // namespace brdf::processing
