#include "brdf/core/merl.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/sha256.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

std::string ShaTable() { return brdf::test::DataPath("reference/merl_binary_sha256.tsv"); }
const std::string kBrokenDir = std::string(BRDF_SOURCE_DIR) + "/tests/data/broken/merl/";

fs::path TempDir() { return brdf::test::NewTempDir("merl"); }

// ---------------------------------------------------------------------------------------
// SHA-256: the FIPS 180-2 appendix examples and the NIST short/long message values.

TEST(Sha256, MatchesThePublishedTestVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklm"
                      "nopqklmnopqrlmnopqrsmnopqrstnopqrstu"),
            "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, GivesTheSameDigestForAnySplitIntoUpdates) {
  const std::string million(1000000, 'a');
  std::mt19937 rng(3);
  Sha256 sha;
  for (std::size_t pos = 0; pos < million.size();) {
    const std::size_t n = std::min<std::size_t>(rng() % 200, million.size() - pos);
    sha.Update(million.data() + pos, n);
    pos += n;
  }
  const auto digest = sha.Finish();
  std::string hex;
  for (const auto b : digest) {
    char buf[3];
    std::snprintf(buf, sizeof buf, "%02x", b);
    hex += buf;
  }
  EXPECT_EQ(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// ---------------------------------------------------------------------------------------
// Bin indexing, checked against the README's formulas with the test's own geometry.

struct HalfDiff {
  double theta_h, phi_h, theta_d, phi_d;  // radians
};

// ωi and ωo for given Rusinkiewicz angles: the difference vector d = ω(θd, φd) lives in the
// frame whose pole is h = ω(θh, φh) and whose first axis is ∂h/∂θh.
void FromHalfDiff(const HalfDiff& a, Vec3& wi, Vec3& wo) {
  const Vec3 h = SphericalDirection(a.theta_h, a.phi_h);
  const Vec3 t{std::cos(a.phi_h) * std::cos(a.theta_h), std::sin(a.phi_h) * std::cos(a.theta_h),
               -std::sin(a.theta_h)};
  const Vec3 b{-std::sin(a.phi_h), std::cos(a.phi_h), 0.0};
  const Vec3 d = SphericalDirection(a.theta_d, a.phi_d);
  wi = t * d.x + b * d.y + h * d.z;
  wo = h * (2 * Dot(wi, h)) - wi;
}

HalfDiff ToHalfDiff(const Vec3& wi, const Vec3& wo) {
  const Vec3 h = Normalize(wi + wo);
  HalfDiff a;
  a.theta_h = std::acos(std::min(1.0, h.z));
  a.phi_h = std::atan2(h.y, h.x);
  const Vec3 t{std::cos(a.phi_h) * std::cos(a.theta_h), std::sin(a.phi_h) * std::cos(a.theta_h),
               -std::sin(a.theta_h)};
  const Vec3 b{-std::sin(a.phi_h), std::cos(a.phi_h), 0.0};
  a.theta_d = std::acos(std::clamp(Dot(wi, h), -1.0, 1.0));
  a.phi_d = std::atan2(Dot(wi, b), Dot(wi, t));
  return a;
}

// README: i_θh = floor(√(θh/90°)·90), i_θd = floor(θd/90°·90), i_φd = floor(φd/180°·180)
// with φd folded into [0°, 180°).
MerlBin ReadmeBin(const HalfDiff& a) {
  const double th = RadToDeg(a.theta_h), td = RadToDeg(a.theta_d);
  double pd = std::fmod(RadToDeg(a.phi_d), 180.0);
  if (pd < 0) pd += 180.0;
  return {std::min(89, static_cast<int>(std::floor(std::sqrt(th / 90.0) * 90.0))),
          std::min(89, static_cast<int>(std::floor(td))),
          std::min(179, static_cast<int>(std::floor(pd)))};
}

std::vector<HalfDiff> RandomHalfDiffs(std::size_t n, std::uint64_t seed) {
  // Keeps both directions above the horizon and every angle away from bin edges.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<HalfDiff> out;
  while (out.size() < n) {
    HalfDiff a{DegToRad(80 * u(rng) * u(rng)), 2 * kPi * u(rng) - kPi, DegToRad(85 * u(rng)),
               2 * kPi * u(rng) - kPi};
    Vec3 wi, wo;
    FromHalfDiff(a, wi, wo);
    if (wi.z < 0.02 || wo.z < 0.02) continue;
    const double th = std::sqrt(RadToDeg(a.theta_h) / 90.0) * 90.0;
    const double td = RadToDeg(a.theta_d), pd = std::fmod(RadToDeg(a.phi_d) + 360.0, 180.0);
    auto near_edge = [](double x) { return std::abs(x - std::round(x)) < 1e-6; };
    if (near_edge(th) || near_edge(td) || near_edge(pd)) continue;
    out.push_back(a);
  }
  return out;
}

TEST(MerlBin, FollowsTheReadmeIndexFormulasIncludingThePhiDiffFold) {
  int folded = 0;
  for (const HalfDiff& a : RandomHalfDiffs(20000, 1)) {
    Vec3 wi, wo;
    FromHalfDiff(a, wi, wo);
    const MerlBin got = MerlBinOf(wi, wo), want = ReadmeBin(a);
    ASSERT_EQ(got.theta_half, want.theta_half) << RadToDeg(a.theta_h);
    ASSERT_EQ(got.theta_diff, want.theta_diff) << RadToDeg(a.theta_d);
    ASSERT_EQ(got.phi_diff, want.phi_diff) << RadToDeg(a.phi_d);
    folded += a.phi_d < 0 ? 1 : 0;
  }
  EXPECT_GT(folded, 5000);  // half of the cases exercise φd → φd + 180°
  // The index layout: (i_θh·90 + i_θd)·180 + i_φd.
  EXPECT_EQ((MerlBin{2, 3, 4}.Index()), (2u * 90 + 3) * 180 + 4);
  EXPECT_EQ((MerlBin{89, 89, 179}.Index()), kMerlBinsPerChannel - 1);
}

TEST(MerlBin, CentresFallInTheirOwnBinAtTheRightAngles) {
  for (int th = 0; th < 90; th += 7) {
    for (int td = 0; td < 90; td += 11) {
      for (int pd = 0; pd < 180; pd += 13) {
        Vec3 wi, wo;
        MerlBinCenter({th, td, pd}, wi, wo);
        const HalfDiff a = ToHalfDiff(wi, wo);
        // Centre of the √-spaced θh interval [90(i/90)², 90((i+1)/90)²) in index space.
        EXPECT_NEAR(RadToDeg(a.theta_h), 90.0 * std::pow((th + 0.5) / 90.0, 2), 1e-9);
        EXPECT_NEAR(RadToDeg(a.theta_d), td + 0.5, 1e-9);
        if (th > 0) {
          EXPECT_NEAR(std::fmod(RadToDeg(a.phi_d) + 360.0, 360.0), pd + 0.5, 1e-7);
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Reading: layout and scales from bytes the test writes itself.

std::string Header(std::int32_t a = 90, std::int32_t b = 90, std::int32_t c = 180) {
  std::string s;
  AppendU32(s, static_cast<std::uint32_t>(a));
  AppendU32(s, static_cast<std::uint32_t>(b));
  AppendU32(s, static_cast<std::uint32_t>(c));
  return s;
}

// A whole file whose raw value in plane c, bin i is value(c, i).
template <class F>
std::string MerlBytes(F value) {
  std::string s = Header();
  s.reserve(kMerlFileBytes);
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < kMerlBinsPerChannel; ++i)
      AppendU64(s, std::bit_cast<std::uint64_t>(static_cast<double>(value(c, i))));
  return s;
}

MerlBrdf FromString(const std::string& bytes, const std::string& name = "test.binary") {
  return MerlBrdf::FromBytes(
      std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), name);
}

TEST(MerlBrdf, ReadsPlanesInRgbOrderAtTheReadmeIndexWithTheChannelScales) {
  // Red holds index + 1, green 2·index + 1, blue 1500: decoding the value names the bin.
  const MerlBrdf brdf = FromString(MerlBytes([](int c, std::size_t i) {
    return c == 0 ? i + 1.0 : c == 1 ? 2.0 * i + 1.0 : 1500.0;
  }));
  for (const HalfDiff& a : RandomHalfDiffs(3000, 2)) {
    Vec3 wi, wo;
    FromHalfDiff(a, wi, wo);
    const double index = static_cast<double>(ReadmeBin(a).Index());
    const Rgb f = brdf.Eval(wi, wo);
    EXPECT_DOUBLE_EQ(f[0], (index + 1) / 1500.0);
    EXPECT_DOUBLE_EQ(f[1], (2 * index + 1) * 1.15 / 1500.0);
    EXPECT_DOUBLE_EQ(f[2], 1.66);
    EXPECT_TRUE(brdf.IsMeasured(wi, wo));
  }
  EXPECT_EQ(brdf.info().unmeasured_bins, (std::array<std::uint64_t, 3>{0, 0, 0}));
  EXPECT_EQ(brdf.Eval(SphericalDirectionDeg(30, 0), {0.5, 0.0, -0.8}), (Rgb{0, 0, 0}));
  EXPECT_EQ(brdf.Eval(SphericalDirectionDeg(30, 0), {NAN, 0.0, 0.8}), (Rgb{0, 0, 0}));
}

TEST(MerlBrdf, FlagsNegativeValuesAsNotMeasured) {
  const HalfDiff a{DegToRad(10.3), 0.2, DegToRad(20.5), 1.0};
  const std::size_t hole = ReadmeBin(a).Index();
  const MerlBrdf brdf = FromString(MerlBytes([hole](int c, std::size_t i) {
    return (c == 1 && i == hole) ? -1.0 : (c == 2 && i % 1000 == 0) ? -0.5 : 300.0;
  }));
  EXPECT_EQ(brdf.info().unmeasured_bins, (std::array<std::uint64_t, 3>{0, 1, 1458}));
  Vec3 wi, wo;
  FromHalfDiff(a, wi, wo);
  EXPECT_FALSE(brdf.IsMeasured(wi, wo));
  const Rgb f = brdf.Eval(wi, wo);
  EXPECT_DOUBLE_EQ(f[0], 0.2);
  EXPECT_EQ(f[1], 0.0);
}

// ---------------------------------------------------------------------------------------
// Round trips through files written from analytic materials.

Material Lambert(Rgb rho) {
  Material m;
  m.model = Model::kLambert;
  m.SetParameter(0, rho);
  m.name = "lambert";
  return m;
}

TEST(MerlRoundTrip, ReproducesAConstantBrdfExactlyWhereverTheBinCentreIsVisible) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "lambert.binary").string();
  const AnalyticBrdf lambert(Lambert({0.2, 0.5, 0.8}));
  WriteMerlBinary(path, lambert);
  const MerlBrdf merl = MerlBrdf::Load(path);
  EXPECT_EQ(merl.Name(), "lambert.binary");
  // Bins whose centre pair is below the horizon are written as not measured; count them with
  // the test's own geometry.
  std::uint64_t hidden = 0;
  for (int th = 0; th < 90; ++th)
    for (int td = 0; td < 90; ++td)
      for (int pd = 0; pd < 180; ++pd) {
        Vec3 wi, wo;
        const double t = (th + 0.5) / 90.0;
        FromHalfDiff({kPi / 2 * t * t, 0.0, DegToRad(td + 0.5), DegToRad(pd + 0.5)}, wi, wo);
        hidden += (wi.z <= 0 || wo.z <= 0) ? 1 : 0;
      }
  EXPECT_GT(hidden, 0u);
  EXPECT_EQ(merl.info().unmeasured_bins, (std::array<std::uint64_t, 3>{hidden, hidden, hidden}));
  // Up to 80° the bin centre of any pair is visible (bins are at most 2° wide).
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    const Vec3 wi = SphericalDirectionDeg(80 * u(rng), 360 * u(rng));
    const Vec3 wo = SphericalDirectionDeg(80 * u(rng), 360 * u(rng));
    ASSERT_TRUE(merl.IsMeasured(wi, wo));
    const Rgb f = merl.Eval(wi, wo);
    EXPECT_NEAR(f[0], 0.2 / kPi, 1e-15);
    EXPECT_NEAR(f[1], 0.5 / kPi, 1e-15);
    EXPECT_NEAR(f[2], 0.8 / kPi, 1e-15);
  }
  // At grazing pairs whose bin centre is below the horizon the reader reports a hole.
  int holes = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 wi = SphericalDirectionDeg(89.5 + 0.45 * u(rng), 360 * u(rng));
    const Vec3 wo = SphericalDirectionDeg(89.5 + 0.45 * u(rng), 360 * u(rng));
    if (!merl.IsMeasured(wi, wo)) {
      ++holes;
      EXPECT_EQ(merl.Eval(wi, wo), (Rgb{0, 0, 0}));
    }
  }
  EXPECT_GT(holes, 0);
  fs::remove_all(dir);
}

