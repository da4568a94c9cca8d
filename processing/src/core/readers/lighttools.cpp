#include "brdf/core/lighttools.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/gonio.h"
#include "readers/text_util.h"

namespace brdf {
namespace {

constexpr std::size_t kMaxAngles = 100000;
constexpr double kMaxDouble = std::numeric_limits<double>::max();

void ReadAngleList(detail::TokenStream& ts, std::string_view name, double min, double max,
                   std::vector<double>* out) {
  const std::size_t n = ts.NextCount(std::string(name) + " count", 1, kMaxAngles, 2);
  out->clear();
  out->reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = ts.NextInRange(std::string(name) + " angle (degrees)", min, max);
    if (!out->empty() && !(v > out->back()))
      ts.Fail(std::string(name) + " angles in strictly ascending order",
              detail::FormatShortest(v) + " after " + detail::FormatShortest(out->back()));
    out->push_back(v);
  }
}

// Channel index of a TristimulusValue token for the file's spectral content, or -1.
int ChannelOf(std::string_view v, LightToolsSpectral spectral) {
  using detail::EqualsIgnoreCase;
  switch (spectral) {
    case LightToolsSpectral::kMonochrome:
      return 0;
    case LightToolsSpectral::kXyz:
      if (EqualsIgnoreCase(v, "TrisX")) return 0;
      if (EqualsIgnoreCase(v, "TrisY")) return 1;
      if (EqualsIgnoreCase(v, "TrisZ")) return 2;
      return -1;
    case LightToolsSpectral::kRgb:
      if (EqualsIgnoreCase(v, "R") || EqualsIgnoreCase(v, "Red")) return 0;
      if (EqualsIgnoreCase(v, "G") || EqualsIgnoreCase(v, "Green")) return 1;
      if (EqualsIgnoreCase(v, "B") || EqualsIgnoreCase(v, "Blue")) return 2;
      return -1;
  }
  return -1;
}

std::size_t ChannelCount(LightToolsSpectral s) {
  return s == LightToolsSpectral::kMonochrome ? 1 : 3;
}

const char* ChannelName(LightToolsSpectral s, int channel) {
  static const char* kXyz[] = {"TrisX", "TrisY", "TrisZ"};
  static const char* kRgb[] = {"R", "G", "B"};
  return s == LightToolsSpectral::kXyz ? kXyz[channel] : kRgb[channel];
}

}  // namespace

