// LightTools BSDF ASCII files, in the layout the MiniDiff software exports.
//
// No public sample of a MiniDiff export exists; the layout supported here is documented in
// docs/formats/lighttools.md and summarised below. Tests write files with WriteLightToolsBsdf
// (and by hand) from analytic materials.
//
//   # comment lines
//   Symmetry PlaneSymmetrical | Asymmetrical        (Asymmetric is accepted too)
//   SpectralContent Monochrome | XYZ | RGB
//   ScatterAzimuth <n> a1 … an                      (degrees, ascending, in [0, 360])
//   ScatterRadial <m> r1 … rm                       (degrees, ascending, in [0, 90])
//   DataBegin
//   AOI <deg>  POI <deg>  Side Front|Back  Wavelength <value>  ScatterType BRDF|BTDF
//   TristimulusValue <channel>  TIS <value>
//   <n × m values: for each azimuth, the m radial values (one azimuth per line)>
//   … more blocks …
//   DataEnd
//
// In a block the keywords may come in any order and all but AOI and TIS are optional
// (POI 0, Side Front, ScatterType BRDF, Wavelength 0); TIS closes the keyword part and is
// followed by the values. A Monochrome file has one block per (side, scatter type, AOI, POI);
// an XYZ file three, with TristimulusValue TrisX, TrisY and TrisZ; an RGB file (the MiniDiff
// three-LED variant) three, with TristimulusValue R, G and B (linear Rec.709 f_r).
//
// Angles: ScatterRadial is the polar angle θ of the scattered direction from the surface
// normal and ScatterAzimuth its azimuth in the sample frame; POI is the azimuth of the plane
// of incidence (the light's azimuth). Values are BSDF in 1/sr (not multiplied by cosθ).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/measurement.h"

namespace brdf {

enum class LightToolsSpectral { kMonochrome, kXyz, kRgb };

struct LightToolsBlock {
  double aoi_deg = 0;      // θin
  double poi_deg = 0;      // azimuth of the plane of incidence, sample frame
  bool back_side = false;  // Side Back
  bool btdf = false;       // ScatterType BTDF
  double wavelength = 0;   // as written (0 if absent)
  int channel = 0;         // 0: Monochrome / TrisX / R, 1: TrisY / G, 2: TrisZ / B
  double tis = 0;
  std::vector<double> values;  // n_az × n_rad, azimuth-major, 1/sr
  std::uint64_t line = 0;      // line of the block's first keyword (messages only)
};

struct LightToolsBsdf {
  bool plane_symmetric = false;
  LightToolsSpectral spectral = LightToolsSpectral::kMonochrome;
  std::vector<double> scatter_azimuth_deg;
  std::vector<double> scatter_radial_deg;
  std::vector<LightToolsBlock> blocks;
  std::vector<std::string> comments;  // '#' lines without the '#'
};

// Parses the text; `file` names it in error messages. Throws FormatError naming the file and
// line: unknown keywords, counts the file cannot hold, angles out of range or not ascending,
// NaN/inf or negative values, a TristimulusValue that does not fit SpectralContent,
// truncation, text after DataEnd.
LightToolsBsdf ParseLightToolsBsdf(std::string_view text, const std::string& file);
// Reads a file of at most 128 MiB (larger ones are refused before reading).
LightToolsBsdf ReadLightToolsBsdf(const std::string& path);

// The file text (values with 9 significant digits: below float resolution) and an atomic
// writer (temporary sibling renamed into place). Throws InvalidArgument for an inconsistent
// struct (a block whose value count is not n_az × n_rad), IoError when writing fails.
std::string FormatLightToolsBsdf(const LightToolsBsdf& bsdf);
void WriteLightToolsBsdf(const std::string& path, const LightToolsBsdf& bsdf);

struct LightToolsImportOptions {
  // Import the front-side BTDF blocks (mirrored through the surface into the reflection
  // hemisphere) when the file has no front-side BRDF blocks.
  bool allow_btdf = false;
};

// Front-side BRDF blocks become one slice per (AOI, POI), ascending AOI. With a single POI in
// the file the data is stored isotropically: φin = 0 and φout = azimuth − POI (docs/design.md §4);
// with several, slice φin = POI and azimuths stay in the sample frame. PlaneSymmetrical files
// get the mirror half (φ → 2·POI − φ) added. θout = radial; the θ = 0 sample appears once.
// XYZ → linear Rec.709 (IEC 61966-2-1 matrix); Monochrome → grey. Back-side blocks are not
// part of a reflection capture and are skipped (counted in metadata "lighttools_skipped").
// Throws FormatError when a channel block is missing or repeated for an (AOI, POI), or when
// there is nothing to import (a BTDF-only file without options.allow_btdf).
Measurement LightToolsToMeasurement(const LightToolsBsdf& bsdf, const std::string& file,
                                    const LightToolsImportOptions& options = {});
Measurement LoadLightToolsBsdf(const std::string& path,
                               const LightToolsImportOptions& options = {});

}  // namespace brdf