// A glossy GGX material: the lookup returns f at the centre of the pair's bin (the test
// computes the bin and its centre itself), so its error against f at the pair is bounded by
// f's variation across one bin — 90·(2i+1)/8100 degrees in θh, 1° in θd and φd. The test
// asserts both, estimating the variation on a 5×5×5 grid over the bin (plus the two points).
TEST(MerlRoundTrip, ReturnsTheAnalyticValueAtTheBinCentreForAGlossyMaterial) {
  Material ggx;
  ggx.model = Model::kGgx;
  ggx.SetParameter(0, {0.05, 0.10, 0.20});
  ggx.SetParameter(1, {0.04, 0.5, 0.9});  // f0
  ggx.SetParameter(2, {0.15, 0.15, 0.3});
  const AnalyticBrdf source(ggx);
  const MerlBrdf merl = FromString(EncodeMerlBinary(source), "ggx.binary");
  double worst_relative = 0;
  for (const HalfDiff& a : RandomHalfDiffs(4000, 5)) {
    Vec3 wi, wo;
    FromHalfDiff(a, wi, wo);
    if (wi.z > std::cos(DegToRad(75)) && wo.z > std::cos(DegToRad(75))) {
      const MerlBin bin = ReadmeBin(a);
      auto f_at = [&](double th_index, double td_deg, double pd_deg) {
        const double t = th_index / 90.0;
        Vec3 i, o;
        FromHalfDiff({kPi / 2 * t * t, 0.0, DegToRad(td_deg), DegToRad(pd_deg)}, i, o);
        return source.Eval(i, o);
      };
      const Rgb centre = f_at(bin.theta_half + 0.5, bin.theta_diff + 0.5, bin.phi_diff + 0.5);
      const Rgb got = merl.Eval(wi, wo), exact = source.Eval(wi, wo);
      Rgb lo = exact, hi = exact;
      for (int x = 0; x <= 4; ++x)
        for (int y = 0; y <= 4; ++y)
          for (int z = 0; z <= 4; ++z) {
            const Rgb f =
                f_at(bin.theta_half + x / 4.0, bin.theta_diff + y / 4.0, bin.phi_diff + z / 4.0);
            for (int c = 0; c < 3; ++c) {
              lo[c] = std::min({lo[c], f[c], centre[c]});
              hi[c] = std::max({hi[c], f[c], centre[c]});
            }
          }
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(got[c], centre[c], 1e-12 * (1 + centre[c]));
        EXPECT_LE(std::abs(got[c] - exact[c]), hi[c] - lo[c] + 1e-12);
        worst_relative = std::max(worst_relative, std::abs(got[c] - exact[c]) / exact[c]);
      }
    }
  }
  // For this lobe (α = 0.15) a bin is a sizeable step near the peak: the worst relative
  // lookup error over the sample is a few percent to tens of percent, never a factor.
  EXPECT_LT(worst_relative, 1.0);
}