LightToolsBsdf ParseLightToolsBsdf(std::string_view text_in, const std::string& file) {
  detail::TokenStream ts(text_in, file);
  LightToolsBsdf lt;
  bool have_symmetry = false, have_spectral = false, have_azimuth = false, have_radial = false;
  const auto once = [&](bool* seen, const detail::TokenStream::Token& t) {
    if (*seen) ts.FailAt(t.line, "each keyword once", "a second " + detail::Printable(t.text));
    *seen = true;
  };
  while (true) {
    const auto t = ts.Next("a header keyword or DataBegin");
    const std::string_view k = t.text;
    if (detail::EqualsIgnoreCase(k, "DataBegin")) break;
    if (detail::EqualsIgnoreCase(k, "Symmetry")) {
      once(&have_symmetry, t);
      const auto v = ts.Next("PlaneSymmetrical or Asymmetrical");
      if (detail::EqualsIgnoreCase(v.text, "PlaneSymmetrical")) {
        lt.plane_symmetric = true;
      } else if (detail::EqualsIgnoreCase(v.text, "Asymmetrical") ||
                 detail::EqualsIgnoreCase(v.text, "Asymmetric")) {
        lt.plane_symmetric = false;
      } else {
        ts.Fail("Symmetry PlaneSymmetrical or Asymmetrical", detail::Printable(v.text));
      }
    } else if (detail::EqualsIgnoreCase(k, "SpectralContent")) {
      once(&have_spectral, t);
      const auto v = ts.Next("Monochrome, XYZ or RGB");
      if (detail::EqualsIgnoreCase(v.text, "Monochrome")) {
        lt.spectral = LightToolsSpectral::kMonochrome;
      } else if (detail::EqualsIgnoreCase(v.text, "XYZ")) {
        lt.spectral = LightToolsSpectral::kXyz;
      } else if (detail::EqualsIgnoreCase(v.text, "RGB")) {
        lt.spectral = LightToolsSpectral::kRgb;
      } else {
        ts.Fail("SpectralContent Monochrome, XYZ or RGB", detail::Printable(v.text));
      }
    } else if (detail::EqualsIgnoreCase(k, "ScatterAzimuth")) {
      once(&have_azimuth, t);
      ReadAngleList(ts, "ScatterAzimuth", 0.0, 360.0, &lt.scatter_azimuth_deg);
    } else if (detail::EqualsIgnoreCase(k, "ScatterRadial")) {
      once(&have_radial, t);
      ReadAngleList(ts, "ScatterRadial", 0.0, 90.0, &lt.scatter_radial_deg);
    } else {
      ts.FailAt(t.line,
                "a header keyword (Symmetry, SpectralContent, ScatterAzimuth, ScatterRadial) "
                "or DataBegin",
                detail::Printable(k));
    }
  }
  const std::uint64_t begin_line = ts.line();
  if (!have_azimuth) ts.FailAt(begin_line, "a ScatterAzimuth line before DataBegin", "DataBegin");
  if (!have_radial) ts.FailAt(begin_line, "a ScatterRadial line before DataBegin", "DataBegin");
  if (!have_spectral) ts.FailAt(begin_line, "a SpectralContent line before DataBegin", "DataBegin");
  // A file may end its data at once (DataBegin DataEnd), so the grid's size is checked
  // against the rest of the file only where a block asks for its values, below; both counts
  // are at most 100,000, so their product fits.
  const std::size_t per_block = lt.scatter_azimuth_deg.size() * lt.scatter_radial_deg.size();

  while (true) {
    const auto first = ts.Next("a block keyword (AOI, ...) or DataEnd");
    if (detail::EqualsIgnoreCase(first.text, "DataEnd")) break;
    LightToolsBlock block;
    block.line = first.line;
    bool aoi = false, poi = false, side = false, wavelength = false, type = false, tris = false,
         tis = false;
    for (auto t = first;; t = ts.Next("a block keyword (AOI, POI, Side, Wavelength, "
                                      "ScatterType, TristimulusValue, TIS)")) {
      const std::string_view k = t.text;
      if (detail::EqualsIgnoreCase(k, "AOI")) {
        once(&aoi, t);
        block.aoi_deg = ts.NextInRange("AOI (degrees)", 0.0, 90.0, true);
      } else if (detail::EqualsIgnoreCase(k, "POI")) {
        once(&poi, t);
        block.poi_deg = ts.NextInRange("POI (degrees)", -360.0, 360.0);
      } else if (detail::EqualsIgnoreCase(k, "Side")) {
        once(&side, t);
        const auto v = ts.Next("Front or Back");
        if (detail::EqualsIgnoreCase(v.text, "Front")) {
          block.back_side = false;
        } else if (detail::EqualsIgnoreCase(v.text, "Back")) {
          block.back_side = true;
        } else {
          ts.Fail("Side Front or Back", detail::Printable(v.text));
        }
      } else if (detail::EqualsIgnoreCase(k, "Wavelength")) {
        once(&wavelength, t);
        block.wavelength = ts.NextInRange("Wavelength", 0.0, kMaxDouble);
      } else if (detail::EqualsIgnoreCase(k, "ScatterType")) {
        once(&type, t);
        const auto v = ts.Next("BRDF or BTDF");
        if (detail::EqualsIgnoreCase(v.text, "BRDF")) {
          block.btdf = false;
        } else if (detail::EqualsIgnoreCase(v.text, "BTDF")) {
          block.btdf = true;
        } else {
          ts.Fail("ScatterType BRDF or BTDF", detail::Printable(v.text));
        }
      } else if (detail::EqualsIgnoreCase(k, "TristimulusValue")) {
        once(&tris, t);
        const auto v = ts.Next("a TristimulusValue channel");
        const int c = ChannelOf(v.text, lt.spectral);
        if (c < 0)
          ts.Fail(lt.spectral == LightToolsSpectral::kXyz
                      ? "TristimulusValue TrisX, TrisY or TrisZ (SpectralContent XYZ)"
                      : "TristimulusValue R, G or B (SpectralContent RGB)",
                  detail::Printable(v.text));
        block.channel = c;
      } else if (detail::EqualsIgnoreCase(k, "TIS")) {
        once(&tis, t);
        block.tis = ts.NextInRange("TIS value", 0.0, kMaxDouble);
        break;
      } else {
        ts.FailAt(t.line,
                  "a block keyword (AOI, POI, Side, Wavelength, ScatterType, TristimulusValue, "
                  "TIS)",
                  detail::Printable(k));
      }
    }
    if (!aoi) ts.FailAt(block.line, "an AOI line in the block", "a block without AOI");
    if (!tris && lt.spectral != LightToolsSpectral::kMonochrome)
      ts.FailAt(block.line, "a TristimulusValue line in every block of a 3-channel file",
                "a block without one");
    if (per_block > ts.remaining_bytes() / 2 + 1)
      ts.Fail(std::to_string(per_block) + " values after TIS", "a file too short to hold them");
    block.values.reserve(per_block);
    for (std::size_t i = 0; i < per_block; ++i) {
      const auto t = ts.Next("a BSDF value");
      const double v = detail::ParseFiniteDouble(t.text, file, t.line, "a BSDF value");
      if (v < 0) ts.Fail("a non-negative BSDF value", detail::Printable(t.text));
      block.values.push_back(v);
    }
    lt.blocks.push_back(std::move(block));
  }
  if (!ts.AtEnd()) {
    const auto t = ts.Peek();
    ts.FailAt(t.line, "end of file after DataEnd", detail::Printable(t.text));
  }
  lt.comments = ts.comments();
  return lt;
}

