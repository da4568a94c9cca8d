// The value rule of docs/design.md §4 ("Values no surface has"): the limits are checked at the
// numbers that section derives (f_r·cosθout ≤ 1e5 1/sr; negative down to 1 % of the slice's
// peak, at least 1e-3 1/sr, or 5σ), on both sides of each, through the functions every command
// uses (FindLutInputProblems and BuildLut).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "brdf/core/error.h"
#include "brdf/processing/resample.h"
#include "synthetic_capture.h"

namespace brdf::processing {
namespace {

// Lambertian (ρ = 0.8, 0.5, 0.2) on a 10° grid at θin 0°, 20°: every value below 0.26 1/sr.
Measurement Base() { return test::GridCapture(test::Lambertian(), {0, 20}, 75.0, 10.0); }

// The index of the sample of slice `s` at θout `theta_deg`, φout 0.
std::size_t SampleAt(const Measurement& m, std::size_t s, double theta_deg) {
  const auto& v = m.slices[s].samples;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::fabs(v[i].theta_out_deg - theta_deg) < 1e-3 && std::fabs(v[i].phi_out_deg) < 1e-3)
      return i;
  ADD_FAILURE() << "no sample at θout " << theta_deg;
  return 0;
}

std::string Problems(const Measurement& m) {
  ResampleOptions any;
  any.require_uniform_theta_in = false;
  std::string text;
  for (const LutInputProblem& p : FindLutInputProblems(m, any)) text += p.message + "\n";
  return text;
}

TEST(PlausibleValues, UpperBoundIsOnFrTimesCosThetaOut) {
  Measurement m = Base();
  const std::size_t n = SampleAt(m, 1, 60);  // cos 60° = 0.5
  m.slices[1].samples[n].rgb[1] = 1.99e5f;   // f_r·cos = 0.995e5: a value a surface may have
  EXPECT_EQ(Problems(m), "");
  EXPECT_NO_THROW(BuildLut(m));
  m.slices[1].samples[n].rgb[1] = 2.01e5f;  // 1.005e5
  const std::string text = Problems(m);
  EXPECT_NE(text.find("slice 1"), std::string::npos) << text;
  EXPECT_NE(text.find("sample " + std::to_string(n)), std::string::npos) << text;
  EXPECT_NE(text.find("green f_r·cosθout above 1e5"), std::string::npos) << text;
  EXPECT_THROW(BuildLut(m), InvalidArgument);
}

TEST(PlausibleValues, TheHorizonIsBoundedAtCos89) {
  Measurement m = Base();
  Sample s = m.slices[0].samples.front();
  s.theta_out_deg = 90.0f;
  s.rgb = {1e5f / 0.0174524f * 0.99f, 0.1f, 0.1f};  // just under 1e5 / cos 89°
  m.slices[0].samples.push_back(s);
  EXPECT_EQ(Problems(m), "");
  m.slices[0].samples.back().rgb[0] = 3e38f;
  EXPECT_NE(Problems(m).find("red f_r·cosθout above 1e5"), std::string::npos) << Problems(m);
}

TEST(PlausibleValues, NegativeNoiseIsOnePercentOfTheSlicePeakOrFiveSigma) {
  Measurement m = Base();
  const std::size_t peak = SampleAt(m, 0, 10), low = SampleAt(m, 0, 50);
  m.slices[0].samples[peak].rgb[0] = 10.0f;  // the slice's peak: allowance 0.1 1/sr
  m.slices[0].samples[low].rgb[2] = -0.099f;
  EXPECT_EQ(Problems(m), "");
  m.slices[0].samples[low].rgb[2] = -0.101f;
  const std::string text = Problems(m);
  EXPECT_NE(text.find("sample " + std::to_string(low)), std::string::npos) << text;
  EXPECT_NE(text.find("blue f_r negative beyond noise"), std::string::npos) << text;
  // The sample's own σ widens it to 5σ.
  m.slices[0].has_sigma = true;
  m.slices[0].samples[low].sigma[2] = 0.021f;
  EXPECT_EQ(Problems(m), "");
  m.slices[0].samples[low].sigma[2] = 0.019f;
  EXPECT_NE(Problems(m), "");
}

TEST(PlausibleValues, NegativeFloorIsOneThousandthPerSr) {
  Measurement m = Base();
  for (Slice& s : m.slices)
    for (Sample& x : s.samples) x.rgb = {0.05f, 0.05f, 0.05f};  // peak 0.05: 1 % is 5e-4
  const std::size_t n = SampleAt(m, 1, 30);
  m.slices[1].samples[n].rgb[0] = -0.00099f;
  EXPECT_EQ(Problems(m), "");
  m.slices[1].samples[n].rgb[0] = -0.00101f;
  EXPECT_NE(Problems(m).find("red f_r negative beyond noise"), std::string::npos);
}

TEST(PlausibleValues, NegatedAndScaledCapturesAreRefusedFlaggedInvalidOnesIgnored) {
  Measurement negated = Base(), scaled = Base();
  for (Slice& s : negated.slices)
    for (Sample& x : s.samples)
      for (float& v : x.rgb) v = -v;
  for (Slice& s : scaled.slices)
    for (Sample& x : s.samples)
      for (float& v : x.rgb) v *= 1e30f;
  EXPECT_NE(Problems(negated).find("negative beyond noise"), std::string::npos);
  EXPECT_NE(Problems(scaled).find("above 1e5"), std::string::npos);
  Measurement flagged = Base();
  flagged.slices[1].samples[3].rgb[0] = -1e30f;
  flagged.slices[1].samples[3].flags |= kFlagInvalid;  // no usable value, and says so
  EXPECT_EQ(Problems(flagged), "");
}

}  // namespace
}  // namespace brdf::processing