// ---------------------------------------------------------------------------------------
// Bad input

std::string ReadError(const std::string& bytes) {
  try {
    FromString(bytes, "bad.binary");
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

TEST(MerlBrdf, RefusesBadHeadersSizesAndValuesWithTheirPosition) {
  EXPECT_EQ(ReadError(""),
            "bad.binary: byte 0: expected a 12-byte header of three int32 (90, 90, 180), then "
            "3 x 1458000 float64, got 0 bytes in the file");
  EXPECT_EQ(ReadError(Header(90, 90, 360)),
            "bad.binary: byte 8: expected header dimension 2 (phi_diff bins) = 180, got 360 (a "
            "MERL .binary file starts with the int32 values 90, 90, 180)");
  EXPECT_NE(ReadError(Header(-90, 90, 180))
                .find("byte 0: expected header dimension 0 "
                      "(theta_half bins) = 90, got -90"),
            std::string::npos);
  EXPECT_EQ(ReadError(Header() + std::string(1000, '\0')),
            "bad.binary: file size: expected 34992012 bytes (12-byte header + 3 x 1458000 "
            "float64 values), got 1012 bytes (the file is truncated)");
  const std::size_t nan_at = 12345;
  std::string bytes = MerlBytes([](int, std::size_t) { return 1.0; });
  const double nan = std::nan("");
  std::memcpy(bytes.data() + 12 + 8 * nan_at, &nan, 8);
  const double inf = INFINITY;
  std::memcpy(bytes.data() + 12 + 8 * (2 * kMerlBinsPerChannel + 7), &inf, 8);
  // Bin 12345 = (θh 0, θd 68, φd 105).
  EXPECT_EQ(ReadError(bytes), "bad.binary: byte " + std::to_string(12 + 8 * nan_at) +
                                  " (red plane, bin theta_half 0, theta_diff 68, phi_diff 105): "
                                  "expected a finite value (negative marks 'not measured'), "
                                  "got NaN");
  const double one = 1.0;
  std::memcpy(bytes.data() + 12 + 8 * nan_at, &one, 8);
  EXPECT_NE(ReadError(bytes).find("(blue plane, bin theta_half 0, theta_diff 0, phi_diff 7): "
                                  "expected a finite value (negative marks 'not measured'), "
                                  "got +inf"),
            std::string::npos);
  bytes.push_back('\0');
  EXPECT_NE(ReadError(bytes).find("trailing data after the table"), std::string::npos);
}

TEST(MerlBrdf, RefusesAnOversizedFileBeforeReadingIt) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "big.binary").string();
  {
    std::ofstream f(path, std::ios::binary);
    f << Header();
  }
  fs::resize_file(path, kMerlFileBytes + 1);
  try {
    MerlBrdf::Load(path);
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.position(), "file size");
    EXPECT_EQ(e.expected(), "at most 34992012 bytes");
  }
  fs::remove_all(dir);
}

