#include "brdf/core/gonio.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "test_support.h"

namespace brdf {
namespace {

std::string SharedTable() {
  return brdf::test::DataPath("goniometer-csv/test_brdf_viewer_2D_data.csv");
}

// The shared table parsed here with getline/strtod, independently of the reader.
struct RawRow {
  double incidence, angle;
  std::vector<double> values;
};
std::vector<RawRow> RawRows() {
  std::ifstream in(SharedTable());
  std::string line;
  std::getline(in, line);  // header
  std::vector<RawRow> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string cell;
    RawRow r;
    std::getline(ss, cell, ',');
    r.incidence = std::strtod(cell.c_str(), nullptr);
    std::getline(ss, cell, ',');
    r.angle = std::strtod(cell.c_str(), nullptr);
    while (std::getline(ss, cell, ',')) r.values.push_back(std::strtod(cell.c_str(), nullptr));
    rows.push_back(std::move(r));
  }
  return rows;
}

TEST(Cie, D65WhitePointChromaticityMatchesThePublishedValue) {
  // CIE 015: D65 with the 1931 2° observer has chromaticity (x, y) = (0.31271, 0.32902).
  std::vector<double> nm, flat;
  for (int w = 380; w <= 780; w += 10) {
    nm.push_back(w);
    flat.push_back(1.0);
  }
  const auto xyz = ReflectanceToXyz(nm, flat);
  const double sum = xyz[0] + xyz[1] + xyz[2];
  EXPECT_NEAR(xyz[1], 1.0, 1e-12);
  EXPECT_NEAR(xyz[0] / sum, 0.31271, 2e-4);
  EXPECT_NEAR(xyz[1] / sum, 0.32902, 2e-4);
  // Published D65 tristimulus values (Y = 100 scale): X = 95.047, Z = 108.883.
  EXPECT_NEAR(xyz[0], 0.95047, 1e-3);
  EXPECT_NEAR(xyz[2], 1.08883, 1e-3);
}

TEST(Cie, Rec709MatrixMapsD65WhiteToEqualRgb) {
  const auto rgb = XyzToLinearRec709({0.95047, 1.0, 1.08883});
  for (double v : rgb) EXPECT_NEAR(v, 1.0, 1e-3);
  // The published sRGB blue primary XYZ (0.1805, 0.0722, 0.9505) maps to (0, 0, 1).
  const auto blue = XyzToLinearRec709({0.1805, 0.0722, 0.9505});
  EXPECT_NEAR(blue[0], 0.0, 1e-3);
  EXPECT_NEAR(blue[1], 0.0, 1e-3);
  EXPECT_NEAR(blue[2], 1.0, 1e-3);
}

TEST(Cie, FlatSpectrumGivesExactlyNeutralRgb) {
  std::vector<double> nm, half;
  for (int w = 390; w <= 730; w += 10) {
    nm.push_back(w);
    half.push_back(0.5);
  }
  for (double v : ReflectanceToLinearRec709(nm, half)) EXPECT_NEAR(v, 0.5, 1e-12);
  EXPECT_THROW(Cie1931Cmf(395), InvalidArgument);
}

TEST(Gonio, ReadsTheSharedTableWithItsOwnShape) {
  const GonioTable t = ReadGonioTable(SharedTable());
  ASSERT_EQ(t.wavelengths_nm.size(), 35u);
  EXPECT_EQ(t.wavelengths_nm.front(), 390.0);
  EXPECT_EQ(t.wavelengths_nm.back(), 730.0);
  const std::vector<RawRow> raw = RawRows();
  ASSERT_EQ(t.rows.size(), raw.size());
  ASSERT_EQ(t.rows.size(), 329u);
  for (std::size_t i = 0; i < raw.size(); ++i) {
    EXPECT_EQ(t.rows[i].incidence_deg, raw[i].incidence);
    EXPECT_EQ(t.rows[i].measurement_angle_deg, raw[i].angle);
    EXPECT_EQ(t.rows[i].reflectance_factor, raw[i].values);
    EXPECT_EQ(t.rows[i].line, i + 2);
  }
}

// The file's numbers at its own angles: every sample's RGB is the file row's reflectance
// factor / π taken through the documented colour conversion, recomputed here step by step.
TEST(Gonio, InPlaneValuesReproduceTheFileAtItsOwnAngles) {
  const Measurement m = LoadGonioTable(SharedTable());
  const std::vector<RawRow> raw = RawRows();
  std::vector<double> nm;
  for (int w = 390; w <= 730; w += 10) nm.push_back(w);
  const auto to_rgb = [&](const std::vector<double>& spectrum) {
    std::array<double, 3> xyz{};
    double norm = 0;
    for (std::size_t k = 0; k < nm.size(); ++k) {
      const auto cmf = Cie1931Cmf(nm[k]);
      for (int c = 0; c < 3; ++c) xyz[c] += spectrum[k] * cmf[c] * CieD65(nm[k]);
      norm += cmf[1] * CieD65(nm[k]);
    }
    for (double& v : xyz) v /= norm;
    return std::array<double, 3>{3.2406 * xyz[0] - 1.5372 * xyz[1] - 0.4986 * xyz[2],
                                 -0.9689 * xyz[0] + 1.8758 * xyz[1] + 0.0415 * xyz[2],
                                 0.0557 * xyz[0] - 0.2040 * xyz[1] + 1.0570 * xyz[2]};
  };
  const auto white = to_rgb(std::vector<double>(nm.size(), 1.0));
  std::map<double, std::size_t> next_in_slice;
  ASSERT_EQ(m.slices.size(), 5u);
  std::map<double, const Slice*> slice_of;
  for (const Slice& s : m.slices) slice_of[s.theta_in_deg] = &s;
  std::size_t checked = 0;
  for (const RawRow& r : raw) {
    ASSERT_TRUE(slice_of.count(r.incidence));
    const Sample& s = slice_of[r.incidence]->samples.at(next_in_slice[r.incidence]++);
    EXPECT_EQ(s.theta_in_deg, static_cast<float>(r.incidence));
    EXPECT_EQ(s.theta_out_deg, static_cast<float>(std::fabs(r.angle)));
    EXPECT_EQ(s.phi_out_deg, r.angle > 0 ? 180.0f : 0.0f);
    std::vector<double> fr;
    for (double v : r.values) fr.push_back(v / kPi);
    const auto rgb = to_rgb(fr);
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(s.rgb[c], rgb[c] / white[c], 1e-6 * std::fabs(rgb[c]) + 1e-9);
    ++checked;
  }
  EXPECT_EQ(checked, 329u);
}

TEST(Gonio, SpecularPeakOfEachIncidenceLandsOnTheMirrorDirection) {
  const Measurement m = LoadGonioTable(SharedTable());
  for (const Slice& s : m.slices) {
    const Sample* peak = &s.samples.front();
    for (const Sample& smp : s.samples)
      if (smp.rgb[1] > peak->rgb[1]) peak = &smp;
    EXPECT_EQ(peak->theta_out_deg, static_cast<float>(s.theta_in_deg)) << s.theta_in_deg;
    EXPECT_EQ(peak->phi_out_deg, 180.0f) << s.theta_in_deg;
    // The mirror direction of docs/design.md §4: (θin, φin + 180°).
    const Vec3 w = SphericalDirectionDeg(peak->theta_out_deg, peak->phi_out_deg);
    const Vec3 mirror = Reflect(SphericalDirectionDeg(s.theta_in_deg, 0.0));
    EXPECT_NEAR(Dot(w, mirror), 1.0, 1e-6);
  }
}

TEST(Gonio, RowsShadowedByTheSourceAreFlaggedInvalid) {
  const Measurement m = LoadGonioTable(SharedTable());
  std::size_t zero_rows = 0;
  for (const RawRow& r : RawRows()) {
    bool all_zero = true;
    for (double v : r.values) all_zero = all_zero && v == 0.0;
    zero_rows += all_zero;
  }
  std::size_t invalid = 0;
  for (const Slice& s : m.slices) {
    for (const Sample& smp : s.samples) {
      if (!(smp.flags & kFlagInvalid)) continue;
      ++invalid;
      EXPECT_EQ(smp.phi_out_deg, 0.0f);  // on the source's side
      EXPECT_NEAR(smp.theta_out_deg, s.theta_in_deg, 10.0);
    }
  }
  EXPECT_EQ(invalid, zero_rows);
  EXPECT_GT(invalid, 0u);
}

TEST(Gonio, RejectsBandsOffTheCieGrid) {
  try {
    ParseGonioTable("Incident_angle,Measure_angle,395nm\n10,0,0.5\n", "g.csv");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()),
              "g.csv: line 1: expected a band on the CIE 10 nm grid between 380 and 780 nm, got "
              "'395nm'");
  }
}

}  // namespace
}  // namespace brdf
