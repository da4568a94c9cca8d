// `brdf export-csv` run as a user runs it: a .bpc the test writes, exported, read back with
// brdf::ReadCsv (and imported back with `brdf import`) must give every float bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/csv.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/models.h"
#include "tool_test_util.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;
using tooltest::Quote;
using tooltest::ToolRun;

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A capture as the instrument writes one: θin 0/20/40/60, values of a Lafortune material
// (non-round floats), σ on every slice, flags, the last slice interrupted, and awkward floats
// a text format can lose: a denormal, −0, a negative (noisy dark) value, the largest float.
Measurement AwkwardCapture() {
  Material mat;
  mat.model = Model::kLafortune;
  mat.SetParameter(0, {0.21, 0.34, 0.12});
  mat.SetParameter(1, {0.4, 0.35, 0.3});
  mat.SetParameter(2, {18, 22, 30});
  Measurement m;
  m.metadata.sample_name = "tile, \"awkward\"";
  m.metadata.instrument_model = "MiniDiff V2 (simulated)";
  m.metadata.instrument_serial = "SIM-7";
  m.metadata.firmware_version = "2.1.0";
  m.metadata.protocol_version = "1";
  m.metadata.calibration_reference = "Spectralon 99%";
  m.metadata.calibration_time = "2026-11-22T09:58:00Z";
  m.metadata.capture_start = "2026-11-22T10:00:00Z";
  m.metadata.capture_end = "2026-11-22T10:03:00Z";
  m.metadata.operator_notes = "two lines\nand a backslash \\ = sign";
  m.metadata.software_version = "brdf-toolchain test";
  m.metadata.extra["seed"] = "9";
  m.metadata.extra["theta_in_deg"] = "0, 20, 40, 60";
  for (double tin : {0.0, 20.0, 40.0, 60.0}) {
    Slice s;
    s.theta_in_deg = tin;
    s.has_sigma = true;
    s.complete = tin != 60.0;
    const Vec3 l = SphericalDirectionDeg(tin, 0.0);
    for (int t = 0; t <= 75; t += 5) {
      for (int p = 0; p < 360; p += 7) {
        Sample x;
        x.theta_in_deg = static_cast<float>(tin);
        x.theta_out_deg = static_cast<float>(t) + 0.1f;
        x.phi_out_deg = static_cast<float>(p) + 0.3f;
        const Rgb f = mat.Evaluate(l, SphericalDirectionDeg(x.theta_out_deg, x.phi_out_deg));
        for (int c = 0; c < 3; ++c) {
          x.rgb[c] = static_cast<float>(f[c]);
          x.sigma[c] = static_cast<float>(0.013 * f[c]);
        }
        x.flags = static_cast<std::uint8_t>((t + p) % 16);
        s.samples.push_back(x);
      }
    }
    m.slices.push_back(std::move(s));
  }
  Sample& a = m.slices[1].samples[3];
  a.rgb = {1e-40f, -0.0f, -2.5e-4f};
  a.sigma = {std::numeric_limits<float>::denorm_min(), 0.0f, 3e-38f};
  m.slices[2].samples[5].rgb[1] = std::numeric_limits<float>::max();
  return m;
}

void ExpectSameMeasurement(const Measurement& got, const Measurement& want) {
  const Metadata &g = got.metadata, &w = want.metadata;
  EXPECT_EQ(g.sample_name, w.sample_name);
  EXPECT_EQ(g.instrument_model, w.instrument_model);
  EXPECT_EQ(g.instrument_serial, w.instrument_serial);
  EXPECT_EQ(g.firmware_version, w.firmware_version);
  EXPECT_EQ(g.protocol_version, w.protocol_version);
  EXPECT_EQ(g.calibration_reference, w.calibration_reference);
  EXPECT_EQ(g.calibration_time, w.calibration_time);
  EXPECT_EQ(g.capture_start, w.capture_start);
  EXPECT_EQ(g.capture_end, w.capture_end);
  EXPECT_EQ(g.operator_notes, w.operator_notes);
  EXPECT_EQ(g.units, w.units);
  EXPECT_EQ(g.software_version, w.software_version);
  EXPECT_EQ(g.extra, w.extra);
  ASSERT_EQ(got.slices.size(), want.slices.size());
  for (std::size_t i = 0; i < want.slices.size(); ++i) {
    const Slice &a = want.slices[i], &b = got.slices[i];
    EXPECT_EQ(b.theta_in_deg, a.theta_in_deg);
    EXPECT_EQ(b.phi_in_deg, a.phi_in_deg);
    EXPECT_EQ(b.has_sigma, a.has_sigma);
    EXPECT_EQ(b.complete, a.complete);
    ASSERT_EQ(b.samples.size(), a.samples.size());
    for (std::size_t k = 0; k < a.samples.size(); ++k) {
      const Sample &x = a.samples[k], &y = b.samples[k];
      ASSERT_TRUE(
          SameBits(x.theta_in_deg, y.theta_in_deg) && SameBits(x.phi_in_deg, y.phi_in_deg) &&
          SameBits(x.theta_out_deg, y.theta_out_deg) && SameBits(x.phi_out_deg, y.phi_out_deg))
          << "slice " << i << " sample " << k;
      for (int c = 0; c < 3; ++c) {
        ASSERT_TRUE(SameBits(x.rgb[c], y.rgb[c]))
            << "slice " << i << " sample " << k << ": " << x.rgb[c] << " vs " << y.rgb[c];
        ASSERT_TRUE(SameBits(x.sigma[c], y.sigma[c])) << "slice " << i << " sample " << k;
      }
      ASSERT_EQ(x.flags, y.flags) << "slice " << i << " sample " << k;
    }
  }
}