// Hand-made broken files (tests/data/broken/merl, made by make_broken.py there).
TEST(MerlBrokenFiles, EachFailsWithAClearFormatError) {
  const std::map<std::string, std::string> expected = {
      {"empty.binary", "12-byte header"},
      {"short_header.binary", "12-byte header"},
      {"wrong_dims.binary", "byte 8: expected header dimension 2 (phi_diff bins) = 180, got 360"},
      {"swapped_dims.binary",
       "byte 0: expected header dimension 0 (theta_half bins) = 90, got 180"},
      {"negative_dims.binary",
       "byte 4: expected header dimension 1 (theta_diff bins) = 90, got -90"},
      {"huge_dims.binary", "got 2147483647"},
      {"truncated.binary", "got 4108 bytes (the file is truncated)"},
      {"text_file.binary", "= 90, got 1819043176"},
  };
  std::set<std::string> present, listed;
  for (const auto& e : fs::directory_iterator(kBrokenDir))
    if (e.path().extension() == ".binary") present.insert(e.path().filename().string());
  for (const auto& [name, part] : expected) listed.insert(name);
  EXPECT_EQ(present, listed) << "every broken file needs an expectation here";
  for (const auto& [name, part] : expected) {
    SCOPED_TRACE(name);
    const std::string path = kBrokenDir + name;
    try {
      MerlBrdf::Load(path);
      ADD_FAILURE() << "loaded";
    } catch (const FormatError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
      EXPECT_NE(m.find(part), std::string::npos) << m;
    }
  }
}

