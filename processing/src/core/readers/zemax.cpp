#include "brdf/core/zemax.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "brdf/core/error.h"
#include "brdf/core/gonio.h"
#include "readers/text_util.h"

namespace brdf {
namespace {

// No real table has more than a few thousand angles per axis; this bound only keeps the
// product of four counts from overflowing before the remaining-bytes check.
constexpr std::size_t kMaxAngles = 100000;

void ReadAngleList(detail::TokenStream& ts, std::string_view name, double min, double max,
                   std::vector<double>* out, bool max_open = false) {
  const std::size_t n = ts.NextCount(std::string(name) + " count", 1, kMaxAngles, 2);
  out->clear();
  out->reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = ts.NextInRange(std::string(name) + " angle (degrees)", min, max, max_open);
    if (!out->empty() && !(v > out->back()))
      ts.Fail(std::string(name) + " angles in strictly ascending order",
              detail::FormatShortest(v) + " after " + detail::FormatShortest(out->back()));
    out->push_back(v);
  }
}

int ChannelOfIndicator(std::string_view token, bool xyz) {
  if (!xyz) return detail::EqualsIgnoreCase(token, "Monochrome") ? 0 : -1;
  if (detail::EqualsIgnoreCase(token, "TristimulusX")) return 0;
  if (detail::EqualsIgnoreCase(token, "TristimulusY")) return 1;
  if (detail::EqualsIgnoreCase(token, "TristimulusZ")) return 2;
  return -1;
}

bool IsChannelIndicator(std::string_view token) {
  return ChannelOfIndicator(token, false) >= 0 || ChannelOfIndicator(token, true) >= 0;
}

// Linear interpolation position along an ascending axis: f = (1 − t)·v[i0] + t·v[i1].
struct AxisPos {
  std::size_t i0 = 0, i1 = 0;
  double t = 0;
};

AxisPos ClampedPos(const std::vector<double>& axis, double x) {
  if (x <= axis.front()) return {0, 0, 0};
  if (x >= axis.back()) return {axis.size() - 1, axis.size() - 1, 0};
  const auto it = std::upper_bound(axis.begin(), axis.end(), x);
  const std::size_t i1 = static_cast<std::size_t>(it - axis.begin());
  const std::size_t i0 = i1 - 1;
  return {i0, i1, (x - axis[i0]) / (axis[i1] - axis[i0])};
}

// Azimuth position: plane-symmetric tables fold α into [0°, 180°] and clamp; full tables wrap
// between the last azimuth and the first one + 360°.
AxisPos AzimuthPos(const std::vector<double>& az, bool plane_symmetric, double alpha_deg) {
  alpha_deg = WrapDeg360(alpha_deg);
  if (plane_symmetric) return ClampedPos(az, alpha_deg > 180.0 ? 360.0 - alpha_deg : alpha_deg);
  if (az.size() == 1) return {0, 0, 0};
  if (alpha_deg < az.front()) alpha_deg += 360.0;
  if (alpha_deg >= az.back()) {
    const double span = az.front() + 360.0 - az.back();
    if (span <= 0) return {az.size() - 1, az.size() - 1, 0};
    return {az.size() - 1, 0, (alpha_deg - az.back()) / span};
  }
  return ClampedPos(az, alpha_deg);
}

Vec3 RotateAboutZ(const Vec3& v, double angle_deg) {
  const double a = DegToRad(angle_deg), c = std::cos(a), s = std::sin(a);
  return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}

}  // namespace