class ExportCsvCommand : public tooltest::ToolTest {};

TEST_F(ExportCsvCommand, RoundTripIsBitExact) {
  const Measurement m = AwkwardCapture();
  WriteBpc((dir_ / "cap.bpc").string(), m);
  const ToolRun run =
      Run("export-csv " + Quote(dir_ / "cap.bpc") + " --out " + Quote(dir_ / "cap.csv"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // What the copy keeps that every other command refuses is said, one warning per reason
  // (docs/robustness.md, "One verdict per file"): the incomplete slice, and the largest float,
  // a value no surface has (docs/design.md §4).
  EXPECT_NE(run.err.find("warning: copied as it is"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("stopped before finishing"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("above 1e5"), std::string::npos) << run.err;
  ExpectSameMeasurement(ReadCsv((dir_ / "cap.csv").string()), m);

  // And back into a capture through `brdf import`.
  const ToolRun back =
      Run("import " + Quote(dir_ / "cap.csv") + " --out " + Quote(dir_ / "back.bpc"));
  ASSERT_EQ(back.exit_code, 0) << back.err;
  const BpcReadResult r = ReadBpc((dir_ / "back.bpc").string());
  EXPECT_TRUE(r.finished);
  EXPECT_TRUE(r.problems.empty());
  ExpectSameMeasurement(r.measurement, m);
}

TEST_F(ExportCsvCommand, RefusesValuesACsvCannotHoldNamingTheSample) {
  Measurement m = AwkwardCapture();
  m.slices[2].samples[11].rgb[0] = std::numeric_limits<float>::quiet_NaN();
  WriteBpc((dir_ / "nan.bpc").string(), m);
  const ToolRun run =
      Run("export-csv " + Quote(dir_ / "nan.bpc") + " --out " + Quote(dir_ / "nan.csv"));
  EXPECT_EQ(run.exit_code, 1);
  const auto lines = run.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << run.err;
  EXPECT_NE(lines[0].find("slice 2, sample 11"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("NaN"), std::string::npos) << lines[0];
  EXPECT_FALSE(fs::exists(dir_ / "nan.csv"));
}

TEST_F(ExportCsvCommand, RefusesDamagedCaptureNamingTheByte) {
  WriteBpc((dir_ / "cap.bpc").string(), AwkwardCapture());
  const auto size = fs::file_size(dir_ / "cap.bpc");
  {
    // Flip one byte in the middle of the file: inside a slice payload, caught by its CRC-32.
    std::fstream f(dir_ / "cap.bpc", std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(size / 2));
    const char c = static_cast<char>(f.get());
    f.seekp(static_cast<std::streamoff>(size / 2));
    f.put(static_cast<char>(c ^ 0x5a));
  }
  const ToolRun run =
      Run("export-csv " + Quote(dir_ / "cap.bpc") + " --out " + Quote(dir_ / "cap.csv"));
  EXPECT_EQ(run.exit_code, 1);
  const auto lines = run.ErrLines();
  ASSERT_EQ(lines.size(), 1u) << run.err;
  EXPECT_NE(lines[0].find("cap.bpc"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("byte"), std::string::npos) << lines[0];
  EXPECT_FALSE(fs::exists(dir_ / "cap.csv"));
}

TEST_F(ExportCsvCommand, WrongOrMissingArgumentsGiveOneClearLine) {
  WriteBpc((dir_ / "cap.bpc").string(), AwkwardCapture());
  std::ofstream(dir_ / "taken.csv") << "keep me";
  std::ofstream(dir_ / "p.csv") << "theta_in,phi_in,theta_out,phi_out,r,g,b\n20,0,30,0,1,1,1\n";
  const std::string cap = Quote(dir_ / "cap.bpc");
  struct Case {
    std::string args;
    int exit_code;
    std::vector<std::string> words;
  };
  const Case cases[] = {
      {"export-csv", 2, {"file"}},
      {"export-csv " + cap, 2, {"--out"}},
      {"export-csv " + Quote(dir_ / "missing.bpc") + " --out " + Quote(dir_ / "o.csv"),
       1,
       {"missing.bpc"}},
      {"export-csv " + Quote(dir_ / "p.csv") + " --out " + Quote(dir_ / "o.csv"),
       1,
       {".bpc", "brdf import"}},
      {"export-csv " + cap + " --out " + Quote(dir_ / "o.bpc"), 1, {"--out", ".csv"}},
      {"export-csv " + cap + " --out " + Quote(dir_ / "taken.csv"), 1, {"taken.csv", "--force"}},
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
    EXPECT_FALSE(fs::exists(dir_ / "o.csv")) << c.args;
  }
  EXPECT_EQ(ReadFileText((dir_ / "taken.csv").string(), 100), "keep me");
  const ToolRun forced =
      Run("export-csv " + cap + " --out " + Quote(dir_ / "taken.csv") + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

}  // namespace
}  // namespace brdf