// ---------------------------------------------------------------------------------------
// Identification by SHA-256

TEST(MerlDigests, ReadsThePublishedTable) {
  const std::vector<MerlDigest> table = ReadMerlDigestTable(ShaTable());
  ASSERT_EQ(table.size(), 100u);
  EXPECT_EQ(table[0].material, "alum-bronze");
  EXPECT_EQ(table[0].size_bytes, kMerlFileBytes);
  EXPECT_EQ(table[0].sha256, "d6506c69e44430bfe8ea676f3950599ca3a6bfb1f46b9906da336d13991bd37d");
  EXPECT_EQ(table.back().material, "yellow-plastic");
  for (const MerlDigest& d : table) EXPECT_EQ(d.size_bytes, kMerlFileBytes) << d.material;
}

TEST(MerlDigests, NamesTheLineOfAMalformedEntry) {
  const fs::path dir = TempDir();
  const std::string path = (dir / "table.tsv").string();
  WriteFileAtomically(
      path, "# comment\nok\t34992012\t" + std::string(64, 'a') + "\nbad\t34992012\tnot-hex\n");
  try {
    ReadMerlDigestTable(path);
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.position(), "line 3");
    EXPECT_EQ(e.expected(), "64 hexadecimal digits of SHA-256 in the third field");
  }
  fs::remove_all(dir);
}

