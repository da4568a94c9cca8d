// In-plane spectral goniometer tables, and the colour conversions every spectral or
// tristimulus importer shares.
//
// The table (e.g. ../shared/brdf-data/goniometer-csv/test_brdf_viewer_2D_data.csv) is a CSV
// with the header `Incident_angle,Measure_angle,<λ1>nm,...,<λn>nm` and one row per
// (incidence, measurement angle). Values are a reflectance factor R = π·f_r (a perfect white
// diffuser reads 1), so f_r = R/π in 1/sr (docs/design.md §4).
//
// Geometry: the goniometer moves its detector in the plane of incidence. The incidence angle
// is θin (light at φin = 0, docs/design.md §4). The measurement angle a is the detector's polar
// angle with a sign telling the side of the normal: a > 0 is the specular side (the
// reflected beam leaves at a = +θin, and the real file's peaks sit exactly there), a < 0 is
// the side of the light source. So θout = |a|, φout = 180° for a > 0 and 0° for a ≤ 0.
// Rows whose every band is exactly 0 are the detector positions shadowed by the source arm
// (they cluster around a = −θin in the real file): they are kept with kFlagInvalid.
//
// Spectral to RGB: XYZ = Σ R(λ)/π · x̄,ȳ,z̄(λ) · D65(λ) / Σ ȳ(λ) D65(λ) over the table's
// bands (CIE 1931 2° observer and CIE D65, CIE 015:2018 tables at 10 nm), then XYZ → linear
// Rec.709 with the IEC 61966-2-1 matrix, then a diagonal white balance so that a spectrally
// flat reflector maps to exactly neutral RGB despite the table's truncated band range (the
// correction is below 1% for 390–730 nm). Band centres must lie on the 10 nm CIE grid
// between 380 and 780 nm.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/measurement.h"

namespace brdf {

struct GonioRow {
  double incidence_deg = 0;                // θin
  double measurement_angle_deg = 0;        // signed detector angle, see above
  std::vector<double> reflectance_factor;  // one per band, as in the file (π·f_r)
  std::uint64_t line = 0;                  // 1-based line in the file
};

struct GonioTable {
  std::vector<double> wavelengths_nm;  // band centres, ascending
  std::vector<GonioRow> rows;          // file order
};

// Parses the table text. `file` names the source in error messages. Throws FormatError naming
// the file and line: wrong header, a band that is not "<number>nm" on the CIE 10 nm grid,
// a row with the wrong number of fields, a non-finite or negative value, an angle outside
// [0°, 90°) (incidence) or [−90°, 90°] (measurement), duplicate rows.
GonioTable ParseGonioTable(std::string_view text, const std::string& file);
// Reads a file of at most 32 MiB (larger ones are refused before reading).
GonioTable ReadGonioTable(const std::string& path);

// One slice per incidence (ascending θin), samples in file order with f_r in linear Rec.709
// RGB. Metadata: source file, "gonio_wavelengths_nm", the conversions used.
Measurement GonioToMeasurement(const GonioTable& table, const std::string& file);
Measurement LoadGonioTable(const std::string& path);

// CIE 1931 2° colour matching functions x̄, ȳ, z̄ at `wavelength_nm` (a multiple of 10 nm in
// [380, 780]); throws InvalidArgument otherwise.
std::array<double, 3> Cie1931Cmf(double wavelength_nm);
// CIE standard illuminant D65 relative spectral power (100 at 560 nm) at the same grid.
double CieD65(double wavelength_nm);

// XYZ (Y = 1 for the perfect white diffuser under D65) of a reflectance spectrum sampled at
// `wavelengths_nm`, with the D65-weighted sums above.
std::array<double, 3> ReflectanceToXyz(const std::vector<double>& wavelengths_nm,
                                       const std::vector<double>& reflectance);

// Linear Rec.709/sRGB primaries, D65 white, from XYZ (IEC 61966-2-1 matrix).
std::array<double, 3> XyzToLinearRec709(const std::array<double, 3>& xyz);

// Spectrum → linear Rec.709 RGB with the white balance described above: a flat spectrum of
// value v gives exactly (v, v, v).
std::array<double, 3> ReflectanceToLinearRec709(const std::vector<double>& wavelengths_nm,
                                                const std::vector<double>& reflectance);

}  // namespace brdf
