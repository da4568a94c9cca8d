// `brdf import` and `brdf info` on third-party measurement files, run as a user runs them.
// The tests write each file themselves from an analytic material (or read the shared Zemax
// file with their own line scan), so every expected value is the file's own number, never the
// tool's output.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/brdf_source.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/merl.h"
#include "brdf/core/models.h"
#include "brdf/core/rgl.h"
#include "test_support.h"
#include "tool_test_util.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using tooltest::Quote;
using tooltest::ToolRun;

constexpr double kPi = 3.14159265358979323846;

std::string SharedZemax() {
  return brdf::test::DataPath("zemax-imaging-sphere/test_13_planesymmetric_btdf_zemax.bsdf");
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A coloured glossy material and a grey one (for the spectral table, whose flat spectra map to
// grey RGB).
Material ColouredWard() {
  Material m;
  m.model = Model::kWard;
  m.SetParameter(0, {0.31, 0.17, 0.06});
  m.SetParameter(1, {0.08, 0.07, 0.05});
  m.SetParameter(2, {0.12, 0.15, 0.2});
  return m;
}
Material GreyWard() {
  Material m;
  m.model = Model::kWard;
  m.SetParameter(0, {0.4, 0.4, 0.4});
  m.SetParameter(1, {0.1, 0.1, 0.1});
  m.SetParameter(2, {0.2, 0.2, 0.2});
  return m;
}

std::string Format(const char* format, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// (θin, θout, φout) → the RGB the test wrote there, as float (the .bpc stores float32).
using Key = std::tuple<float, float, float>;
using Expected = std::map<Key, std::array<float, 3>>;

BpcReadResult ReadIntact(const fs::path& path) {
  BpcReadResult r = ReadBpc(path.string());
  EXPECT_TRUE(r.finished);
  EXPECT_TRUE(r.problems.empty());
  return r;
}

// Every sample of `m` is one the test wrote, with bit-identical RGB; every written entry is
// present exactly once.
void ExpectSameValues(const Measurement& m, const Expected& expected) {
  std::size_t samples = 0;
  for (const Slice& s : m.slices) {
    for (const Sample& x : s.samples) {
      ++samples;
      const auto it = expected.find({x.theta_in_deg, x.theta_out_deg, x.phi_out_deg});
      ASSERT_NE(it, expected.end())
          << "unexpected sample at theta_in " << x.theta_in_deg << ", theta_out " << x.theta_out_deg
          << ", phi_out " << x.phi_out_deg;
      for (int c = 0; c < 3; ++c)
        ASSERT_TRUE(SameBits(x.rgb[c], it->second[c]))
            << x.rgb[c] << " vs " << it->second[c] << " at theta_in " << x.theta_in_deg
            << ", theta_out " << x.theta_out_deg << ", phi_out " << x.phi_out_deg;
    }
  }
  EXPECT_EQ(samples, expected.size());
}

class ImportCommand : public tooltest::ToolTest {};

TEST_F(ImportCommand, CsvPointCloudKeepsEveryValue) {
  const Material mat = ColouredWard();
  std::string text = "# sample_name=coloured ward tile\ntheta_in,phi_in,theta_out,phi_out,r,g,b\n";
  Expected expected;
  for (int tin : {0, 20, 40, 60}) {
    for (int tout = 0; tout <= 75; tout += 5) {
      for (int pout = 0; pout < 360; pout += 15) {
        const Rgb f =
            mat.Evaluate(SphericalDirectionDeg(tin, 0), SphericalDirectionDeg(tout, pout));
        std::array<float, 3> v;
        text += std::to_string(tin) + ",0," + std::to_string(tout) + "," + std::to_string(pout);
        for (int c = 0; c < 3; ++c) {
          v[c] = static_cast<float>(f[c]);
          text += "," + Format("%.9g", v[c]);  // 9 digits identify a float
        }
        text += "\n";
        expected[{static_cast<float>(tin), static_cast<float>(tout), static_cast<float>(pout)}] = v;
      }
    }
  }
  WriteText(dir_ / "ward.csv", text);
  const ToolRun run =
      Run("import " + Quote(dir_ / "ward.csv") + " --out " + Quote(dir_ / "ward.bpc"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("4 slices"), std::string::npos) << run.out;
  const BpcReadResult back = ReadIntact(dir_ / "ward.bpc");
  ASSERT_EQ(back.measurement.slices.size(), 4u);
  EXPECT_EQ(back.measurement.ThetaInDeg(), (std::vector<double>{0, 20, 40, 60}));
  EXPECT_EQ(back.measurement.metadata.sample_name, "coloured ward tile");
  ExpectSameValues(back.measurement, expected);
}

TEST_F(ImportCommand, LightToolsRgbTableKeepsEveryValue) {
  // The MiniDiff RGB layout of docs/formats/lighttools.md, written by hand: per incidence three
  // blocks (R, G, B), each n_az lines of n_rad values; ScatterRadial is θout, ScatterAzimuth
  // φout in the sample frame, the light's plane at POI = 0.
  const Material mat = ColouredWard();
  std::vector<int> azimuths, radials;
  for (int a = 0; a < 360; a += 30) azimuths.push_back(a);
  for (int t = 0; t <= 80; t += 10) radials.push_back(t);
  std::string text = "# written by import_test\nSymmetry Asymmetrical\nSpectralContent RGB\n";
  text += "ScatterAzimuth " + std::to_string(azimuths.size());
  for (int a : azimuths) text += " " + std::to_string(a);
  text += "\nScatterRadial " + std::to_string(radials.size());
  for (int t : radials) text += " " + std::to_string(t);
  text += "\nDataBegin\n";
  Expected expected;
  const char* channel_names[3] = {"R", "G", "B"};
  for (int aoi : {15, 45}) {
    const Vec3 l = SphericalDirectionDeg(aoi, 0);
    for (int c = 0; c < 3; ++c) {
      text += "AOI " + std::to_string(aoi) + "\nPOI 0\nSide Front\nScatterType BRDF\n";
      text += std::string("TristimulusValue ") + channel_names[c] + "\nTIS 0.5\n";
      for (int a : azimuths) {
        for (std::size_t k = 0; k < radials.size(); ++k) {
          const float v =
              static_cast<float>(mat.Evaluate(l, SphericalDirectionDeg(radials[k], a))[c]);
          text += (k == 0 ? "" : "\t") + Format("%.9g", v);
          // θout = 0 is one direction whatever the azimuth: one sample, stored at φout = 0.
          const float phi = radials[k] == 0 ? 0.0f : static_cast<float>(a);
          expected[{static_cast<float>(aoi), static_cast<float>(radials[k]), phi}][c] = v;
        }
        text += "\n";
      }
    }
  }
  text += "DataEnd\n";
  WriteText(dir_ / "minidiff.bsdf", text);
  const ToolRun run =
      Run("import " + Quote(dir_ / "minidiff.bsdf") + " --out " + Quote(dir_ / "minidiff.bpc"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("lighttools"), std::string::npos) << run.out;
  const BpcReadResult back = ReadIntact(dir_ / "minidiff.bpc");
  EXPECT_EQ(back.measurement.ThetaInDeg(), (std::vector<double>{15, 45}));
  ExpectSameValues(back.measurement, expected);
}

TEST_F(ImportCommand, GoniometerTableGivesReflectanceFactorOverPi) {
  // The in-plane spectral table of ../shared/brdf-data/goniometer-csv: reflectance factor
  // R = π·f_r per band; the signed measurement angle a puts the detector at θout = |a|, on the
  // specular side (φout = 180°) for a > 0, on the light's side (φout = 0°) otherwise. Flat
  // spectra are grey, so each channel must be R/π.
  const Material mat = GreyWard();
  std::string text = "Incident_angle,Measure_angle,450nm,550nm,650nm\n";
  std::map<Key, double> expected;
  for (int tin : {10, 40}) {
    for (int a = -80; a <= 80; a += 10) {
      if (a == -tin) continue;  // the detector would be in the source arm's shadow
      const double phi = a > 0 ? 180.0 : 0.0;
      const double f =
          mat.Evaluate(SphericalDirectionDeg(tin, 0), SphericalDirectionDeg(std::abs(a), phi))[0];
      const std::string r = Format("%.6g", kPi * f);
      text += std::to_string(tin) + "," + std::to_string(a) + "," + r + "," + r + "," + r + "\n";
      expected[{static_cast<float>(tin), static_cast<float>(std::abs(a)),
                static_cast<float>(phi)}] = std::strtod(r.c_str(), nullptr) / kPi;
    }
  }
  WriteText(dir_ / "gonio.csv", text);
  const ToolRun run =
      Run("import " + Quote(dir_ / "gonio.csv") + " --out " + Quote(dir_ / "g.bpc"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("gonio"), std::string::npos) << run.out;
  const BpcReadResult back = ReadIntact(dir_ / "g.bpc");
  EXPECT_EQ(back.measurement.ThetaInDeg(), (std::vector<double>{10, 40}));
  std::size_t samples = 0;
  for (const Slice& s : back.measurement.slices) {
    for (const Sample& x : s.samples) {
      ++samples;
      const auto it = expected.find({x.theta_in_deg, x.theta_out_deg, x.phi_out_deg});
      ASSERT_NE(it, expected.end())
          << x.theta_in_deg << " " << x.theta_out_deg << " " << x.phi_out_deg;
      // The file holds 6 digits; the conversion to float and the spectral white balance are
      // far below that.
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(x.rgb[c], it->second, 1e-6 * it->second);
    }
  }
  EXPECT_EQ(samples, expected.size());
}

// A virtual capture at the reference geometry of docs/design.md §1 (θin 0/20/40/60°, θout 0–75°,
// φout 0–359°, 1° steps): every grid point once, f_r equal to the source's own evaluation
// (the reader's Eval, tested on its own in rgl_test / merl_test) as float, flagged invalid
// exactly where `unmeasured` says so.
template <typename Unmeasured>
void ExpectReferenceCapture(const Measurement& m, const BrdfSource& source, Unmeasured unmeasured,
                            std::size_t* flagged) {
  ASSERT_EQ(m.ThetaInDeg(), (std::vector<double>{0, 20, 40, 60}));
  *flagged = 0;
  for (const Slice& s : m.slices) {
    ASSERT_EQ(s.samples.size(), 76u * 360u);
    EXPECT_FALSE(s.has_sigma);
    std::vector<bool> seen(76 * 360, false);
    const Vec3 wi = SphericalDirectionDeg(s.theta_in_deg, 0);
    for (const Sample& x : s.samples) {
      const int t = static_cast<int>(x.theta_out_deg), p = static_cast<int>(x.phi_out_deg);
      ASSERT_TRUE(t == x.theta_out_deg && p == x.phi_out_deg && t >= 0 && t <= 75 && p >= 0 &&
                  p < 360)
          << x.theta_out_deg << " " << x.phi_out_deg;
      ASSERT_FALSE(seen[t * 360 + p]) << "twice: " << t << " " << p;
      seen[t * 360 + p] = true;
      const Vec3 wo = SphericalDirectionDeg(t, p);
      const Rgb f = source.Eval(wi, wo);
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(x.rgb[c], static_cast<float>(f[c])) << s.theta_in_deg << " " << t << " " << p;
      const bool invalid = unmeasured(wi, wo);
      ASSERT_EQ(x.flags, invalid ? kFlagInvalid : 0) << s.theta_in_deg << " " << t << " " << p;
      *flagged += invalid;
    }
  }
}

TEST_F(ImportCommand, RglMaterialBecomesANoiseFreeCaptureAtTheReferenceGeometry) {
  const std::string file = brdf::test::DataPath("rgl/vch_silk_blue_rgb.bsdf");
  const ToolRun run = Run("import " + Quote(file) + " --out " + Quote(dir_ / "silk.bpc"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("rgl"), std::string::npos) << run.out;
  const BpcReadResult back = ReadIntact(dir_ / "silk.bpc");
  EXPECT_EQ(back.measurement.metadata.extra.at("source_format"), "rgl");
  std::size_t flagged = 1;
  ExpectReferenceCapture(
      back.measurement, RglBrdf::Load(file), [](const Vec3&, const Vec3&) { return false; },
      &flagged);
  EXPECT_EQ(flagged, 0u);
}

// The grey Ward material with a hole: no value (NaN) where the view direction leans far
// towards −x, which EncodeMerlBinary stores as "not measured" bins.
class WardWithHole final : public BrdfSource {
 public:
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override {
    if (wo.x < -0.5) return {std::nan(""), std::nan(""), std::nan("")};
    return GreyWard().Evaluate(wi, wo);
  }
  std::string Name() const override { return "ward with a hole"; }
};

TEST_F(ImportCommand, MerlTableBecomesANoiseFreeCaptureWithUnmeasuredBinsFlagged) {
  // A MERL table written by the MERL writer under a name whose extension says nothing:
  // --format decides.
  const fs::path file = dir_ / "ward_table.dat";
  WriteMerlBinary(file.string(), WardWithHole());
  const ToolRun run =
      Run("import " + Quote(file) + " --format merl --out " + Quote(dir_ / "ward.bpc"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const MerlBrdf merl = MerlBrdf::Load(file.string());
  std::size_t flagged = 0;
  ExpectReferenceCapture(
      ReadIntact(dir_ / "ward.bpc").measurement, merl,
      [&](const Vec3& wi, const Vec3& wo) { return !merl.IsMeasured(wi, wo); }, &flagged);
  EXPECT_GT(flagged, 100u);  // the hole reaches the grid: the flag check above is not idle
  EXPECT_NE(run.out.find(std::to_string(flagged) + " flagged invalid"), std::string::npos)
      << run.out;
}

// The shared Zemax file, read with a plain line scan (not the reader under test).
struct ZemaxScan {
  std::uint64_t scatter_type_line = 0;
  std::vector<double> aoi_deg;
  std::vector<double> tis;
  std::vector<double> specular_value;  // first value of each incidence's block: α = 0, ρ = 0
};

ZemaxScan ScanSharedZemax() {
  ZemaxScan z;
  std::istringstream in(ReadFileText(SharedZemax(), 1 << 20));
  std::string line;
  std::uint64_t n = 0;
  bool expect_aoi_list = false, expect_first_row = false;
  while (std::getline(in, line)) {
    ++n;
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "ScatterType") z.scatter_type_line = n;
    if (expect_aoi_list) {
      std::istringstream values(line);
      for (double v; values >> v;) z.aoi_deg.push_back(v);
      expect_aoi_list = false;
    }
    if (word == "AngleOfIncidence") expect_aoi_list = true;
    if (expect_first_row && !word.empty()) {
      z.specular_value.push_back(std::strtod(word.c_str(), nullptr));
      expect_first_row = false;
    }
    if (word == "TIS") {
      double v = 0;
      words >> v;
      z.tis.push_back(v);
      expect_first_row = true;
    }
  }
  return z;
}

TEST_F(ImportCommand, RefusesZemaxBtdfWithoutAllowBtdf) {
  const ZemaxScan z = ScanSharedZemax();
  ASSERT_GT(z.scatter_type_line, 0u);
  const ToolRun run = Run("import " + Quote(SharedZemax()) + " --out " + Quote(dir_ / "z.bpc"));
  EXPECT_EQ(run.exit_code, 1);
  const auto lines = run.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << run.err;
  EXPECT_NE(lines[0].find(SharedZemax()), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("line " + std::to_string(z.scatter_type_line)), std::string::npos)
      << lines[0];
  EXPECT_NE(lines[0].find("ScatterType"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("--allow-btdf"), std::string::npos) << lines[0];
  EXPECT_FALSE(fs::exists(dir_ / "z.bpc"));
}

TEST_F(ImportCommand, ImportsZemaxBtdfWithAllowBtdfMirroredOntoTheSpecularDirection) {
  const ZemaxScan z = ScanSharedZemax();
  ASSERT_EQ(z.aoi_deg.size(), 13u);
  ASSERT_EQ(z.specular_value.size(), z.aoi_deg.size());
  const ToolRun run =
      Run("import " + Quote(SharedZemax()) + " --out " + Quote(dir_ / "z.bpc") + " --allow-btdf");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const BpcReadResult back = ReadIntact(dir_ / "z.bpc");
  const Measurement& m = back.measurement;
  EXPECT_EQ(m.ThetaInDeg(), z.aoi_deg);
  EXPECT_NE(m.metadata.extra.at("scatter_type").find("BTDF"), std::string::npos);
  // The table's centre (α = 0, ρ = 0) is the direct transmission direction; mirrored through
  // the surface it is the specular direction (θout = θin, φout = 180°).
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    int found = 0;
    for (const Sample& x : m.slices[i].samples) {
      if (std::abs(x.theta_out_deg - z.aoi_deg[i]) > 1e-3 || std::abs(x.phi_out_deg - 180) > 1e-3)
        continue;
      ++found;
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(x.rgb[c], static_cast<float>(z.specular_value[i])) << "AOI " << z.aoi_deg[i];
    }
    EXPECT_EQ(found, 1) << "AOI " << z.aoi_deg[i];
  }
}

TEST_F(ImportCommand, SampleOptionNamesTheSample) {
  WriteText(dir_ / "p.csv", "theta_in,phi_in,theta_out,phi_out,r,g,b\n20,0,30,180,0.1,0.2,0.3\n");
  const ToolRun run = Run("import " + Quote(dir_ / "p.csv") + " --out " + Quote(dir_ / "p.bpc") +
                          " --format csv --sample 'tile 7'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(ReadIntact(dir_ / "p.bpc").measurement.metadata.sample_name, "tile 7");
}

TEST_F(ImportCommand, RefusesToOverwriteWithoutForce) {
  WriteText(dir_ / "p.csv", "theta_in,phi_in,theta_out,phi_out,r,g,b\n20,0,30,180,0.1,0.2,0.3\n");
  WriteText(dir_ / "p.bpc", "an earlier capture");
  const std::string args = "import " + Quote(dir_ / "p.csv") + " --out " + Quote(dir_ / "p.bpc");
  const ToolRun refused = Run(args);
  EXPECT_EQ(refused.exit_code, 1);
  ASSERT_EQ(refused.ErrLines().size(), 1u) << refused.err;
  EXPECT_NE(refused.err.find("--force"), std::string::npos) << refused.err;
  EXPECT_EQ(ReadFileText((dir_ / "p.bpc").string(), 100), "an earlier capture");
  const ToolRun forced = Run(args + " --force");
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_EQ(ReadIntact(dir_ / "p.bpc").measurement.SampleCount(), 1u);
}

// Each bad command line: a non-zero exit, no output file, and the problem on the first line of
// stderr (argument errors add one line pointing at --help, nothing else).
TEST_F(ImportCommand, WrongOrMissingArgumentsGiveOneClearLine) {
  WriteText(dir_ / "p.csv", "theta_in,phi_in,theta_out,phi_out,r,g,b\n20,0,30,180,0.1,0.2,0.3\n");
  WriteText(dir_ / "notes.txt", "nothing a reader knows\n");
  const std::string csv = Quote(dir_ / "p.csv"), out = Quote(dir_ / "o.bpc");
  struct Case {
    std::string args;
    int exit_code;
    std::vector<std::string> words;  // each must appear on the first stderr line
  };
  const Case cases[] = {
      {"import", 2, {"file"}},
      {"import " + csv, 2, {"--out"}},
      {"import " + csv + " --out " + out + " --format spreadsheet", 2, {"--format", "spreadsheet"}},
      {"import " + Quote(dir_ / "missing.csv") + " --out " + out, 1, {"missing.csv"}},
      {"import " + csv + " --out " + Quote(dir_ / "o.csv"), 1, {"--out", ".bpc"}},
      {"import " + Quote(dir_ / "notes.txt") + " --out " + out, 1, {"notes.txt", "--format"}},
      {"import " + csv + " --out " + out + " --format zemax", 1, {"p.csv", "line"}},
      {"import " + csv + " --out " + Quote(dir_ / "no-such-dir" / "o.bpc"), 1, {"no-such-dir"}},
  };
  for (const Case& c : cases) {
    const ToolRun run = Run(c.args);
    EXPECT_EQ(run.exit_code, c.exit_code) << c.args << "\n" << run.err;
    const auto lines = run.ErrLines();
    ASSERT_FALSE(lines.empty()) << c.args;
    EXPECT_EQ(lines[0].rfind("brdf: ", 0), 0u) << lines[0];
    EXPECT_LE(lines.size(), 2u) << run.err;
    if (lines.size() == 2) {
      EXPECT_NE(lines[1].find("--help"), std::string::npos) << run.err;
    }
    for (const std::string& w : c.words)
      EXPECT_NE(lines[0].find(w), std::string::npos)
          << c.args << ": '" << w << "' not in " << lines[0];
    EXPECT_TRUE(run.out.empty()) << run.out;
    EXPECT_FALSE(fs::exists(dir_ / "o.bpc")) << c.args;
  }
}

class InfoCommand : public tooltest::ToolTest {};

// The README of the third-party data set (BRDF_DATA_DIR/README.md): integrating the table should
// land within 5–15% of the file's TIS lines; docs/formats/zemax.md gives the tolerance
// |integrated − TIS| ≤ 15% and covered ≤ 1.01·TIS (a lower bound).
TEST_F(InfoCommand, ShowsZemaxIntegratedTisNextToTheFilesOwn) {
  const ZemaxScan z = ScanSharedZemax();
  ASSERT_EQ(z.tis.size(), 13u);
  const ToolRun json_run = Run("info --json " + Quote(SharedZemax()));
  ASSERT_EQ(json_run.exit_code, 0) << json_run.err;
  const Json j = Json::parse(json_run.out);
  EXPECT_EQ(j["format"], "zemax");
  EXPECT_EQ(j["header"]["scatter_type"], "BTDF");
  ASSERT_EQ(j["tis"].size(), z.tis.size());
  for (std::size_t i = 0; i < z.tis.size(); ++i) {
    const Json& row = j["tis"][i];
    EXPECT_EQ(row["angle_of_incidence_deg"].get<double>(), z.aoi_deg[i]);
    EXPECT_EQ(row["file_tis"].get<double>(), z.tis[i]);
    const double integrated = row["integrated_tis"].get<double>();
    EXPECT_NEAR(integrated, z.tis[i], 0.15 * z.tis[i]) << "AOI " << z.aoi_deg[i];
    EXPECT_LE(row["covered_tis"].get<double>(), 1.01 * z.tis[i]) << "AOI " << z.aoi_deg[i];
  }
  EXPECT_EQ(j["slices"].size(), z.aoi_deg.size());

  const ToolRun text_run = Run("info " + Quote(SharedZemax()));
  ASSERT_EQ(text_run.exit_code, 0) << text_run.err;
  std::istringstream lines(text_run.out);
  std::string line;
  bool in_table = false;
  std::size_t rows = 0;
  while (std::getline(lines, line)) {
    if (line.find("file TIS") != std::string::npos && line.find("integrated") != std::string::npos)
      in_table = true;
    if (!in_table) continue;
    std::istringstream words(line);
    std::string channel;
    double rotation = 0, aoi = 0, file_tis = 0, integrated = 0;
    if (!(words >> channel >> rotation >> aoi >> file_tis >> integrated) || channel != "Monochrome")
      continue;
    ASSERT_LT(rows, z.tis.size());
    EXPECT_EQ(aoi, z.aoi_deg[rows]);
    EXPECT_NEAR(file_tis, z.tis[rows], 5e-6);  // printed with 5 decimals
    EXPECT_NEAR(integrated, z.tis[rows], 0.15 * z.tis[rows]);
    ++rows;
  }
  EXPECT_EQ(rows, z.tis.size()) << text_run.out;
}

TEST_F(InfoCommand, DescribesCsvPointCloudByContent) {
  WriteText(dir_ / "p.csv",
            "# sample_name=two samples\ntheta_in,phi_in,theta_out,phi_out,r,g,b\n"
            "20,0,30,180,0.1,0.2,0.3\n20,0,40,180,0.3,0.2,0.1\n");
  const ToolRun run = Run("info --json " + Quote(dir_ / "p.csv"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json j = Json::parse(run.out);
  EXPECT_EQ(j["format"], "csv");
  EXPECT_EQ(j["sample_count"], 2);
  EXPECT_EQ(j["metadata"]["sample_name"], "two samples");
  ASSERT_EQ(j["slices"].size(), 1u);
  EXPECT_EQ(j["slices"][0]["theta_in_deg"], 20.0);
  EXPECT_EQ(j["slices"][0]["theta_out_deg"], Json({30.0, 40.0}));
}

}  // namespace
}  // namespace brdf