ZemaxBsdf ParseZemaxBsdf(std::string_view text_in, const std::string& file) {
  detail::TokenStream ts(text_in, file);
  ZemaxBsdf z;
  bool have_source = false, have_symmetry = false, have_spectral = false, have_type = false,
       have_rotation = false, have_aoi = false, have_azimuth = false, have_radial = false;
  std::uint64_t azimuth_line = 0;
  const auto once = [&](bool* seen, const detail::TokenStream::Token& t) {
    if (*seen)
      ts.FailAt(t.line, "each header keyword once", "a second " + detail::Printable(t.text));
    *seen = true;
  };
  while (true) {
    const detail::TokenStream::Token peek = ts.Peek();
    if (peek.text.empty())
      ts.FailAt(peek.line, "a data section (Monochrome or TristimulusX, then DataBegin)",
                "end of file");
    if (IsChannelIndicator(peek.text)) break;
    const detail::TokenStream::Token t = ts.Next("a header keyword");
    const std::string_view k = t.text;
    if (detail::EqualsIgnoreCase(k, "Source")) {
      once(&have_source, t);
      z.source = ts.RestOfLine("Source");
    } else if (detail::EqualsIgnoreCase(k, "Symmetry")) {
      once(&have_symmetry, t);
      const auto v = ts.Next("PlaneSymmetrical or Asymmetrical");
      if (detail::EqualsIgnoreCase(v.text, "PlaneSymmetrical")) {
        z.plane_symmetric = true;
      } else if (detail::EqualsIgnoreCase(v.text, "Asymmetrical") ||
                 detail::EqualsIgnoreCase(v.text, "Asymmetrical4D")) {
        z.plane_symmetric = false;
      } else {
        ts.Fail("Symmetry PlaneSymmetrical, Asymmetrical or ASymmetrical4D",
                detail::Printable(v.text));
      }
    } else if (detail::EqualsIgnoreCase(k, "SpectralContent")) {
      once(&have_spectral, t);
      const auto v = ts.Next("Monochrome or XYZ");
      if (detail::EqualsIgnoreCase(v.text, "Monochrome")) {
        z.xyz = false;
      } else if (detail::EqualsIgnoreCase(v.text, "XYZ")) {
        z.xyz = true;
      } else {
        ts.Fail("SpectralContent Monochrome or XYZ", detail::Printable(v.text));
      }
    } else if (detail::EqualsIgnoreCase(k, "ScatterType")) {
      once(&have_type, t);
      const auto v = ts.Next("BRDF or BTDF");
      z.scatter_type_line = v.line;
      if (detail::EqualsIgnoreCase(v.text, "BRDF")) {
        z.btdf = false;
      } else if (detail::EqualsIgnoreCase(v.text, "BTDF")) {
        z.btdf = true;
      } else {
        ts.Fail("ScatterType BRDF or BTDF", detail::Printable(v.text));
      }
    } else if (detail::EqualsIgnoreCase(k, "SampleRotation")) {
      once(&have_rotation, t);
      ReadAngleList(ts, "SampleRotation", -360.0, 360.0, &z.sample_rotation_deg);
    } else if (detail::EqualsIgnoreCase(k, "AngleOfIncidence")) {
      once(&have_aoi, t);
      ReadAngleList(ts, "AngleOfIncidence", 0.0, 90.0, &z.angle_of_incidence_deg, true);
    } else if (detail::EqualsIgnoreCase(k, "ScatterAzimuth")) {
      once(&have_azimuth, t);
      azimuth_line = t.line;
      ReadAngleList(ts, "ScatterAzimuth", 0.0, 360.0, &z.scatter_azimuth_deg);
    } else if (detail::EqualsIgnoreCase(k, "ScatterRadial")) {
      once(&have_radial, t);
      ReadAngleList(ts, "ScatterRadial", 0.0, 180.0, &z.scatter_radial_deg);
    } else if (detail::EqualsIgnoreCase(k, "DataBegin")) {
      ts.FailAt(t.line, "a channel keyword (Monochrome or TristimulusX) before DataBegin",
                "DataBegin");
    } else {
      ts.FailAt(t.line,
                "a header keyword (Source, Symmetry, SpectralContent, ScatterType, "
                "SampleRotation, AngleOfIncidence, ScatterAzimuth, ScatterRadial)",
                detail::Printable(k));
    }
  }
  const std::uint64_t data_line = ts.Peek().line;
  const auto require = [&](bool seen, std::string_view what) {
    if (!seen)
      ts.FailAt(data_line, std::string("a ") + std::string(what) + " line before the data",
                "the data section");
  };
  require(have_symmetry, "Symmetry");
  require(have_spectral, "SpectralContent");
  require(have_aoi, "AngleOfIncidence");
  require(have_azimuth, "ScatterAzimuth");
  require(have_radial, "ScatterRadial");
  if (!have_rotation) z.sample_rotation_deg = {0.0};
  if (z.plane_symmetric && z.scatter_azimuth_deg.back() > 180.0)
    ts.FailAt(azimuth_line, "ScatterAzimuth angles in [0, 180] for a PlaneSymmetrical file",
              detail::FormatShortest(z.scatter_azimuth_deg.back()));

  // Refuse a table the rest of the file cannot hold before allocating it (each value takes
  // at least two bytes: a digit and a separator).
  const std::size_t limit = ts.remaining_bytes() / 2 + 1;
  std::size_t per_channel = 1;
  for (std::size_t n : {z.sample_rotation_deg.size(), z.angle_of_incidence_deg.size(),
                        z.scatter_azimuth_deg.size(), z.scatter_radial_deg.size()}) {
    if (per_channel > limit / n)
      ts.FailAt(data_line,
                "a table the file can hold (at most " + std::to_string(limit) + " values)",
                "a declared table larger than that");
    per_channel *= n;
  }
  if (per_channel * z.channels() > limit)
    ts.FailAt(data_line, "a table the file can hold (at most " + std::to_string(limit) + " values)",
              std::to_string(per_channel * z.channels()) + " declared values");

  const std::size_t blocks = z.sample_rotation_deg.size() * z.angle_of_incidence_deg.size();
  const std::size_t per_block = z.scatter_azimuth_deg.size() * z.scatter_radial_deg.size();
  z.values.assign(z.channels(), {});
  z.tis.assign(z.channels(), {});
  std::vector<bool> seen_channel(z.channels(), false);
  for (std::size_t section = 0; section < z.channels(); ++section) {
    const auto ind = ts.Next(z.xyz ? "TristimulusX, TristimulusY or TristimulusZ" : "Monochrome");
    const int channel = ChannelOfIndicator(ind.text, z.xyz);
    if (channel < 0)
      ts.Fail(z.xyz ? "a channel keyword TristimulusX, TristimulusY or TristimulusZ"
                    : "the channel keyword Monochrome",
              detail::Printable(ind.text));
    if (seen_channel[channel])
      ts.Fail("each channel section once", "a second " + detail::Printable(ind.text));
    seen_channel[channel] = true;
    ts.Expect("DataBegin");
    std::vector<double>& vals = z.values[channel];
    std::vector<double>& tis = z.tis[channel];
    vals.reserve(blocks * per_block);
    tis.reserve(blocks);
    for (std::size_t b = 0; b < blocks; ++b) {
      if (detail::EqualsIgnoreCase(ts.Peek().text, "TIS")) {
        ts.Next("TIS");
        tis.push_back(ts.NextInRange("TIS value", 0.0, std::numeric_limits<double>::max()));
      } else {
        tis.push_back(std::numeric_limits<double>::quiet_NaN());
      }
      for (std::size_t i = 0; i < per_block; ++i) {
        const auto t = ts.Next("a BSDF value");
        const double v = detail::ParseFiniteDouble(t.text, file, t.line, "a BSDF value");
        if (v < 0) ts.Fail("a non-negative BSDF value", detail::Printable(t.text));
        vals.push_back(v);
      }
    }
    ts.Expect("DataEnd");
  }
  if (!ts.AtEnd()) {
    const auto t = ts.Peek();
    ts.FailAt(t.line, "end of file after DataEnd", detail::Printable(t.text));
  }
  z.comments = ts.comments();
  return z;
}

