// Helpers for the tests that run the built `brdf` tool as a user runs it (the one runner of
// tests/tools): a private scratch folder per test, a process runner, and oracles written here from
// the specifications, independent of the code under test: the analytic BRDFs of docs/design.md §9,
// the specular frame of docs/design.md §5, the Bézier of docs/design.md §6 (by bisection), the
// RGB9E5 layout of EXT_texture_shared_exponent, and minimal KTX2 / DDS / .bpc layout readers
// written from their specifications.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/measurement.h"
#include "test_support.h"

namespace brdf::tooltest {

namespace fs = std::filesystem;

inline constexpr double kPi = 3.14159265358979323846;

struct ToolRun {
  int exit_code = -1;
  std::string out, err;

  // stderr split into lines (without the newlines).
  std::vector<std::string> ErrLines() const {
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (start < err.size()) {
      const std::size_t end = err.find('\n', start);
      lines.push_back(err.substr(start, end == std::string::npos ? end : end - start));
      if (end == std::string::npos) break;
      start = end + 1;
    }
    return lines;
  }
};

inline std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Runs `brdf <args>` with stdout and stderr captured.
inline ToolRun RunTool(const std::string& args, const fs::path& dir) {
  const fs::path out_file = dir / ".tool_stdout.txt", err_file = dir / ".tool_stderr.txt";
  const std::string cmd = std::string(BRDF_TOOL) + " " + args + " >'" + out_file.string() +
                          "' 2>'" + err_file.string() + "'";
  const int status = std::system(cmd.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadAll(out_file);
  r.err = ReadAll(err_file);
  fs::remove(out_file);
  fs::remove(err_file);
  return r;
}

inline std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

// A fresh private folder per test (mkdtemp), removed afterwards.
class ToolTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::ScopedTempDir::MakeTempDir("tool"); }
  void TearDown() override {
    if (std::getenv("BRDF_KEEP_TEST_OUTPUT") == nullptr) fs::remove_all(dir_);
  }
  ToolRun Run(const std::string& args) const { return RunTool(args, dir_); }
  fs::path dir_;
};

