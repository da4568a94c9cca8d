#include "brdf/core/csv.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/models.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// An instrument-like capture of a Ward material: θin 0/20/40/60, θout 0..75 step 3, φout
// 0..357 step 3 (non-round floats on purpose: values come from the model).
Measurement WardCapture(bool with_sigma) {
  Material mat;
  mat.model = Model::kWard;
  mat.SetParameter(0, {0.25, 0.18, 0.08});
  mat.SetParameter(1, {0.05, 0.05, 0.05});
  mat.SetParameter(2, {0.15, 0.15, 0.15});
  Measurement m;
  m.metadata.sample_name = "ward, painted";
  m.metadata.operator_notes = "line one\nline two with a backslash \\ and = sign";
  m.metadata.capture_start = "2026-11-22T10:04:05Z";
  m.metadata.extra["seed"] = "42";
  for (double tin : {0.0, 20.0, 40.0, 60.0}) {
    Slice s;
    s.theta_in_deg = tin;
    s.has_sigma = with_sigma;
    s.complete = tin != 60.0;
    const Vec3 l = SphericalDirectionDeg(tin, 0.0);
    for (int t = 0; t <= 75; t += 3) {
      for (int p = 0; p < 360; p += 3) {
        Sample smp;
        smp.theta_in_deg = static_cast<float>(tin);
        smp.theta_out_deg = static_cast<float>(t);
        smp.phi_out_deg = static_cast<float>(p);
        const Rgb f = mat.Evaluate(l, SphericalDirectionDeg(t, p));
        for (int c = 0; c < 3; ++c) {
          smp.rgb[c] = static_cast<float>(f[c]);
          if (with_sigma) smp.sigma[c] = static_cast<float>(0.01 * f[c]);
        }
        smp.flags = (t == 75 && p == 90) ? kFlagSaturated | kFlagInterpolated : 0;
        s.samples.push_back(smp);
      }
    }
    m.slices.push_back(std::move(s));
  }
  return m;
}

TEST(Csv, RoundTripIsBitExact) {
  const fs::path dir = brdf::test::NewTempDir("csv");
  for (bool with_sigma : {false, true}) {
    const Measurement m = WardCapture(with_sigma);
    const std::string path = (dir / "ward.csv").string();
    WriteCsv(path, m);
    const Measurement back = ReadCsv(path);
    EXPECT_EQ(back.metadata.sample_name, m.metadata.sample_name);
    EXPECT_EQ(back.metadata.operator_notes, m.metadata.operator_notes);
    EXPECT_EQ(back.metadata.capture_start, m.metadata.capture_start);
    EXPECT_EQ(back.metadata.extra.at("seed"), "42");
    ASSERT_EQ(back.slices.size(), m.slices.size());
    for (std::size_t i = 0; i < m.slices.size(); ++i) {
      const Slice& a = m.slices[i];
      const Slice& b = back.slices[i];
      EXPECT_EQ(b.theta_in_deg, a.theta_in_deg);
      EXPECT_EQ(b.has_sigma, with_sigma);
      EXPECT_EQ(b.complete, a.complete);
      ASSERT_EQ(b.samples.size(), a.samples.size());
      for (std::size_t k = 0; k < a.samples.size(); ++k) {
        const Sample& x = a.samples[k];
        const Sample& y = b.samples[k];
        ASSERT_TRUE(SameBits(x.theta_out_deg, y.theta_out_deg) &&
                    SameBits(x.phi_out_deg, y.phi_out_deg));
        for (int c = 0; c < 3; ++c) {
          ASSERT_TRUE(SameBits(x.rgb[c], y.rgb[c])) << x.rgb[c] << " vs " << y.rgb[c];
          ASSERT_TRUE(SameBits(x.sigma[c], y.sigma[c]));
        }
        ASSERT_EQ(x.flags, y.flags);
      }
    }
  }
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);  // the atomic writer left no temporary behind
  fs::remove_all(dir);
}

TEST(Csv, ReadsHandWrittenFileWithColumnsInAnyOrder) {
  const std::string text =
      "# a spreadsheet export\n"
      "r,g,b,theta_out_deg,phi_out_deg,theta_in_deg,phi_in_deg\r\n"
      "0.5,0.25,0.125,30,-90,20,0\r\n"
      "1,2,3,45,180,20,0\r\n"
      "\r\n"
      "0.1,0.1,0.1,10,0,0,0\r\n";
  const Measurement m = ParseCsv(text, "hand.csv");
  ASSERT_EQ(m.slices.size(), 2u);
  EXPECT_EQ(m.slices[0].theta_in_deg, 0.0);
  ASSERT_EQ(m.slices[1].samples.size(), 2u);
  const Sample& s = m.slices[1].samples[0];
  EXPECT_EQ(s.theta_in_deg, 20.0f);
  EXPECT_EQ(s.theta_out_deg, 30.0f);
  EXPECT_EQ(s.phi_out_deg, 270.0f);  // −90° wrapped
  EXPECT_EQ(s.rgb[0], 0.5f);
  EXPECT_EQ(s.rgb[1], 0.25f);
  EXPECT_EQ(s.rgb[2], 0.125f);
  EXPECT_EQ(s.flags, 0);
  EXPECT_FALSE(m.slices[1].has_sigma);
}

TEST(Csv, ReportsLineAndColumnOfBadValues) {
  const auto message = [](const std::string& text) {
    try {
      ParseCsv(text, "bad.csv");
    } catch (const FormatError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string header = "theta_in,phi_in,theta_out,phi_out,r,g,b\n";
  EXPECT_EQ(message(header + "0,0,10,0,1,1,1\n0,0,95,0,1,1,1\n"),
            "bad.csv: line 3: expected theta_out in [0, 90], got '95'");
  EXPECT_EQ(message(header + "0,0,10,0,1,inf,1\n"),
            "bad.csv: line 2: expected g (a finite number), got 'inf'");
  EXPECT_EQ(message("theta_in,phi_in,theta_out,phi_out,r,g\n"),
            "bad.csv: line 1: expected a header with a b column, got "
            "'theta_in,phi_in,theta_out,phi_out,r,g'");
  EXPECT_EQ(message(header),
            "bad.csv: line 2: expected at least one data row after the header, "
            "got end of file");
}

}  // namespace
}  // namespace brdf

namespace brdf {
namespace {

// Found by csv_fuzzer: a finite double beyond the float32 range (FLT_MAX ≈ 3.40282e38) became
// inf in the capture, which no writer can store; the largest float itself is kept.
TEST(Csv, RefusesValuesBeyondFloat32RangeNamingTheLine) {
  const std::string header = "theta_in,phi_in,theta_out,phi_out,r,g,b,sigma_r,sigma_g,sigma_b\n";
  try {
    ParseCsv(header + "20,0,35,180,0.1,0.1,0.1,1e39,0,0\n", "big.csv");
    FAIL() << "no exception";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("big.csv: line 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1e39"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseCsv(header + "20,0,35,180,-1e39,0.1,0.1,0,0,0\n", "big.csv"), FormatError);
  const Measurement m = ParseCsv(header + "20,0,35,180,3.4028235e38,0.1,0.1,0,0,0\n", "ok.csv");
  EXPECT_EQ(m.slices.at(0).samples.at(0).rgb[0], 3.4028235e38f);
}

}  // namespace
}  // namespace brdf