ZemaxBsdf ReadZemaxBsdf(const std::string& path) {
  return ParseZemaxBsdf(detail::ReadTextFile(path, detail::kMaxZemaxBytes), path);
}

std::string FormatZemaxBsdf(const ZemaxBsdf& z) {
  std::string out;
  char buf[64];
  for (const std::string& c : z.comments) out += "#" + c + "\n";
  out += "Source  " + (z.source.empty() ? std::string("Measured") : z.source) + "\n";
  out +=
      std::string("Symmetry  ") + (z.plane_symmetric ? "PlaneSymmetrical" : "Asymmetrical") + "\n";
  out += std::string("SpectralContent  ") + (z.xyz ? "XYZ" : "Monochrome") + "\n";
  out += std::string("ScatterType  ") + (z.btdf ? "BTDF" : "BRDF") + "\n";
  const auto list = [&](const char* name, const std::vector<double>& v) {
    out += std::string(name) + " " + std::to_string(v.size()) + "\n";
    for (double a : v) out += detail::FormatShortest(a) + "\t";
    out += "\n";
  };
  list("SampleRotation", z.sample_rotation_deg);
  list("AngleOfIncidence", z.angle_of_incidence_deg);
  list("ScatterAzimuth", z.scatter_azimuth_deg);
  list("ScatterRadial", z.scatter_radial_deg);
  out += "\n";
  static const char* kChannelNames[] = {"TristimulusX", "TristimulusY", "TristimulusZ"};
  const std::size_t n_az = z.scatter_azimuth_deg.size(), n_rad = z.scatter_radial_deg.size();
  const std::size_t blocks = z.sample_rotation_deg.size() * z.angle_of_incidence_deg.size();
  for (std::size_t c = 0; c < z.channels(); ++c) {
    out += std::string(z.xyz ? kChannelNames[c] : "Monochrome") + "\nDataBegin\n";
    for (std::size_t b = 0; b < blocks; ++b) {
      if (c < z.tis.size() && b < z.tis[c].size() && !std::isnan(z.tis[c][b])) {
        std::snprintf(buf, sizeof buf, "TIS %.7g\n", z.tis[c][b]);
        out += buf;
      }
      for (std::size_t a = 0; a < n_az; ++a) {
        for (std::size_t r = 0; r < n_rad; ++r) {
          std::snprintf(buf, sizeof buf, "%.7E%c", z.values[c][(b * n_az + a) * n_rad + r],
                        r + 1 == n_rad ? '\n' : '\t');
          out += buf;
        }
      }
    }
    out += "DataEnd\n";
  }
  return out;
}