LightToolsBsdf ReadLightToolsBsdf(const std::string& path) {
  return ParseLightToolsBsdf(detail::ReadTextFile(path, detail::kMaxLightToolsBytes), path);
}

std::string FormatLightToolsBsdf(const LightToolsBsdf& lt) {
  const std::size_t n_az = lt.scatter_azimuth_deg.size(), n_rad = lt.scatter_radial_deg.size();
  if (n_az == 0 || n_rad == 0)
    throw InvalidArgument("LightTools BSDF: ScatterAzimuth and ScatterRadial must not be empty");
  std::string out;
  char buf[64];
  for (const std::string& c : lt.comments) out += "#" + c + "\n";
  out +=
      std::string("Symmetry ") + (lt.plane_symmetric ? "PlaneSymmetrical" : "Asymmetrical") + "\n";
  out += std::string("SpectralContent ") +
         (lt.spectral == LightToolsSpectral::kXyz   ? "XYZ"
          : lt.spectral == LightToolsSpectral::kRgb ? "RGB"
                                                    : "Monochrome") +
         "\n";
  const auto list = [&](const char* name, const std::vector<double>& v) {
    out += std::string(name) + " " + std::to_string(v.size());
    for (double a : v) out += " " + detail::FormatShortest(a);
    out += "\n";
  };
  list("ScatterAzimuth", lt.scatter_azimuth_deg);
  list("ScatterRadial", lt.scatter_radial_deg);
  out += "DataBegin\n";
  for (const LightToolsBlock& b : lt.blocks) {
    if (b.values.size() != n_az * n_rad)
      throw InvalidArgument("LightTools BSDF: a block holds " + std::to_string(b.values.size()) +
                            " values, expected " + std::to_string(n_az * n_rad));
    out += "AOI " + detail::FormatShortest(b.aoi_deg) + "\n";
    out += "POI " + detail::FormatShortest(b.poi_deg) + "\n";
    out += std::string("Side ") + (b.back_side ? "Back" : "Front") + "\n";
    out += "Wavelength " + detail::FormatShortest(b.wavelength) + "\n";
    out += std::string("ScatterType ") + (b.btdf ? "BTDF" : "BRDF") + "\n";
    if (lt.spectral != LightToolsSpectral::kMonochrome) {
      if (b.channel < 0 || b.channel > 2)
        throw InvalidArgument("LightTools BSDF: channel " + std::to_string(b.channel));
      out += std::string("TristimulusValue ") + ChannelName(lt.spectral, b.channel) + "\n";
    }
    std::snprintf(buf, sizeof buf, "TIS %.9g\n", b.tis);
    out += buf;
    for (std::size_t a = 0; a < n_az; ++a) {
      for (std::size_t r = 0; r < n_rad; ++r) {
        std::snprintf(buf, sizeof buf, "%.9g%c", b.values[a * n_rad + r],
                      r + 1 == n_rad ? '\n' : '\t');
        out += buf;
      }
    }
  }
  out += "DataEnd\n";
  return out;
}

