#include "brdf/core/gonio.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "readers/text_util.h"

namespace brdf {
namespace {

// CIE 1931 2° standard colorimetric observer and CIE standard illuminant D65 at 10 nm,
// 380–780 nm: CIE 015:2018 "Colorimetry", 4th ed., tables 1 (D65 relative spectral power)
// and 6 (x̄, ȳ, z̄ of the 1931 observer), every second row of the 5 nm tables.
constexpr double kFirstNm = 380.0;
constexpr int kBands = 41;
constexpr double kCmf[kBands][3] = {
    {0.001368, 0.000039, 0.006450}, {0.004243, 0.000120, 0.020050},  // 380, 390
    {0.014310, 0.000396, 0.067850}, {0.043510, 0.001210, 0.207400},  // 400, 410
    {0.134380, 0.004000, 0.645600}, {0.283900, 0.011600, 1.385600},  // 420, 430
    {0.348280, 0.023000, 1.747060}, {0.336200, 0.038000, 1.772110},  // 440, 450
    {0.290800, 0.060000, 1.669200}, {0.195360, 0.090980, 1.287640},  // 460, 470
    {0.095640, 0.139020, 0.812950}, {0.032010, 0.208020, 0.465180},  // 480, 490
    {0.004900, 0.323000, 0.272000}, {0.009300, 0.503000, 0.158200},  // 500, 510
    {0.063270, 0.710000, 0.078250}, {0.165500, 0.862000, 0.042160},  // 520, 530
    {0.290400, 0.954000, 0.020300}, {0.433450, 0.994950, 0.008750},  // 540, 550
    {0.594500, 0.995000, 0.003900}, {0.762100, 0.952000, 0.002100},  // 560, 570
    {0.916300, 0.870000, 0.001650}, {1.026300, 0.757000, 0.001100},  // 580, 590
    {1.062200, 0.631000, 0.000800}, {1.002600, 0.503000, 0.000340},  // 600, 610
    {0.854450, 0.381000, 0.000190}, {0.642400, 0.265000, 0.000050},  // 620, 630
    {0.447900, 0.175000, 0.000020}, {0.283500, 0.107000, 0.000000},  // 640, 650
    {0.164900, 0.061000, 0.000000}, {0.087400, 0.032000, 0.000000},  // 660, 670
    {0.046770, 0.017000, 0.000000}, {0.022700, 0.008210, 0.000000},  // 680, 690
    {0.011359, 0.004102, 0.000000}, {0.005790, 0.002091, 0.000000},  // 700, 710
    {0.002899, 0.001047, 0.000000}, {0.001440, 0.000520, 0.000000},  // 720, 730
    {0.000690, 0.000249, 0.000000}, {0.000332, 0.000120, 0.000000},  // 740, 750
    {0.000166, 0.000060, 0.000000}, {0.000083, 0.000030, 0.000000},  // 760, 770
    {0.000042, 0.000015, 0.000000},                                  // 780
};
constexpr double kD65[kBands] = {
    49.9755, 54.6482, 82.7549, 91.4860, 93.4318, 86.6823, 104.865, 117.008, 117.812,
    114.861, 115.923, 108.811, 109.354, 107.802, 104.790, 107.689, 104.405, 104.046,
    100.000, 96.3342, 95.7880, 88.6856, 90.0062, 89.5991, 87.6987, 83.2886, 83.6992,
    80.0268, 80.0456, 82.2778, 78.2842, 69.7213, 71.6091, 74.3490, 61.6040, 69.8856,
    75.0870, 63.5927, 46.4182, 66.8054, 63.3828,
};

// Index of a wavelength on the 10 nm grid, or -1.
int BandIndex(double wavelength_nm) {
  const double k = (wavelength_nm - kFirstNm) / 10.0;
  const double r = std::round(k);
  if (std::fabs(k - r) > 1e-9 || r < 0 || r >= kBands) return -1;
  return static_cast<int>(r);
}

int RequireBand(double wavelength_nm) {
  const int i = BandIndex(wavelength_nm);
  if (i < 0)
    throw InvalidArgument("wavelength " + detail::FormatShortest(wavelength_nm) +
                          " nm is not on the CIE 10 nm grid 380..780 nm");
  return i;
}

// "390nm" → 390.
double ParseBandHeader(std::string_view field, const std::string& file) {
  std::string_view f = field;
  if (f.size() < 3 || !detail::EqualsIgnoreCase(f.substr(f.size() - 2), "nm"))
    detail::Fail(file, 1, "a band column named like '550nm'", detail::Printable(field));
  f.remove_suffix(2);
  const double nm = detail::ParseFiniteDouble(detail::Trim(f), file, 1, "band wavelength in nm");
  if (BandIndex(nm) < 0)
    detail::Fail(file, 1, "a band on the CIE 10 nm grid between 380 and 780 nm",
                 detail::Printable(field));
  return nm;
}

}  // namespace

std::array<double, 3> Cie1931Cmf(double wavelength_nm) {
  const int i = RequireBand(wavelength_nm);
  return {kCmf[i][0], kCmf[i][1], kCmf[i][2]};
}

double CieD65(double wavelength_nm) { return kD65[RequireBand(wavelength_nm)]; }

std::array<double, 3> ReflectanceToXyz(const std::vector<double>& wavelengths_nm,
                                       const std::vector<double>& reflectance) {
  if (wavelengths_nm.size() != reflectance.size() || wavelengths_nm.empty())
    throw InvalidArgument("ReflectanceToXyz: " + std::to_string(wavelengths_nm.size()) +
                          " wavelengths for " + std::to_string(reflectance.size()) + " values");
  std::array<double, 3> xyz{};
  double norm = 0;
  for (std::size_t k = 0; k < wavelengths_nm.size(); ++k) {
    const int i = RequireBand(wavelengths_nm[k]);
    for (int c = 0; c < 3; ++c) xyz[c] += reflectance[k] * kCmf[i][c] * kD65[i];
    norm += kCmf[i][1] * kD65[i];
  }
  if (!(norm > 0)) throw InvalidArgument("ReflectanceToXyz: bands carry no luminance weight");
  for (double& v : xyz) v /= norm;
  return xyz;
}

std::array<double, 3> XyzToLinearRec709(const std::array<double, 3>& xyz) {
  // IEC 61966-2-1:1999 (sRGB), XYZ → linear RGB, D65 white.
  return {3.2406 * xyz[0] - 1.5372 * xyz[1] - 0.4986 * xyz[2],
          -0.9689 * xyz[0] + 1.8758 * xyz[1] + 0.0415 * xyz[2],
          0.0557 * xyz[0] - 0.2040 * xyz[1] + 1.0570 * xyz[2]};
}

std::array<double, 3> ReflectanceToLinearRec709(const std::vector<double>& wavelengths_nm,
                                                const std::vector<double>& reflectance) {
  const std::array<double, 3> rgb =
      XyzToLinearRec709(ReflectanceToXyz(wavelengths_nm, reflectance));
  const std::vector<double> flat(wavelengths_nm.size(), 1.0);
  const std::array<double, 3> white = XyzToLinearRec709(ReflectanceToXyz(wavelengths_nm, flat));
  std::array<double, 3> out;
  for (int c = 0; c < 3; ++c) out[c] = rgb[c] / white[c];
  return out;
}

GonioTable ParseGonioTable(std::string_view text, const std::string& file) {
  detail::LineCursor lines(text, file);
  std::string_view line;
  std::vector<std::string_view> fields;
  if (!lines.Next(&line))
    detail::Fail(file, 1, "a header 'Incident_angle,Measure_angle,...'", "an empty file");
  // A UTF-8 byte order mark is tolerated on the header.
  if (line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
  detail::SplitCsvLine(line, &fields);
  if (fields.size() < 3 || !detail::EqualsIgnoreCase(fields[0], "Incident_angle") ||
      !detail::EqualsIgnoreCase(fields[1], "Measure_angle")) {
    lines.Fail("a header 'Incident_angle,Measure_angle,<band>nm,...'", detail::Printable(line));
  }
  GonioTable table;
  for (std::size_t i = 2; i < fields.size(); ++i) {
    table.wavelengths_nm.push_back(ParseBandHeader(fields[i], file));
    if (i > 2 && !(table.wavelengths_nm[i - 2] > table.wavelengths_nm[i - 3]))
      lines.Fail("band wavelengths in ascending order", detail::Printable(fields[i]));
  }
  const std::size_t bands = table.wavelengths_nm.size();
  std::set<std::pair<double, double>> seen;
  while (lines.Next(&line)) {
    if (detail::Trim(line).empty()) continue;
    detail::SplitCsvLine(line, &fields);
    if (fields.size() != bands + 2) {
      lines.Fail(std::to_string(bands + 2) + " comma-separated fields",
                 std::to_string(fields.size()) + " fields");
    }
    GonioRow row;
    row.line = lines.line_number();
    row.incidence_deg = detail::ParseFiniteDouble(fields[0], file, row.line, "Incident_angle");
    row.measurement_angle_deg =
        detail::ParseFiniteDouble(fields[1], file, row.line, "Measure_angle");
    if (row.incidence_deg < 0 || row.incidence_deg >= 90)
      lines.Fail("Incident_angle in [0, 90)", detail::Printable(fields[0]));
    if (row.measurement_angle_deg < -90 || row.measurement_angle_deg > 90)
      lines.Fail("Measure_angle in [-90, 90]", detail::Printable(fields[1]));
    if (!seen.emplace(row.incidence_deg, row.measurement_angle_deg).second)
      lines.Fail(
          "one row per (Incident_angle, Measure_angle)",
          "a repeated pair " + detail::Printable(fields[0]) + ", " + detail::Printable(fields[1]));
    row.reflectance_factor.reserve(bands);
    for (std::size_t b = 0; b < bands; ++b) {
      const double v =
          detail::ParseFiniteDouble(fields[b + 2], file, row.line, "reflectance factor");
      if (v < 0) lines.Fail("a non-negative reflectance factor", detail::Printable(fields[b + 2]));
      row.reflectance_factor.push_back(v);
    }
    table.rows.push_back(std::move(row));
  }
  if (table.rows.empty())
    detail::Fail(file, lines.line_number() + 1, "at least one data row", "end of file");
  return table;
}

GonioTable ReadGonioTable(const std::string& path) {
  return ParseGonioTable(detail::ReadTextFile(path, detail::kMaxGonioBytes), path);
}

Measurement GonioToMeasurement(const GonioTable& table, const std::string& file) {
  Measurement m;
  m.metadata.sample_name = file;
  m.metadata.extra["source_file"] = file;
  m.metadata.extra["source_format"] = "gonio";
  std::string bands;
  for (double nm : table.wavelengths_nm)
    bands += (bands.empty() ? "" : ",") + detail::FormatShortest(nm);
  m.metadata.extra["gonio_wavelengths_nm"] = bands;
  m.metadata.extra["conversion"] =
      "f_r = reflectance factor / pi; spectrum -> XYZ (CIE 1931 2deg, D65) -> linear Rec.709, "
      "white-balanced; measurement angle a -> theta_out = |a|, phi_out = 180 if a > 0 else 0";
  std::map<double, std::size_t> slice_of;
  for (const GonioRow& row : table.rows) slice_of.emplace(row.incidence_deg, 0);
  for (auto& [theta_in, index] : slice_of) {
    index = m.slices.size();
    Slice s;
    s.theta_in_deg = theta_in;
    m.slices.push_back(std::move(s));
  }
  const std::vector<double> flat(table.wavelengths_nm.size(), 1.0);
  const std::array<double, 3> white =
      XyzToLinearRec709(ReflectanceToXyz(table.wavelengths_nm, flat));
  std::vector<double> fr(table.wavelengths_nm.size());
  for (const GonioRow& row : table.rows) {
    Sample smp;
    smp.theta_in_deg = static_cast<float>(row.incidence_deg);
    smp.phi_in_deg = 0;
    smp.theta_out_deg = static_cast<float>(std::fabs(row.measurement_angle_deg));
    smp.phi_out_deg = row.measurement_angle_deg > 0 ? 180.0f : 0.0f;
    bool all_zero = true;
    for (std::size_t b = 0; b < fr.size(); ++b) {
      fr[b] = row.reflectance_factor[b] * kInvPi;
      all_zero = all_zero && row.reflectance_factor[b] == 0;
    }
    const std::array<double, 3> rgb = XyzToLinearRec709(ReflectanceToXyz(table.wavelengths_nm, fr));
    for (int c = 0; c < 3; ++c) smp.rgb[c] = static_cast<float>(rgb[c] / white[c]);
    if (all_zero) smp.flags |= kFlagInvalid;
    m.slices[slice_of[row.incidence_deg]].samples.push_back(smp);
  }
  return m;
}

Measurement LoadGonioTable(const std::string& path) {
  return GonioToMeasurement(ReadGonioTable(path), path);
}

}  // namespace brdf
