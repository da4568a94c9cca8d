// `brdf capture` run as a lab user runs it: the built tool against the simulated instrument.
// Values are checked against models.h evaluated here, files with ReadBpc.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "brdf/core/bpc.h"
#include "brdf/core/file_util.h"
#include "commands.h"
#include "device_test_support.h"
#include "test_support.h"

namespace brdf::device {
namespace {

namespace fs = std::filesystem;

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

class CaptureCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = brdf::test::ScopedTempDir::MakeTempDir("capture-cli"); }
  void TearDown() override { fs::remove_all(dir_); }

  ToolRun Run(const std::string& args) const {
    const fs::path err_file = dir_ / "stderr.txt";
    const std::string cmd = std::string(BRDF_TOOL) + " " + args + " 2>'" + err_file.string() + "'";
    ToolRun r;
    std::FILE* pipe = ::popen(cmd.c_str(), "r");
    if (pipe == nullptr) return r;
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
    const int status = ::pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = ReadFileText(err_file.string(), 1 << 20);
    return r;
  }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

// A coarse grid keeps each run short: 16 rows × 72 columns per slice.
const std::string kCoarse = " --theta-out-step 5 --phi-out-step 5";

TEST_F(CaptureCli, NoiseFreeCaptureMatchesTheAnalyticMaterial) {
  const std::string out = Path("red.bpc");
  const ToolRun r =
      Run("capture --device sim --material plastic_glossy_red --sample 'red tile' "
          "--out " +
          out + " --theta-in 0,40 --noise 0" + kCoarse);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << "progress goes to stderr";
  EXPECT_NE(r.err.find("slice 1/2 θin=0°: 1,152 samples"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("slice 2/2 θin=40°: 1,152 samples"), std::string::npos) << r.err;
  const BpcReadResult file = ReadBpc(out);
  EXPECT_TRUE(file.finished);
  EXPECT_EQ(file.measurement.metadata.sample_name, "red tile");
  ASSERT_EQ(file.measurement.slices.size(), 2u);
  const Material m = testing::LibraryMaterial("plastic_glossy_red");
  for (const Slice& s : file.measurement.slices) {
    ASSERT_EQ(s.samples.size(), 1152u);
    for (const Sample& x : s.samples) {
      const Rgb t = testing::Truth(m, x);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(x.rgb[c], t[c], 1e-5 * t[c]);
    }
  }
}

TEST_F(CaptureCli, InterruptedCaptureTellsHowToResumeAndResumeCompletesIt) {
  for (const char* noise : {"0", "1"}) {
    const std::string common =
        std::string(" --material gold --sample g --noise ") + noise + kCoarse + " --seed 5";
    const std::string whole = Path("whole.bpc"), cut = Path("cut.bpc");
    fs::remove(whole);
    fs::remove(cut);
    ASSERT_EQ(Run("capture --out " + whole + common).exit_code, 0);

    // 8 set-up frames, then 18 per slice: the link drops in the third slice.
    const ToolRun broken = Run("capture --out " + cut + common + " --sim-fault disconnect:51");
    EXPECT_EQ(broken.exit_code, 1);
    EXPECT_NE(broken.err.find("disconnected"), std::string::npos) << broken.err;
    EXPECT_NE(broken.err.find("2 of 4 slices are saved in " + cut), std::string::npos)
        << broken.err;
    EXPECT_NE(broken.err.find("--resume"), std::string::npos) << broken.err;
    const BpcReadResult partial = ReadBpc(cut);
    EXPECT_FALSE(partial.finished);
    EXPECT_EQ(partial.measurement.slices.size(), 2u);

    const ToolRun resumed = Run("capture --out " + cut + common + " --resume");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    EXPECT_NE(resumed.err.find("slice 3/4 θin=40°"), std::string::npos) << resumed.err;
    const Measurement a = LoadBpc(whole), b = LoadBpc(cut);
    ASSERT_EQ(b.slices.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      ASSERT_EQ(a.slices[k].samples.size(), b.slices[k].samples.size());
      for (std::size_t i = 0; i < a.slices[k].samples.size(); ++i) {
        const Sample &x = a.slices[k].samples[i], &y = b.slices[k].samples[i];
        ASSERT_EQ(x.rgb, y.rgb) << "noise " << noise << " slice " << k << " sample " << i;
        ASSERT_EQ(x.sigma, y.sigma);
        ASSERT_EQ(x.flags, y.flags);
        ASSERT_EQ(x.theta_out_deg, y.theta_out_deg);
        ASSERT_EQ(x.phi_out_deg, y.phi_out_deg);
      }
    }
    EXPECT_EQ(b.metadata.extra.at("resumed_theta_in_deg"), "40,60");

    const ToolRun again = Run("capture --out " + cut + common + " --resume");
    EXPECT_EQ(again.exit_code, 0);
    EXPECT_NE(again.err.find("nothing to resume"), std::string::npos) << again.err;
  }
}

TEST_F(CaptureCli, InterruptedCaptureRecordsItsPlanSoConvertNamesTheMissingSlices) {
  // 8 set-up frames (dark + a white per θin with 4 θin; 7 with 3), then 18 per slice on the
  // coarse grid: disconnect:51 / :45 drop the link in the third slice, after two saved.
  struct Case {
    std::string theta_in, fault, key, missing;
  };
  // 0,30,60 differs from the reference instrument's 0,20,40,60 that `brdf convert` assumes
  // when a capture records no plan: only the recorded plan names 60° alone as missing.
  for (const Case& c : {Case{"0,20,40,60", "51", "0,20,40,60", "missing 40, 60°"},
                        Case{"0,30,60", "46", "0,30,60", "missing 60°)"}}) {
    SCOPED_TRACE(c.theta_in);
    const std::string out = Path("plan.bpc");
    fs::remove(out);
    const std::string common = " --material gold --sample g --theta-in " + c.theta_in + kCoarse;
    const ToolRun broken =
        Run("capture --out " + out + common + " --sim-fault disconnect:" + c.fault);
    ASSERT_EQ(broken.exit_code, 1) << broken.err;
    ASSERT_EQ(ReadBpc(out).measurement.slices.size(), 2u);

    const ToolRun info = Run("info --json " + out);
    // Missing planned slices: convert refuses it, so info reports it and exits 1.
    ASSERT_EQ(info.exit_code, 1) << info.err;
    EXPECT_NE(info.out.find("\"theta_in_deg\": \"" + c.key + "\""), std::string::npos) << info.out;

    const ToolRun convert = Run("convert " + out + " --out " + Path("lut") + " --quiet --force");
    EXPECT_EQ(convert.exit_code, 1);
    EXPECT_NE(convert.out.find("converted 0 of 1"), std::string::npos) << convert.out;
    EXPECT_NE(convert.out.find(c.missing), std::string::npos) << convert.out;
    EXPECT_NE(convert.out.find("--resume"), std::string::npos) << convert.out;

    // Resuming keeps the plan and completes the capture, which then converts.
    const ToolRun resumed = Run("capture --out " + out + common + " --resume --quiet");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    EXPECT_EQ(ReadBpc(out).measurement.metadata.extra.at("theta_in_deg"), c.key);
    const ToolRun done =
        Run("convert " + out + " --out " + Path("lut") + " --formats ktx2 --quiet --force");
    EXPECT_EQ(done.exit_code, 0) << done.out << done.err;
  }
}

TEST_F(CaptureCli, ResumeRefusesADifferentThetaInPlan) {
  const std::string out = Path("p.bpc");
  ASSERT_EQ(Run("capture --material gold --sample g --out " + out + kCoarse +
                " --sim-fault disconnect:31")
                .exit_code,
            1);
  const ToolRun r = Run("capture --material gold --sample g --out " + out + kCoarse +
                        " --theta-in 0,20,40 --resume");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("theta_in_deg = 0,20,40,60"), std::string::npos) << r.err;
}

TEST_F(CaptureCli, CorruptFrameIsRetriedWithAWarningNamingTheCrc) {
  const std::string out = Path("c.bpc");
  const ToolRun r = Run("capture --material paper_white --sample p --out " + out + kCoarse +
                        " --sim-fault corrupt:30");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("CRC-32"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("measuring again"), std::string::npos) << r.err;
  EXPECT_TRUE(ReadBpc(out).finished);
}

TEST_F(CaptureCli, EveryListedFaultApplies) {
  // Two corrupt frames in different slices: both are retried (one warning each).
  const std::string out = Path("two.bpc");
  const ToolRun r = Run("capture --material paper_white --sample p --out " + out + kCoarse +
                        " --sim-fault corrupt:12,corrupt:60");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::size_t warnings = 0;
  for (std::size_t at = r.err.find("warning"); at != std::string::npos;
       at = r.err.find("warning", at + 1))
    ++warnings;
  EXPECT_EQ(warnings, 2u) << r.err;
}

TEST_F(CaptureCli, OutputMustBeABpcFileAndTheSeedAWholeNumber) {
  for (const std::string& args :
       {std::string("--out ") + Path("cap.txt"), "--out " + Path("c.bpc") + " --seed -1",
        "--out " + Path("c.bpc") + " --seed 1.5"}) {
    const ToolRun r = Run("capture --material gold --sample g " + args + kCoarse);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
    EXPECT_NE(r.err.find(args.find("seed") != std::string::npos ? "--seed" : ".bpc"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(Path("cap.txt")));
    EXPECT_FALSE(fs::exists(Path("c.bpc")));
  }
}

TEST_F(CaptureCli, ResumeRefusesDifferentSettings) {
  const std::string out = Path("s.bpc");
  ASSERT_EQ(Run("capture --material gold --sample g --out " + out + kCoarse +
                " --sim-fault disconnect:31")
                .exit_code,
            1);
  const ToolRun other_seed =
      Run("capture --material gold --sample g --out " + out + kCoarse + " --seed 2 --resume");
  EXPECT_EQ(other_seed.exit_code, 1);
  EXPECT_NE(other_seed.err.find("seed"), std::string::npos) << other_seed.err;
  const ToolRun other_sample =
      Run("capture --material gold --sample h --out " + out + kCoarse + " --resume");
  EXPECT_EQ(other_sample.exit_code, 1);
  EXPECT_NE(other_sample.err.find("holds sample 'g'"), std::string::npos) << other_sample.err;
}

TEST_F(CaptureCli, ResumeOfAFileWithoutAReadableHeaderSuggestsStartingOver) {
  const std::string out = Path("junk.bpc");
  {
    std::FILE* f = std::fopen(out.c_str(), "wb");
    std::fputs("not a capture", f);
    std::fclose(f);
  }
  const ToolRun r = Run("capture --material gold --sample g --out " + out + kCoarse + " --resume");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("byte 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFileText(out, 100), "not a capture");
}

TEST_F(CaptureCli, RefusesToOverwriteAnExistingFileWithoutForce) {
  const std::string out = Path("x.bpc");
  {
    std::FILE* f = std::fopen(out.c_str(), "wb");
    std::fputs("precious", f);
    std::fclose(f);
  }
  const ToolRun r = Run("capture --material gold --sample g --out " + out + kCoarse);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("already exists"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFileText(out, 100), "precious");
  EXPECT_EQ(Run("capture --material gold --sample g --out " + out + kCoarse + " --force --quiet")
                .exit_code,
            0);
  EXPECT_TRUE(ReadBpc(out).finished);
}

// Ctrl-C, SIGTERM and SIGHUP (a closed SSH session) during a capture: the scan is aborted on the
// instrument, the completed slices stay in a valid, unfinished file, the resume line is printed,
// and --resume completes it to the uninterrupted result. No race against real time: the
// simulated firmware holds before frame 30 (a ROW_DATA of the second slice; 8 set-up frames, 18
// per slice on the coarse grid) until it receives ABORT, and says so on stderr, which the test
// reads through a pipe; the signal is sent only then, so exactly one slice is complete whatever
// the machine's load. The tool's read of the held firmware wakes on the cancel (a waiting poll,
// no timeout), and the firmware reports the ABORT that ends the hold.
TEST_F(CaptureCli, SignalAbortsTheScanAndLeavesAResumableFile) {
  const std::string common = " --material gold --sample g --seed 3" + kCoarse;
  const std::string whole = Path("whole.bpc");
  ASSERT_EQ(Run("capture --quiet --out " + whole + common).exit_code, 0);
  const Measurement expected = LoadBpc(whole);
  const std::string hold_line = "holding before frame 30 until the capture is cancelled";
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE(sig);
    const std::string out = Path("sig.bpc");
    fs::remove(out);
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      ::dup2(pipe_fds[1], 2);
      ::close(pipe_fds[0]);
      ::close(pipe_fds[1]);
      const std::string cmd = std::string("exec ") + BRDF_TOOL + " capture --out " + out + common +
                              " --sim-fault hold:30";
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(pipe_fds[1]);
    // Blocking reads until the hold is announced, then the signal, then the rest until the tool
    // closes its stderr. (A tool silent for a minute is killed: a broken hold must not hang the
    // test.)
    std::string log;
    bool signalled = false, silent = false;
    char buf[4096];
    for (;;) {
      pollfd p{pipe_fds[0], POLLIN, 0};
      const int ready = ::poll(&p, 1, 60000);
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) {
        silent = true;
        ::kill(pid, SIGKILL);
        break;
      }
      const ssize_t n = ::read(pipe_fds[0], buf, sizeof buf);
      if (n == 0) break;
      if (n < 0) {
        if (errno == EINTR) continue;
        break;
      }
      log.append(buf, static_cast<std::size_t>(n));
      if (!signalled && log.find(hold_line) != std::string::npos) {
        ASSERT_EQ(::kill(pid, sig), 0);
        signalled = true;
      }
    }
    ::close(pipe_fds[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_FALSE(silent) << "the tool said nothing for 60 s: " << log;
    ASSERT_TRUE(signalled) << log;
    ASSERT_TRUE(WIFEXITED(status)) << log;
    EXPECT_EQ(WEXITSTATUS(status), 130) << log;
    // Before the hold the first slice was reported; nothing after it but the cancel.
    EXPECT_NE(log.find("slice 1/4"), std::string::npos) << log;
    EXPECT_EQ(log.find("slice 2/4"), std::string::npos) << log;
    EXPECT_NE(log.find("ABORT received, hold released"), std::string::npos) << log;
    // The hold is waited out until the signal, never read as a timeout and retried.
    EXPECT_EQ(log.find("measuring again"), std::string::npos) << log;
    EXPECT_NE(log.find("cancelled"), std::string::npos) << log;
    EXPECT_NE(log.find("1 of 4 slices are saved in " + out +
                       "; run the same command with "
                       "--resume"),
              std::string::npos)
        << log;
    const BpcReadResult partial = ReadBpc(out);
    EXPECT_FALSE(partial.finished);
    EXPECT_TRUE(partial.problems.empty());
    EXPECT_EQ(partial.measurement.slices.size(), 1u);
    const ToolRun resumed = Run("capture --quiet --resume --out " + out + common);
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    const Measurement got = LoadBpc(out);
    ASSERT_EQ(got.slices.size(), 4u);
    for (int k = 0; k < 4; ++k) {
      ASSERT_EQ(got.slices[k].samples.size(), expected.slices[k].samples.size());
      for (std::size_t i = 0; i < got.slices[k].samples.size(); ++i) {
        const Sample &x = got.slices[k].samples[i], &y = expected.slices[k].samples[i];
        ASSERT_EQ(x.rgb, y.rgb) << "slice " << k << " sample " << i;
        ASSERT_EQ(x.sigma, y.sigma);
        ASSERT_EQ(x.flags, y.flags);
      }
    }
  }
}

// RGL paints whose specular peaks clipped at the 1 ms minimum exposure before the ND filter
// stage (1,019 and 759 saturated samples at the reference geometry): now none clips.
TEST_F(CaptureCli, RglPaintPeaksNoLongerClip) {
  const fs::path data = brdf::test::DataDir();
  for (const char* paint : {"chm_orange_rgb", "chm_light_blue_rgb"}) {
    const std::string out = Path(std::string(paint) + ".bpc");
    const ToolRun r =
        Run("capture --material " + (data / "rgl" / (std::string(paint) + ".bsdf")).string() +
            " --sample p --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find(", 0 saturated, "), std::string::npos) << r.err;
    for (const Slice& s : LoadBpc(out).slices)
      for (const Sample& x : s.samples) ASSERT_EQ(x.flags & kFlagSaturated, 0) << paint;
  }
}

TEST_F(CaptureCli, WrongArgumentsGiveOneClearLineAndNonZeroExit) {
  const std::string out = " --out " + Path("bad.bpc");
  struct Case {
    std::string args, expect;
  };
  for (const Case& k : std::vector<Case>{
           {"--material gold --sample g --noise -1" + out, "--noise"},
           {"--material no_such_material --sample g" + out, "library"},
           {"--material gold --sample g --device usb:12" + out, "--device"},
           {"--material gold --sample g --device serial" + out, "--device"},
           {"--material gold --sample g --transport pigeon" + out, "--transport"},
           {"--sample g" + out, "--material"},
           {"--material gold --sample g --theta-in 0,95" + out, "--theta-in"},
           {"--material gold --sample g --exposure fast" + out, "--exposure"},
           {"--material gold --sample g --sim-fault explode:3" + out, "--sim-fault"},
           {"--material gold" + out, "--sample"},
       }) {
    const ToolRun r = Run("capture " + k.args);
    EXPECT_NE(r.exit_code, 0) << k.args;
    EXPECT_NE(r.err.find(k.expect), std::string::npos) << k.args << "\n" << r.err;
    EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
    EXPECT_FALSE(fs::exists(Path("bad.bpc"))) << k.args;
  }
}

TEST_F(CaptureCli, HelpShowsTheDefaultsOfTheCode) {
  const ToolRun r = Run("capture --help");
  ASSERT_EQ(r.exit_code, 0);
  const cli::CaptureOptions defaults;
  auto number = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  std::string theta_in;
  for (double t : defaults.geometry.theta_in_deg)
    theta_in += (theta_in.empty() ? "" : ",") + number(t);
  EXPECT_NE(r.out.find("--theta-in FLOAT=[" + theta_in + "]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--noise FLOAT=" + number(defaults.noise)), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--seed UINT=" + std::to_string(defaults.seed)), std::string::npos);
  EXPECT_NE(r.out.find("--device TEXT=" + defaults.device), std::string::npos);
  EXPECT_NE(r.out.find("--exposure TEXT=" + defaults.exposure), std::string::npos);
  EXPECT_NE(r.out.find("--theta-out-step FLOAT=" + number(defaults.geometry.theta_out_step_deg)),
            std::string::npos);
}

}  // namespace
}  // namespace brdf::device