inline void WriteText(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// ---- directions and analytic BRDFs (docs/design.md §4, §9), written out independently ----

struct V3 {
  double x, y, z;
};
inline V3 Dir(double theta_deg, double phi_deg) {
  const double t = theta_deg * kPi / 180, p = phi_deg * kPi / 180;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}
inline double DotV(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 Unit(const V3& a) {
  const double n = std::sqrt(DotV(a, a));
  return {a.x / n, a.y / n, a.z / n};
}

struct Analytic {
  std::string model;  // "lambert", "ggx", "lafortune"
  std::array<double, 3> kd{}, ks{};
  double shape = 0;  // alpha or n
  std::string Json(const std::string& extra = "") const {
    char buf[512];
    if (model == "lambert")
      std::snprintf(buf, sizeof buf, "{\"model\": \"lambert\", \"rho\": [%.17g, %.17g, %.17g]%s}",
                    kd[0], kd[1], kd[2], extra.c_str());
    else if (model == "ggx")
      std::snprintf(buf, sizeof buf,
                    "{\"model\": \"ggx\", \"kd\": [%.17g, %.17g, %.17g], "
                    "\"f0\": [%.17g, %.17g, %.17g], \"alpha\": %.17g%s}",
                    kd[0], kd[1], kd[2], ks[0], ks[1], ks[2], shape, extra.c_str());
    else
      std::snprintf(buf, sizeof buf,
                    "{\"model\": \"lafortune\", \"kd\": [%.17g, %.17g, %.17g], "
                    "\"ks\": [%.17g, %.17g, %.17g], \"n\": %.17g%s}",
                    kd[0], kd[1], kd[2], ks[0], ks[1], ks[2], shape, extra.c_str());
    return buf;
  }
  // f_r (1/sr) for light l and view v, from the docs/design.md §9 table.
  std::array<double, 3> F(const V3& l, const V3& v) const {
    std::array<double, 3> f{};
    if (l.z <= 0 || v.z <= 0) return f;
    for (int c = 0; c < 3; ++c) {
      if (model == "lambert") {
        f[c] = kd[c] / kPi;
      } else if (model == "lafortune") {
        const V3 r{-l.x, -l.y, l.z};
        const double vr = DotV(v, r);
        f[c] = kd[c] / kPi + ks[c] * (shape + 2) / (2 * kPi) * (vr > 0 ? std::pow(vr, shape) : 0);
      } else {
        const V3 h = Unit({l.x + v.x, l.y + v.y, l.z + v.z});
        const double a2 = shape * shape;
        const double cos_h = h.z, tan2_h = (1 - cos_h * cos_h) / (cos_h * cos_h);
        const double d = a2 / (kPi * std::pow(cos_h, 4) * (a2 + tan2_h) * (a2 + tan2_h));
        const auto g1 = [&](double cos_x) {
          const double tan2 = (1 - cos_x * cos_x) / (cos_x * cos_x);
          return 2 / (1 + std::sqrt(1 + a2 * tan2));
        };
        const double fresnel = ks[c] + (1 - ks[c]) * std::pow(1 - DotV(v, h), 5);
        f[c] = kd[c] / kPi + fresnel * g1(l.z) * g1(v.z) * d / (4 * l.z * v.z);
      }
    }
    return f;
  }
  std::array<double, 3> FAngles(double theta_in, double theta_out, double phi_out) const {
    return F(Dir(theta_in, 0), Dir(theta_out, phi_out));
  }
};

inline Analytic Lambertian() { return {"lambert", {0.5, 0.4, 0.3}, {}, 0}; }
inline Analytic Ggx03() { return {"ggx", {0.2, 0.1, 0.05}, {0.9, 0.6, 0.3}, 0.3}; }
inline Analytic Lafortune20() { return {"lafortune", {0.3, 0.2, 0.1}, {0.5, 0.4, 0.2}, 20}; }

// docs/design.md §5: ω_out = S(θin)·ω_d with S(θm) = [[−cosθm, 0, −sinθm], [0, −1, 0],
// [−sinθm, 0, cosθm]]; returns (θout, φout) in degrees, φout in [0, 360).
inline std::array<double, 2> TexelDirection(double theta_in_deg, int i, int j) {
  const V3 d = Dir(j, i);
  const double c = std::cos(theta_in_deg * kPi / 180), s = std::sin(theta_in_deg * kPi / 180);
  const V3 o{-c * d.x - s * d.z, -d.y, -s * d.x + c * d.z};
  const double theta = std::acos(std::fmax(-1.0, std::fmin(1.0, o.z))) * 180 / kPi;
  double phi = std::atan2(o.y, o.x) * 180 / kPi;
  if (phi < 0) phi += 360;
  if (phi >= 360) phi -= 360;
  return {theta, phi};
}

// docs/design.md §6 Bézier b(x, l), found by bisection on x(t) = 2(1−t)t·l + t² (not the closed
// form).
inline double BezierByBisection(double x, double l) {
  double lo = 0, hi = 1;
  for (int it = 0; it < 200; ++it) {
    const double t = 0.5 * (lo + hi);
    (2 * (1 - t) * t * l + t * t < x ? lo : hi) = t;
  }
  const double t = 0.5 * (lo + hi);
  return 2 * (1 - t) * t * (1 - l) + t * t;
}

// ---- RGB9E5 (EXT_texture_shared_exponent, N = 9, B = 15) ----

inline std::array<double, 3> DecodeRgb9e5Word(std::uint32_t w) {
  const double scale = std::ldexp(1.0, static_cast<int>(w >> 27) - 15 - 9);
  return {(w & 0x1ff) * scale, ((w >> 9) & 0x1ff) * scale, ((w >> 18) & 0x1ff) * scale};
}

// The quantisation step of a colour whose largest channel is `max_c` (> 0): 2^(e − B − N) with
// the shared exponent e of the specification, round-up correction included.
inline double Rgb9e5Step(double max_c) {
  int e = std::max(-16, static_cast<int>(std::floor(std::log2(max_c)))) + 1 + 15;
  if (std::floor(max_c / std::ldexp(1.0, e - 15 - 9) + 0.5) == 512) ++e;
  return std::ldexp(1.0, e - 15 - 9);
}

// ---- container layouts, read from their specifications ----

inline std::uint32_t LoadU32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b.at(at + i));
  return v;
}
inline std::uint64_t LoadU64(const std::string& b, std::size_t at) {
  return LoadU32(b, at) | (static_cast<std::uint64_t>(LoadU32(b, at + 4)) << 32);
}

struct Texture3d {
  std::uint32_t format = 0;  // vkFormat (KTX2) or DXGI format (DDS)
  std::uint32_t width = 0, height = 0, depth = 0;
  std::string payload;  // level 0 bytes
  std::uint32_t Word(std::size_t x, std::size_t y, std::size_t z) const {
    return LoadU32(payload, ((z * height + y) * width + x) * 4);
  }
};

