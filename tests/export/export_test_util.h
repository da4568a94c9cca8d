// LUTs for the exporter tests, built directly (no resampling): analytic materials evaluated in
// the specular frame of docs/design.md §5, and synthetic patterns whose every texel is
// identifiable.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/core/lut.h"
#include "brdf/core/models.h"
#include "test_support.h"

namespace brdf::test {

// Texel (i, j, k) holds f(θin,k, ω_out) with ω_out = S(θin,k)·ω(θd = j°, φd = i°); below the
// horizon the value at θout = 90° with the same φout (docs/design.md §5 edge extension), evaluated
// a hair above the horizon so the analytic models stay finite.
inline Lut AnalyticLut(const Material& material, std::vector<double> theta_in_deg) {
  Lut lut;
  lut.Resize(theta_in_deg.size());
  lut.theta_in_deg = std::move(theta_in_deg);
  for (int k = 0; k < lut.slices(); ++k) {
    const SpecularFrame frame = SpecularFrame::FromThetaInDeg(lut.theta_in_deg[k]);
    const Vec3 l = SphericalDirectionDeg(lut.theta_in_deg[k], 0.0);
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const Vec3 w_out = frame.FromSpecular(SphericalDirectionDeg(j, i));
        const double theta_out = std::min(RadToDeg(ThetaOf(w_out)), 89.9);
        const Vec3 v = SphericalDirection(DegToRad(theta_out), PhiOf(w_out));
        const Rgb f = material.Evaluate(l, v);
        float* t = lut.Texel(k, j, i);
        for (int c = 0; c < 3; ++c) t[c] = static_cast<float>(f[c]);
      }
  }
  return lut;
}

inline Material Ggx03() {
  Material m;
  m.model = Model::kGgx;
  m.SetParameter(0, {0.2, 0.15, 0.1});
  m.SetParameter(1, {0.9, 0.6, 0.3});  // f0
  m.SetParameter(2, {0.3, 0.3, 0.3});
  m.name = "ggx03";
  return m;
}

inline Material Lafortune20() {
  Material m;
  m.model = Model::kLafortune;
  m.SetParameter(0, {0.3, 0.3, 0.3});
  m.SetParameter(1, {0.5, 0.4, 0.2});
  m.SetParameter(2, {20, 20, 20});
  m.name = "lafortune20";
  return m;
}

inline Material Lambert(double rho) {
  Material m;
  m.model = Model::kLambert;
  m.SetParameter(0, {rho, rho * 0.5, rho * 0.25});
  m.name = "lambert";
  return m;
}

// A pattern spanning the whole RGB9E5 range: magnitudes from 2^-26 to 2^17 (clamped), zeros,
// one NaN and infinities, every texel different. `seed` varies it.
inline Lut PatternLut(std::vector<double> theta_in_deg, std::uint32_t seed) {
  Lut lut;
  lut.Resize(theta_in_deg.size());
  lut.theta_in_deg = std::move(theta_in_deg);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> mant(0.5f, 1.0f);
  std::uniform_int_distribution<int> expo(-26, 17);
  for (float& v : lut.texels) v = std::ldexp(mant(rng), expo(rng));
  lut.Texel(0, 0, 0)[0] = 0.0f;
  lut.Texel(0, 0, 1)[1] = std::nanf("");
  lut.Texel(0, 0, 2)[2] = INFINITY;
  lut.Texel(0, 1, 0)[0] = -3.0f;
  return lut;
}

inline std::vector<std::uint8_t> ReadAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

inline void WriteAll(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline std::uint32_t Le32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return b.at(at) | (b.at(at + 1) << 8) | (b.at(at + 2) << 16) |
         (std::uint32_t{b.at(at + 3)} << 24);
}
inline std::uint64_t Le64(const std::vector<std::uint8_t>& b, std::size_t at) {
  return Le32(b, at) | (std::uint64_t{Le32(b, at + 4)} << 32);
}
inline void SetLe32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.at(at + i) = static_cast<std::uint8_t>(v >> (8 * i));
}

// A fresh private folder for one test (mkdtemp), removed when the test program exits.
inline std::string TestDir(const std::string& name) {
  return brdf::test::NewTempDir("export-" + name).string();
}

// Independent CRC-32 (IEEE 802.3, reflected 0xEDB88320), bit by bit as the standard defines it.
inline std::uint32_t BitwiseCrc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

}  // namespace brdf::test
