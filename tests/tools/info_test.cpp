// `brdf info` run as a user runs it: the built tool on files this test writes. Every expected
// number is computed here from the Measurement the test wrote, not by the tool's code.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/file_util.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

ToolRun RunTool(const std::string& args, const fs::path& dir) {
  const fs::path err_file = dir / "stderr.txt";
  const std::string cmd = std::string(BRDF_TOOL) + " " + args + " 2>'" + err_file.string() + "'";
  ToolRun r;
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = ReadFileText(err_file.string(), 1 << 20);
  return r;
}

class InfoTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = brdf::test::ScopedTempDir::MakeTempDir("info"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// Three slices on a coarse grid with known values: f_r = (a, 2a, 3a) with a = 0.01·(j + 1) + i,
// every 10th sample saturated, every 25th invalid (and then excluded from the statistics).
Measurement MakeMeasurement() {
  Measurement m;
  m.metadata.sample_name = "test tile";
  m.metadata.instrument_model = "MiniDiff V2 (simulated)";
  m.metadata.instrument_serial = "SIM-42";
  m.metadata.capture_start = "2026-11-22T10:00:00Z";
  m.metadata.capture_end = "2026-11-22T10:01:00Z";
  m.metadata.extra["seed"] = "3";
  const double theta_in[] = {0, 20, 40};
  for (int i = 0; i < 3; ++i) {
    Slice s;
    s.theta_in_deg = theta_in[i];
    s.has_sigma = i == 1;
    int j = 0;
    for (int t = 0; t <= 75; t += 5) {
      for (int p = 0; p < 360; p += 30, ++j) {
        Sample x;
        x.theta_in_deg = static_cast<float>(theta_in[i]);
        x.theta_out_deg = static_cast<float>(t);
        x.phi_out_deg = static_cast<float>(p);
        const float a = 0.01f * static_cast<float>(j + 1) + static_cast<float>(i);
        x.rgb = {a, 2 * a, 3 * a};
        if (j % 10 == 0) x.flags |= kFlagSaturated;
        if (j % 25 == 0) {
          x.flags |= kFlagInvalid;
          x.rgb = {1e6f, 1e6f, 1e6f};  // would dominate max and mean if not excluded
        }
        s.samples.push_back(x);
      }
    }
    m.slices.push_back(std::move(s));
  }
  return m;
}

TEST_F(InfoTest, JsonDescribesAFinishedCaptureWithItsOwnNumbers) {
  const Measurement m = MakeMeasurement();
  const std::string path = (dir_ / "cap.bpc").string();
  WriteBpc(path, m);
  const ToolRun run = RunTool("info --json '" + path + "'", dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json j = Json::parse(run.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << run.out;
  EXPECT_EQ(j["theta_in_deg"], Json({0.0, 20.0, 40.0}));
  EXPECT_EQ(j["sample_count"], 3 * 16 * 12);
  EXPECT_TRUE(j["finished"].get<bool>());
  EXPECT_TRUE(j["problems"].empty());
  EXPECT_EQ(j["metadata"]["sample_name"], "test tile");
  EXPECT_EQ(j["metadata"]["instrument_serial"], "SIM-42");
  EXPECT_EQ(j["metadata"]["extra"]["seed"], "3");
  ASSERT_EQ(j["slices"].size(), 3u);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE("slice " + std::to_string(i));
    const Json& s = j["slices"][i];
    const Slice& want = m.slices[i];
    EXPECT_EQ(s["theta_in_deg"], want.theta_in_deg);
    EXPECT_EQ(s["samples"], 192);
    EXPECT_TRUE(s["complete"].get<bool>());
    EXPECT_EQ(s["theta_out_deg"], Json({0.0, 75.0}));
    EXPECT_EQ(s["phi_out_deg"], Json({0.0, 330.0}));
    // Closed forms over the valid samples: j = 0..191 minus multiples of 25 (0, 25, ..., 175).
    double sum = 0;
    int valid = 0, saturated = 0, invalid = 0;
    double lo = std::numeric_limits<double>::infinity(), hi = 0;
    for (int k = 0; k < 192; ++k) {
      saturated += k % 10 == 0;
      if (k % 25 == 0) {
        ++invalid;
        continue;
      }
      const double a =
          static_cast<double>(0.01f * static_cast<float>(k + 1) + static_cast<float>(i));
      sum += a;
      lo = std::min(lo, a);
      hi = std::max(hi, a);
      ++valid;
    }
    EXPECT_EQ(valid, 184);
    for (int c = 0; c < 3; ++c) {
      // Channel c holds (c + 1)·a rounded to float.
      const double scale = c + 1;
      EXPECT_NEAR(s["rgb_min"][c].get<double>(), scale * lo, 1e-6 * scale * hi);
      EXPECT_NEAR(s["rgb_max"][c].get<double>(), scale * hi, 1e-6 * scale * hi);
      EXPECT_NEAR(s["rgb_mean"][c].get<double>(), scale * sum / valid, 1e-6 * scale * hi);
    }
    EXPECT_EQ(s["flag_counts"]["saturated"], saturated);
    EXPECT_EQ(s["flag_counts"]["invalid"], invalid);
    EXPECT_EQ(s["flag_counts"]["interpolated"], 0);
  }
}

TEST_F(InfoTest, ReportsAnInterruptedCaptureAndHowToResumeIt) {
  const Measurement m = MakeMeasurement();
  const std::string path = (dir_ / "cut.bpc").string();
  {
    BpcAppender a = BpcAppender::Create(path, m.metadata);
    a.AppendSlice(m.slices[0]);
  }
  const auto intact = fs::file_size(path);
  {
    BpcAppender a = BpcAppender::Resume(path, nullptr);
    a.AppendSlice(m.slices[1]);
  }
  fs::resize_file(path, intact + 1000);  // slice 1 cut 1000 bytes into its chunk
  const ToolRun run = RunTool("info --json '" + path + "'", dir_);
  // Damaged (convert and eval refuse it): described in full, and the exit code says so.
  ASSERT_EQ(run.exit_code, 1) << run.err;
  const Json j = Json::parse(run.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << run.out;
  EXPECT_FALSE(j["finished"].get<bool>());
  EXPECT_EQ(j["theta_in_deg"], Json({0.0}));
  EXPECT_EQ(j["sample_count"], 192);
  ASSERT_EQ(j["problems"].size(), 1u);
  EXPECT_EQ(j["problems"][0]["offset"], intact);
  EXPECT_EQ(j["problems"][0]["slice"], 1);
  EXPECT_EQ(j["problems"][0]["kind"], "truncated");
  EXPECT_NE(j["advice"].get<std::string>().find("--resume"), std::string::npos);

  const ToolRun text = RunTool("info '" + path + "'", dir_);
  EXPECT_EQ(text.exit_code, 1);
  EXPECT_NE(text.out.find("byte " + std::to_string(intact) + " (slice 1)"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("--resume"), std::string::npos) << text.out;
}

TEST_F(InfoTest, DescribesAMaterialFile) {
  const std::string path = (dir_ / "plastic.json").string();
  WriteFileAtomically(path, R"({"model": "lafortune", "kd": [0.5, 0.1, 0.1],
                                "ks": [0.2, 0.2, 0.2], "n": [40, 40, 40]})");
  const ToolRun run = RunTool("info --json '" + path + "'", dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json j = Json::parse(run.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << run.out;
  EXPECT_EQ(j["model"], "lafortune");
  EXPECT_EQ(j["parameters"]["kd"], Json({0.5, 0.1, 0.1}));
  EXPECT_EQ(j["parameters"]["ks"], Json({0.2, 0.2, 0.2}));
  EXPECT_EQ(j["parameters"]["n"], Json({40.0, 40.0, 40.0}));
}

TEST_F(InfoTest, UnknownOrUnreadableFilesGiveOneLineAndFail) {
  const std::string txt = (dir_ / "notes.txt").string();
  WriteFileAtomically(txt, "hello");
  ToolRun run = RunTool("info '" + txt + "'", dir_);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find("notes.txt: a file of unknown type"), std::string::npos) << run.err;

  run = RunTool("info '" + (dir_ / "missing.bpc").string() + "'", dir_);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find("missing.bpc"), std::string::npos) << run.err;

  const std::string bad = (dir_ / "bad.bpc").string();
  WriteFileAtomically(bad, "not a capture at all");
  run = RunTool("info '" + bad + "'", dir_);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find("byte 0"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out.empty());
}

}  // namespace
}  // namespace brdf
