// `brdf preview` on inputs no real material or map has, run as a user runs it: a capture with
// every value negated finishes in about the intact file's time, environment maps with NaN,
// infinite or negative texels (written by OpenImageIO through Debian's Python) are reported in
// one line or refused, and the peak memory of a render, measured by the kernel (getrusage of the
// child), stays within the documented bytes per output pixel.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

class PreviewBoundsCli : public ToolTest {
 protected:
  // Runs Debian's Python (numpy, OpenImageIO) on a script; fails the test if it fails.
  void Python(const std::string& script) const {
    const fs::path file = dir_ / "script.py";
    WriteText(file, script);
    const std::string cmd = std::string(BRDF_PYTHON3) + " " + Quote(file);
    ASSERT_EQ(std::system(cmd.c_str()), 0) << script;
  }
  // Runs `brdf <args>` under a 60 s `timeout` (exit 124 when it fires) and returns the wall time.
  double Seconds(const std::string& args, ToolRun* r) const {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string cmd =
        "timeout 60 " + std::string(BRDF_TOOL) + " " + args + " 2>" + Quote(dir_ / "err.txt");
    const int status = std::system(cmd.c_str());
    r->exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r->err = ReadAll(dir_ / "err.txt");
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
};

// Every sample's RGB multiplied by `factor`, chunk CRCs recomputed (the .bpc layout of
// docs/design.md §3: 12-byte file header, chunks of a 24-byte header and a payload; a slice's
// payload holds its sample count at byte 16, the record size at 28 and the records from 32,
// RGB as float32 at bytes 16, 20, 24 of a record).
std::string ScaleCaptureScript(const fs::path& in, const fs::path& out, double factor) {
  return "import struct, zlib\n"
         "crc = lambda d: zlib.crc32(d) & 0xFFFFFFFF\n"
         "data = open('" +
         in.string() +
         "', 'rb').read()\n"
         "out, pos = bytearray(data[:12]), 12\n"
         "while pos + 24 <= len(data):\n"
         "    tag = data[pos:pos + 4]\n"
         "    index, size = struct.unpack_from('<IQ', data, pos + 4)\n"
         "    p = bytearray(data[pos + 24:pos + 24 + size])\n"
         "    if tag == b'SLCE':\n"
         "        count, rec = struct.unpack_from('<Q', p, 16)[0], struct.unpack_from('<I', p, "
         "28)[0]\n"
         "        for k in range(count):\n"
         "            for c in range(3):\n"
         "                o = 32 + k * rec + 16 + 4 * c\n"
         "                struct.pack_into('<f', p, o, struct.unpack_from('<f', p, o)[0] * " +
         std::to_string(factor) +
         ")\n"
         "    head = tag + struct.pack('<IQI', index, len(p), crc(bytes(p)))\n"
         "    out += head + struct.pack('<I', crc(head)) + p\n"
         "    pos += 24 + size\n"
         "out += data[pos:]\n"
         "open('" +
         out.string() + "', 'wb').write(bytes(out))\n";
}

// The hierarchical refinement's bound does not depend on the values' sign: a negated capture
// either previews in about the intact file's time or is refused at once (a rule that refuses
// such values is free to), never runs for minutes.
TEST_F(PreviewBoundsCli, ANegatedCaptureFinishesInTheIntactFilesTime) {
  ToolRun r = Run("capture --device sim --material gold --sample s --noise 0 --quiet --out " +
                  Quote(dir_ / "cap.bpc"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Python(ScaleCaptureScript(dir_ / "cap.bpc", dir_ / "neg.bpc", -1.0));
  const double intact = Seconds(
      "preview " + Quote(dir_ / "cap.bpc") + " --size 128 --quiet --out " + Quote(dir_ / "a.exr"),
      &r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The timeout keeps the broken build from running for its eight minutes.
  const double negated = Seconds(
      "preview " + Quote(dir_ / "neg.bpc") + " --size 128 --quiet --out " + Quote(dir_ / "n.exr"),
      &r);
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.exit_code << r.err;
  EXPECT_LT(negated, 3.0 * intact + 2.0) << "intact " << intact << " s";
}

// NaN, ±Inf and negative texels are counted in one line and taken as black; a half-float EXR
// whose sun overflowed to +Inf says so; a map with no usable texel is refused in one line.
TEST_F(PreviewBoundsCli, BadMapTexelsAreCountedAndAMapWithoutUsableTexelsIsRefused) {
  Python(
      "import numpy as np, OpenImageIO as oiio\n"
      "def write(name, px, fmt):\n"
      "    o = oiio.ImageOutput.create(name)\n"
      "    o.open(name, oiio.ImageSpec(px.shape[1], px.shape[0], 3, fmt))\n"
      "    o.write_image(px)\n"
      "    o.close()\n"
      "d = '" +
      dir_.string() +
      "/'\n"
      "px = np.full((32, 64, 3), 0.5, np.float32)\n"
      "px[1, 2, 0] = np.nan; px[3, 4, 1] = np.nan\n"
      "px[5, 6, :] = np.inf; px[7, 8, 2] = -np.inf\n"
      "px[9, 10, 1] = -0.25; px[9, 11, 0] = -3; px[9, 12, 2] = -1e-3\n"
      "write(d + 'bad.exr', px, 'float')\n"
      "sun = np.full((32, 64, 3), 0.5, np.float32)\n"
      "sun[4:6, 10:12, :] = 1e6\n"  // beyond half's 65504: +Inf in the file
      "write(d + 'sun.exr', sun, 'half')\n"
      "write(d + 'inf.exr', np.full((32, 64, 3), np.inf, np.float32), 'half')\n");
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const std::string white = Quote(dir_ / "white.json");
  ToolRun r = Run("preview " + white + " --env " + Quote(dir_ / "bad.exr") +
                  " --size 16 --quiet --out " + Quote(dir_ / "b.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_EQ(r.err, (dir_ / "bad.exr").string() +
                       ": warning: 7 of 2048 texels hold NaN, infinite or negative values and are "
                       "taken as black (2 NaN, 1 +Inf (a half-float value beyond 65504 overflows "
                       "to +Inf), 1 -Inf, 3 negative)\n");
  r = Run("preview " + white + " --env " + Quote(dir_ / "sun.exr") + " --size 16 --quiet --out " +
          Quote(dir_ / "s.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_NE(r.err.find(": warning: 4 of 2048 texels hold"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4 +Inf (a half-float value beyond 65504"), std::string::npos) << r.err;
  r = Run("preview " + white + " --env " + Quote(dir_ / "inf.exr") + " --size 16 --quiet --out " +
          Quote(dir_ / "i.exr"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ASSERT_EQ(r.ErrLines().size(), 1u) << r.err;
  EXPECT_NE(r.err.find((dir_ / "inf.exr").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expected texels with a finite radiance >= 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("all 2048 hold NaN, infinite or negative values (2048 +Inf"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "i.exr"));
}

// Peak resident memory (bytes) of `brdf <args>`, measured by the kernel for that one child
// (wait4's rusage), with stdout and stderr discarded.
std::uint64_t PeakRssBytes(const std::vector<std::string>& args, int* exit_code) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    std::string tool = BRDF_TOOL;
    argv.push_back(tool.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    ::execv(tool.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // ru_maxrss is in KiB on Linux
}

// Memory in proportion to the work: the hierarchical preview of a 1024² image costs at most
// 64 bytes per output pixel more than the same preview at 16² (the map, its hierarchy, the
// libraries and the threads' state, which do not depend on the image size). Before: about 205.
TEST_F(PreviewBoundsCli, PeakMemoryIsAtMost64BytesPerOutputPixel) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  auto peak = [&](int size) {
    int code = -1;
    const std::uint64_t bytes =
        PeakRssBytes({"preview", (dir_ / "white.json").string(), "--size", std::to_string(size),
                      "--quiet", "--force", "--out", (dir_ / "p.exr").string()},
                     &code);
    EXPECT_EQ(code, 0) << size;
    return bytes;
  };
  const std::uint64_t small = peak(16), large = peak(1024);
  const double per_pixel =
      (static_cast<double>(large) - static_cast<double>(small)) / (1024.0 * 1024.0);
  EXPECT_LE(per_pixel, 64.0) << "16²: " << small << " B, 1024²: " << large << " B";
  EXPECT_GT(per_pixel, 12.0) << "the image itself (12 bytes a pixel) must show in the measurement";
  // The brute-force reference at 16 subdivisions keeps no table of its directions (before: 48
  // bytes per map pixel and subdivision², 400 MB for this 256 × 128 map, 6 GB for 1024 × 512);
  // its one-pixel image stays within 64 MB of the 16² hierarchical run's footprint.
  Python(
      "import numpy as np, OpenImageIO as oiio\n"
      "o = oiio.ImageOutput.create('" +
      (dir_ / "grey.exr").string() +
      "')\n"
      "o.open('" +
      (dir_ / "grey.exr").string() +
      "', oiio.ImageSpec(256, 128, 3, 'float'))\n"
      "o.write_image(np.full((128, 256, 3), 0.5, np.float32))\n"
      "o.close()\n");
  int code = -1;
  const std::uint64_t quadrature =
      PeakRssBytes({"preview", (dir_ / "white.json").string(), "--size", "1", "--estimator",
                    "quadrature", "--subdivisions", "16", "--env", (dir_ / "grey.exr").string(),
                    "--quiet", "--force", "--out", (dir_ / "q.exr").string()},
                   &code);
  EXPECT_EQ(code, 0);
  EXPECT_LT(quadrature, small + (64u << 20)) << quadrature;
}

// A request beyond what the process may take is refused in one line before any work: here under
// a 1.5 GB address-space limit, an 8192² preview (about 3.3 GB by EstimatedPeakBytes).
TEST_F(PreviewBoundsCli, ARenderThatCannotFitIsRefusedInOneLineBeforeAnyWork) {
  std::ofstream(dir_ / "white.json") << R"({"model": "lambert", "rho": 1.0})";
  const auto t0 = std::chrono::steady_clock::now();
  const std::string cmd = "ulimit -v 1500000; " + std::string(BRDF_TOOL) + " preview " +
                          Quote(dir_ / "white.json") + " --size 8192 --quiet --out " +
                          Quote(dir_ / "big.exr") + " 2>" + Quote(dir_ / "err.txt");
  const int status = std::system(cmd.c_str());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string err = ReadAll(dir_ / "err.txt");
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("8192 × 8192 image"), std::string::npos) << err;
  EXPECT_NE(err.find("of memory, more than the"), std::string::npos) << err;
  EXPECT_NE(err.find("address-space limit"), std::string::npos) << err;
  EXPECT_LT(seconds, 10.0);
  EXPECT_FALSE(fs::exists(dir_ / "big.exr"));
}

}  // namespace
}  // namespace brdf::tooltest