Vec3 ZemaxScatterDirection(double specular_theta_deg, double azimuth_deg, double radial_deg) {
  const double ts = DegToRad(specular_theta_deg);
  const double a = DegToRad(azimuth_deg), p = DegToRad(radial_deg);
  const Vec3 r{-std::sin(ts), 0.0, std::cos(ts)};
  const Vec3 e0{std::cos(ts), 0.0, std::sin(ts)};  // from r towards the normal
  const Vec3 e1{0.0, 1.0, 0.0};                    // r × e0
  return std::cos(p) * r + std::sin(p) * (std::cos(a) * e0 + std::sin(a) * e1);
}

std::vector<ZemaxTis> IntegrateZemaxTis(const ZemaxBsdf& z, std::size_t channel) {
  if (channel >= z.channels())
    throw InvalidArgument("IntegrateZemaxTis: channel " + std::to_string(channel) + " of a " +
                          std::to_string(z.channels()) + "-channel file");
  constexpr int kTheta = 180, kPhi = 360;
  const double d_theta = 0.5 * kPi / kTheta, d_phi = 2.0 * kPi / kPhi;
  std::vector<double> sin_t(kTheta), cos_t(kTheta), sin_p(kPhi), cos_p(kPhi);
  for (int j = 0; j < kTheta; ++j) {
    sin_t[j] = std::sin((j + 0.5) * d_theta);
    cos_t[j] = std::cos((j + 0.5) * d_theta);
  }
  for (int k = 0; k < kPhi; ++k) {
    sin_p[k] = std::sin((k + 0.5) * d_phi);
    cos_p[k] = std::cos((k + 0.5) * d_phi);
  }
  const auto& az = z.scatter_azimuth_deg;
  const auto& rad = z.scatter_radial_deg;
  const std::size_t n_az = az.size(), n_rad = rad.size();
  std::vector<ZemaxTis> out;
  std::vector<double> filled(n_az * n_rad);
  for (std::size_t rot = 0; rot < z.sample_rotation_deg.size(); ++rot) {
    for (std::size_t aoi = 0; aoi < z.angle_of_incidence_deg.size(); ++aoi) {
      const std::size_t block = rot * z.angle_of_incidence_deg.size() + aoi;
      const double* raw = z.values[channel].data() + block * n_az * n_rad;
      for (std::size_t a = 0; a < n_az; ++a) {
        for (std::size_t r = 0; r < n_rad; ++r) {
          const double v = raw[a * n_rad + r];
          filled[a * n_rad + r] = (v == 0.0 && r > 0) ? filled[a * n_rad + r - 1] : v;
        }
      }
      const double ts = DegToRad(z.angle_of_incidence_deg[aoi]);
      const Vec3 rr{-std::sin(ts), 0.0, std::cos(ts)};
      const Vec3 e0{std::cos(ts), 0.0, std::sin(ts)};
      double covered = 0, full = 0;
      for (int j = 0; j < kTheta; ++j) {
        const double weight = cos_t[j] * sin_t[j] * d_theta * d_phi;
        for (int k = 0; k < kPhi; ++k) {
          const Vec3 w{sin_t[j] * cos_p[k], sin_t[j] * sin_p[k], cos_t[j]};
          const double rho = RadToDeg(std::acos(std::clamp(Dot(w, rr), -1.0, 1.0)));
          const double alpha = RadToDeg(std::atan2(w.y, Dot(w, e0)));
          const AxisPos pa = AzimuthPos(az, z.plane_symmetric, alpha);
          const AxisPos pr = ClampedPos(rad, rho);
          const auto lerp2 = [&](const double* t) {
            const double v0 =
                (1 - pr.t) * t[pa.i0 * n_rad + pr.i0] + pr.t * t[pa.i0 * n_rad + pr.i1];
            const double v1 =
                (1 - pr.t) * t[pa.i1 * n_rad + pr.i0] + pr.t * t[pa.i1 * n_rad + pr.i1];
            return (1 - pa.t) * v0 + pa.t * v1;
          };
          full += weight * lerp2(filled.data());
          if (rho <= rad.back()) covered += weight * lerp2(raw);
        }
      }
      ZemaxTis t;
      t.sample_rotation_deg = z.sample_rotation_deg[rot];
      t.angle_of_incidence_deg = z.angle_of_incidence_deg[aoi];
      t.file_tis = z.tis[channel][block];
      t.covered_tis = covered;
      t.filled_tis = full;
      out.push_back(t);
    }
  }
  return out;
}