// The digest of our own file as computed by coreutils' sha256sum, an independent program.
std::string CoreutilsSha256(const std::string& path) {
  std::FILE* p = ::popen(("sha256sum '" + path + "'").c_str(), "r");
  if (p == nullptr) return "";
  char buf[65] = {};
  const std::size_t n = std::fread(buf, 1, 64, p);
  ::pclose(p);
  return std::string(buf, n);
}

TEST(MerlDigests, IdentifiesAFileListedInTheTableAndNoOtherOne) {
  const fs::path dir = TempDir();
  const std::string merl = (dir / "synthetic.binary").string();
  WriteMerlBinary(merl, AnalyticBrdf(Lambert({0.3, 0.3, 0.3})));
  const std::string sha = CoreutilsSha256(merl);
  ASSERT_EQ(sha.size(), 64u);
  EXPECT_EQ(Sha256HexOfFile(merl), sha);
  // A synthetic file is none of the 100 published ones.
  EXPECT_EQ(IdentifyMerlFile(merl, ShaTable()), std::nullopt);
  // Listed under a name, it is recognised; the table may come from the environment.
  const std::string table = (dir / "table.tsv").string();
  WriteFileAtomically(table, "# material\tsize_bytes\tsha256\nsynthetic-grey\t" +
                                 std::to_string(kMerlFileBytes) + "\t" + sha + "\n");
  EXPECT_EQ(IdentifyMerlFile(merl, table), std::optional<std::string>("synthetic-grey"));
  ::setenv("BRDF_MERL_SHA256_TABLE", table.c_str(), 1);
  EXPECT_EQ(IdentifyMerlFile(merl), std::optional<std::string>("synthetic-grey"));
  ::unsetenv("BRDF_MERL_SHA256_TABLE");
  EXPECT_THROW(IdentifyMerlFile(merl), InvalidArgument);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace brdf