void WriteLightToolsBsdf(const std::string& path, const LightToolsBsdf& bsdf) {
  WriteFileAtomically(path, FormatLightToolsBsdf(bsdf));
}

Measurement LightToolsToMeasurement(const LightToolsBsdf& lt, const std::string& file,
                                    const LightToolsImportOptions& options) {
  std::size_t brdf_front = 0, btdf_front = 0, back = 0;
  for (const LightToolsBlock& b : lt.blocks) {
    if (b.back_side) {
      ++back;
    } else if (b.btdf) {
      ++btdf_front;
    } else {
      ++brdf_front;
    }
  }
  const bool use_btdf = brdf_front == 0 && btdf_front > 0 && options.allow_btdf;
  if (brdf_front == 0 && !use_btdf) {
    throw FormatError(file, LinePosition(lt.blocks.empty() ? 1 : lt.blocks.front().line),
                      "a front-side BRDF block",
                      lt.blocks.empty() ? std::string("no blocks between DataBegin and DataEnd")
                                        : std::to_string(btdf_front) + " front-side BTDF and " +
                                              std::to_string(back) + " back-side blocks",
                      btdf_front > 0 ? "transmission data, stored mirrored into the reflection "
                                       "hemisphere only on request"
                                     : "",
                      btdf_front > 0 ? Remedy{RemedyKind::kAllowBtdf, file} : Remedy{});
  }
  const std::size_t channels = ChannelCount(lt.spectral);
  // (AOI, POI) → the block of each channel.
  std::map<std::pair<double, double>, std::array<const LightToolsBlock*, 3>> groups;
  std::set<double> pois;
  for (const LightToolsBlock& b : lt.blocks) {
    if (b.back_side || b.btdf != use_btdf) continue;
    auto& g = groups[{b.aoi_deg, b.poi_deg}];
    if (g[b.channel] != nullptr) {
      throw FormatError(file, LinePosition(b.line),
                        "one block per channel for AOI " + detail::FormatShortest(b.aoi_deg) +
                            ", POI " + detail::FormatShortest(b.poi_deg),
                        "a second block for channel " + std::to_string(b.channel) +
                            " (first at line " + std::to_string(g[b.channel]->line) + ")");
    }
    g[b.channel] = &b;
    pois.insert(b.poi_deg);
  }
  const bool isotropic = pois.size() == 1;
  Measurement m;
  m.metadata.sample_name = file;
  m.metadata.extra["source_file"] = file;
  m.metadata.extra["source_format"] = "lighttools";
  m.metadata.extra["scatter_type"] =
      use_btdf ? "BTDF (mirrored into the reflection hemisphere)" : "BRDF";
  m.metadata.extra["spectral_content"] = lt.spectral == LightToolsSpectral::kXyz
                                             ? "XYZ (converted to linear Rec.709)"
                                         : lt.spectral == LightToolsSpectral::kRgb ? "RGB"
                                                                                   : "Monochrome";
  m.metadata.extra["lighttools_skipped"] = std::to_string(back) + " back-side blocks, " +
                                           std::to_string(use_btdf ? brdf_front : btdf_front) +
                                           " front-side " + (use_btdf ? "BRDF" : "BTDF") +
                                           " blocks";
  std::string notes;
  for (const std::string& c : lt.comments) notes += (notes.empty() ? "" : "\n") + c;
  m.metadata.operator_notes = notes;

  const auto& az = lt.scatter_azimuth_deg;
  const auto& rad = lt.scatter_radial_deg;
  const std::size_t n_az = az.size(), n_rad = rad.size();
  const bool wraps = n_az > 1 && az.back() == az.front() + 360.0;
  for (const auto& [key, g] : groups) {
    const auto [aoi, poi] = key;
    for (std::size_t c = 0; c < channels; ++c) {
      if (g[c] == nullptr) {
        const LightToolsBlock* any = g[0] ? g[0] : g[1] ? g[1] : g[2];
        throw FormatError(file, LinePosition(any->line),
                          std::string("a ") + ChannelName(lt.spectral, static_cast<int>(c)) +
                              " block for AOI " + detail::FormatShortest(aoi) + ", POI " +
                              detail::FormatShortest(poi),
                          "none");
      }
    }
    Slice s;
    s.theta_in_deg = aoi;
    s.phi_in_deg = isotropic ? 0.0 : poi;
    s.samples.reserve(2 * n_az * n_rad);
    for (std::size_t a = 0; a < n_az; ++a) {
      if (wraps && a + 1 == n_az) continue;  // 360° repeats 0°
      // Azimuth relative to the plane of incidence.
      const double rel = WrapDeg360(az[a] - poi);
      const bool mirror = lt.plane_symmetric && rel != 0.0 && rel != 180.0;
      for (std::size_t r = 0; r < n_rad; ++r) {
        if (rad[r] == 0.0 && a > 0) continue;  // the normal direction, once
        std::array<double, 3> v{};
        for (std::size_t c = 0; c < channels; ++c) v[c] = g[c]->values[a * n_rad + r];
        if (lt.spectral == LightToolsSpectral::kXyz) v = XyzToLinearRec709(v);
        if (!(detail::FitsFloat(v[0]) && detail::FitsFloat(v[1]) && detail::FitsFloat(v[2])))
          throw FormatError(file, "data block at AOI " + detail::FormatShortest(aoi),
                            "tristimulus values whose linear RGB stays within float32 range",
                            "values beyond it");
        if (lt.spectral == LightToolsSpectral::kMonochrome) v = {v[0], v[0], v[0]};
        for (int side = 0; side < (mirror && rad[r] != 0.0 ? 2 : 1); ++side) {
          const double rel_side = side == 0 ? rel : 360.0 - rel;
          double phi = isotropic ? rel_side : WrapDeg360(poi + rel_side);
          if (rad[r] == 0.0) phi = 0.0;
          Sample smp;
          smp.theta_in_deg = static_cast<float>(aoi);
          smp.phi_in_deg = static_cast<float>(s.phi_in_deg);
          smp.theta_out_deg = static_cast<float>(rad[r]);
          smp.phi_out_deg = static_cast<float>(WrapDeg360(phi));
          if (smp.phi_out_deg >= 360.0f) smp.phi_out_deg = 0.0f;
          for (int c = 0; c < 3; ++c) smp.rgb[c] = static_cast<float>(v[c]);
          s.samples.push_back(smp);
        }
      }
    }
    m.slices.push_back(std::move(s));
  }
  return m;
}

Measurement LoadLightToolsBsdf(const std::string& path, const LightToolsImportOptions& options) {
  return LightToolsToMeasurement(ReadLightToolsBsdf(path), path, options);
}

}  // namespace brdf