Measurement ZemaxToMeasurement(const ZemaxBsdf& z, const std::string& file,
                               const ZemaxImportOptions& options) {
  if (z.btdf && !options.allow_btdf) {
    throw FormatError(file, LinePosition(z.scatter_type_line),
                      "ScatterType BRDF (a reflection measurement)", "BTDF (transmission)",
                      "transmission data, stored mirrored into the reflection hemisphere only on "
                      "request",
                      Remedy{RemedyKind::kAllowBtdf, file});
  }
  Measurement m;
  m.metadata.sample_name = file;
  m.metadata.extra["source_file"] = file;
  m.metadata.extra["source_format"] = "zemax";
  if (!z.source.empty()) m.metadata.extra["zemax_source"] = z.source;
  m.metadata.extra["scatter_type"] =
      z.btdf ? "BTDF (mirrored into the reflection hemisphere)" : "BRDF";
  m.metadata.extra["spectral_content"] = z.xyz ? "XYZ (converted to linear Rec.709)" : "Monochrome";
  std::string notes;
  for (const std::string& c : z.comments) notes += (notes.empty() ? "" : "\n") + c;
  m.metadata.operator_notes = notes;

  const std::size_t n_az = z.scatter_azimuth_deg.size(), n_rad = z.scatter_radial_deg.size();
  const bool rotated = z.sample_rotation_deg.size() > 1;
  const bool wraps = !z.plane_symmetric && n_az > 1 &&
                     z.scatter_azimuth_deg.back() == z.scatter_azimuth_deg.front() + 360.0;
  for (std::size_t rot = 0; rot < z.sample_rotation_deg.size(); ++rot) {
    const double rotation = rotated ? z.sample_rotation_deg[rot] : 0.0;
    for (std::size_t aoi = 0; aoi < z.angle_of_incidence_deg.size(); ++aoi) {
      Slice s;
      s.theta_in_deg = z.angle_of_incidence_deg[aoi];
      s.phi_in_deg = rotation;
      s.samples.reserve(2 * n_az * n_rad);
      for (std::size_t a = 0; a < n_az; ++a) {
        if (wraps && a + 1 == n_az) continue;  // 360° repeats 0°
        const double alpha = z.scatter_azimuth_deg[a];
        const bool mirror = z.plane_symmetric && alpha != 0.0 && alpha != 180.0;
        for (std::size_t r = 0; r < n_rad; ++r) {
          const double rho = z.scatter_radial_deg[r];
          if (rho == 0.0 && a > 0) continue;  // the specular point, once
          std::array<float, 3> rgb{};
          if (z.xyz) {
            const std::array<double, 3> c =
                XyzToLinearRec709({z.Value(0, rot, aoi, a, r), z.Value(1, rot, aoi, a, r),
                                   z.Value(2, rot, aoi, a, r)});
            if (!(detail::FitsFloat(c[0]) && detail::FitsFloat(c[1]) && detail::FitsFloat(c[2])))
              throw FormatError(file, "data at AOI " + detail::FormatShortest(s.theta_in_deg),
                                "tristimulus values whose linear RGB stays within float32 range",
                                "values beyond it");
            for (int i = 0; i < 3; ++i) rgb[i] = static_cast<float>(c[i]);
          } else {
            rgb.fill(static_cast<float>(z.Value(0, rot, aoi, a, r)));
          }
          bool all_zero = true;
          for (std::size_t c = 0; c < z.channels(); ++c)
            all_zero = all_zero && z.Value(c, rot, aoi, a, r) == 0.0;
          for (int side = 0; side < (mirror ? 2 : 1); ++side) {
            Vec3 w = ZemaxScatterDirection(s.theta_in_deg, side == 0 ? alpha : -alpha, rho);
            if (!(w.z > 1e-12)) continue;  // at or past the horizon
            if (rotated) w = RotateAboutZ(w, rotation);
            Sample smp;
            smp.theta_in_deg = static_cast<float>(s.theta_in_deg);
            smp.phi_in_deg = static_cast<float>(rotation);
            smp.theta_out_deg = static_cast<float>(RadToDeg(ThetaOf(w)));
            smp.phi_out_deg = static_cast<float>(WrapDeg360(RadToDeg(PhiOf(w))));
            if (smp.phi_out_deg >= 360.0f) smp.phi_out_deg = 0.0f;
            smp.rgb = rgb;
            if (all_zero) smp.flags = kFlagInvalid;
            s.samples.push_back(smp);
          }
        }
      }
      m.slices.push_back(std::move(s));
    }
  }
  return m;
}

Measurement LoadZemaxBsdf(const std::string& path, const ZemaxImportOptions& options) {
  return ZemaxToMeasurement(ReadZemaxBsdf(path), path, options);
}

}  // namespace brdf
