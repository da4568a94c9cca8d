// Zemax "BSDF data interchange" ASCII files (the Radiant Imaging / Zemax tabular BSDF format).
//
// Layout read here: '#' comment lines; header keyword lines `Source <text>`,
// `Symmetry PlaneSymmetrical|Asymmetrical|ASymmetrical4D`, `SpectralContent Monochrome|XYZ`,
// `ScatterType BRDF|BTDF`; count-then-list blocks `SampleRotation`, `AngleOfIncidence`,
// `ScatterAzimuth`, `ScatterRadial` (degrees, strictly ascending); then one data section per
// channel: a channel keyword (`Monochrome`, or `TristimulusX`, `TristimulusY`,
// `TristimulusZ` for XYZ files), `DataBegin`, for every rotation and every incidence an
// optional `TIS <value>` line followed by NAzimuth rows of NRadial BSDF values (1/sr), and
// `DataEnd`. Keywords are matched case-insensitively. docs/formats/zemax.md has the details.
//
// Scatter coordinates (our reading, documented in docs/formats/zemax.md): the table is
// centred on the specular direction r = (θs, φ = 180°) of the light at (θs, φin = 0), where
// θs is the file's AngleOfIncidence (which Zemax defines as the specular angle). A value at
// (azimuth α, radial ρ) belongs to the direction obtained by turning r by the angle ρ along
// the great circle that leaves r in the tangent direction cosα·e0 + sinα·e1, where e0 points
// from r towards the surface normal and e1 = r × e0 = +y (so α grows counter-clockwise seen
// from outside, looking back at the sample along −r):
//   ω = cosρ·r + sinρ·(cosα·e0 + sinα·e1),  e0 = (cosθs, 0, sinθs).
// At θs = 0 the limit e0 = +x is used. The file's zeros sit past the instrument's horizon
// (about 84–85° in the shared file, exactly where this reading puts them), which is the
// evidence for reading ρ as a true angle on the sphere rather than a projected distance.
// PlaneSymmetrical files store α in [0°, 180°]; the mirror half is α → −α.
//
// BTDF files: ScatterType BTDF data is transmission, centred on the direct transmission
// direction below the surface. It is read and can be integrated (IntegrateZemaxTis) like a
// BRDF, but converting it into a Measurement (a reflection capture) is refused unless
// ZemaxImportOptions::allow_btdf is set; then every direction is mirrored through the surface
// plane (z → −z), which puts the transmission lobe's centre on the specular direction, and
// the metadata records "scatter_type" = "BTDF (mirrored into the reflection hemisphere)".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/core/measurement.h"

namespace brdf {

struct ZemaxBsdf {
  std::string source;  // the `Source` line ("Measured")
  bool plane_symmetric = true;
  bool xyz = false;   // SpectralContent XYZ (three channels X, Y, Z) instead of Monochrome
  bool btdf = false;  // ScatterType BTDF (transmission)
  std::uint64_t scatter_type_line = 0;  // for messages about the scatter type
  std::vector<double> sample_rotation_deg;
  std::vector<double> angle_of_incidence_deg;
  std::vector<double> scatter_azimuth_deg;
  std::vector<double> scatter_radial_deg;
  // values[channel][((rotation · NAoi + aoi) · NAzimuth + azimuth) · NRadial + radial], 1/sr.
  std::vector<std::vector<double>> values;
  // tis[channel][rotation · NAoi + aoi]; NaN where the file has no TIS line.
  std::vector<std::vector<double>> tis;
  std::vector<std::string> comments;  // '#' lines without the '#'

  std::size_t channels() const { return xyz ? 3 : 1; }
  double Value(std::size_t channel, std::size_t rotation, std::size_t aoi, std::size_t azimuth,
               std::size_t radial) const {
    return values[channel]
                 [((rotation * angle_of_incidence_deg.size() + aoi) * scatter_azimuth_deg.size() +
                   azimuth) *
                      scatter_radial_deg.size() +
                  radial];
  }
};

// Parses the text of a Zemax BSDF file; `file` names it in error messages. Throws FormatError
// naming the file and line for anything outside the layout above: unknown or repeated
// keywords, counts that the rest of the file cannot hold, angles out of range or not
// ascending (AngleOfIncidence in [0, 90), ScatterAzimuth in [0, 360] — [0, 180] for
// PlaneSymmetrical — and ScatterRadial in [0, 180]), NaN/inf or negative values, truncation.
ZemaxBsdf ParseZemaxBsdf(std::string_view text, const std::string& file);
// Reads a file of at most 64 MiB (larger ones are refused before reading).
ZemaxBsdf ReadZemaxBsdf(const std::string& path);

// The file-format text of `bsdf` (writes TIS lines only where they are not NaN). Used by the
// tests and the fuzzing corpus; values are written with 7 significant digits.
std::string FormatZemaxBsdf(const ZemaxBsdf& bsdf);

// The direction (our frame, unit vector) of the table entry at (azimuth, radial) around the
// specular direction of incidence θs, per the reading above. z < 0 means past the horizon.
Vec3 ZemaxScatterDirection(double specular_theta_deg, double azimuth_deg, double radial_deg);

// Integrated scatter per (rotation, incidence): ∫ f(ω) cosθ dω over the hemisphere.
struct ZemaxTis {
  double sample_rotation_deg = 0;
  double angle_of_incidence_deg = 0;
  double file_tis = 0;  // the file's TIS line (NaN if absent)
  // Over the directions the table covers (ρ ≤ the last radial angle, bilinear in (α, ρ),
  // zeros kept): a lower bound of what the data implies.
  double covered_tis = 0;
  // Over the whole hemisphere: the table's zeros past the instrument's horizon replaced by
  // the last non-zero value along the same azimuth, and directions beyond the last radial
  // angle given the value at the last radial angle (edge extension). The estimate compared
  // with the file's TIS.
  double filled_tis = 0;
};

// Midpoint quadrature on a 0.5° (θ) × 1° (φ) grid over the hemisphere, f looked up at each
// grid direction's (α, ρ) by bilinear interpolation in the table. `channel` selects Monochrome
// (0) or X/Y/Z (0/1/2). For BTDF files the transmission hemisphere is integrated the same way.
std::vector<ZemaxTis> IntegrateZemaxTis(const ZemaxBsdf& bsdf, std::size_t channel = 0);

struct ZemaxImportOptions {
  // Accept ScatterType BTDF, mirrored into the reflection hemisphere (see above).
  bool allow_btdf = false;
};

// One slice per (rotation, incidence), θin = AngleOfIncidence. A single-rotation file is
// stored isotropically with φin = 0; with several rotations, slice φin = SampleRotation and
// every direction is turned by the same angle about the normal. Samples: one per table entry
// whose direction is above the surface (ρ = 0 once, mirror halves of PlaneSymmetrical files
// added), f_r = the table value (Monochrome → grey RGB; XYZ → linear Rec.709 with the
// IEC 61966-2-1 matrix). Entries that are 0 in every channel are kept with kFlagInvalid: the
// format uses 0 for "not measured" (past the horizon). Throws FormatError for a BTDF file
// unless options.allow_btdf.
Measurement ZemaxToMeasurement(const ZemaxBsdf& bsdf, const std::string& file,
                               const ZemaxImportOptions& options = {});
Measurement LoadZemaxBsdf(const std::string& path, const ZemaxImportOptions& options = {});

}  // namespace brdf