// KTX 2.0: identifier (12 bytes), vkFormat @12, pixelWidth @20, pixelHeight @24, pixelDepth @28,
// level index @80 (byteOffset u64, byteLength u64, uncompressedByteLength u64).
inline Texture3d ReadKtx2Layout(const fs::path& p) {
  const std::string b = ReadAll(p);
  static const unsigned char kId[12] = {0xAB, 'K',  'T',  'X',  ' ',  '2',
                                        '0',  0xBB, '\r', '\n', 0x1A, '\n'};
  Texture3d t;
  if (b.size() < 104 || std::memcmp(b.data(), kId, 12) != 0) {
    ADD_FAILURE() << p << " is not a KTX2 file";
    return t;
  }
  t.format = LoadU32(b, 12);
  t.width = LoadU32(b, 20);
  t.height = LoadU32(b, 24);
  t.depth = LoadU32(b, 28);
  const std::uint64_t offset = LoadU64(b, 80), length = LoadU64(b, 88);
  if (offset + length > b.size()) {
    ADD_FAILURE() << p << ": level 0 runs past the end of the file";
    return t;
  }
  t.payload = b.substr(offset, length);
  return t;
}

// DDS: "DDS " magic, DDS_HEADER (124 bytes: height @12, width @16, depth @24 from the file
// start), DDS_HEADER_DXT10 (dxgiFormat @128), data from byte 148.
inline Texture3d ReadDdsLayout(const fs::path& p) {
  const std::string b = ReadAll(p);
  Texture3d t;
  if (b.size() < 148 || b.compare(0, 4, "DDS ") != 0) {
    ADD_FAILURE() << p << " is not a DDS file";
    return t;
  }
  t.height = LoadU32(b, 12);
  t.width = LoadU32(b, 16);
  t.depth = LoadU32(b, 24);
  t.format = LoadU32(b, 128);
  t.payload = b.substr(148);
  return t;
}

// .bpc chunk starts (docs/formats/bpc.md: 12-byte preamble, then chunks of a 24-byte header
// with payload_size at +8), with their tags.
struct ChunkSpan {
  std::string tag;
  std::uint64_t offset = 0, size = 0;  // whole chunk, header included
};
inline std::vector<ChunkSpan> BpcChunks(const fs::path& p) {
  const std::string b = ReadAll(p);
  std::vector<ChunkSpan> chunks;
  for (std::size_t pos = 12; pos + 24 <= b.size();) {
    const std::uint64_t n = LoadU64(b, pos + 8);
    chunks.push_back({b.substr(pos, 4), pos, 24 + n});
    pos += 24 + n;
  }
  return chunks;
}

// A noise-free capture of `m` on a θout/φout lattice (degrees, 1° steps by default), computed
// with the formulas above.
inline Measurement CaptureOf(const Analytic& m, const std::vector<double>& theta_in_deg,
                             int theta_out_max = 75, int theta_step = 1, int phi_step = 1) {
  Measurement out;
  out.metadata.sample_name = m.model;
  out.metadata.capture_start = out.metadata.capture_end = "2026-11-22T10:00:00Z";
  for (double ti : theta_in_deg) {
    Slice s;
    s.theta_in_deg = ti;
    for (int t = 0; t <= theta_out_max; t += theta_step)
      for (int p = 0; p < 360; p += phi_step) {
        Sample x;
        x.theta_in_deg = static_cast<float>(ti);
        x.theta_out_deg = static_cast<float>(t);
        x.phi_out_deg = static_cast<float>(p);
        const auto f = m.FAngles(ti, t, p);
        x.rgb = {static_cast<float>(f[0]), static_cast<float>(f[1]), static_cast<float>(f[2])};
        s.samples.push_back(x);
      }
    out.slices.push_back(std::move(s));
  }
  return out;
}

// "a b c" from `brdf eval`.
inline std::array<double, 3> ParseTriple(const std::string& text) {
  std::array<double, 3> v{std::nan(""), std::nan(""), std::nan("")};
  if (std::sscanf(text.c_str(), "%lf %lf %lf", &v[0], &v[1], &v[2]) != 3)
    ADD_FAILURE() << "expected three numbers, got '" << text << "'";
  return v;
}

inline std::string Angles(double a, double b) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g,%.17g", a, b);
  return buf;
}

// Files in `dir` whose names start with `prefix` (hidden temporaries included).
inline std::vector<std::string> FilesStartingWith(const fs::path& dir, const std::string& prefix) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.compare(0, prefix.size(), prefix) == 0) names.push_back(n);
  }
  return names;
}

}  // namespace brdf::tooltest
