// Writing the 722 × 362 EXR and PNG of a K = 4 LUT: brdf::image_io (OpenEXR, libpng) side by
// side with the OpenImageIO path the exporter used before (reproduced here as the baseline).
// Both write atomically (temporary sibling, fsync, rename) into a temporary folder.
//   build/dev/bench/bench_image_io --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "brdf/core/file_util.h"
#include "brdf/image_io/image_io.h"

namespace {

using namespace brdf::image_io;

// A smooth lobe per 361 × 181 cell over a small diffuse floor: compresses like a LUT does.
const RgbImage& Composite() {
  static const RgbImage image = [] {
    RgbImage im;
    im.width = 722;
    im.height = 362;
    im.rgb.resize(static_cast<std::size_t>(im.width) * im.height * 3);
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const double u = (x % 361) / 360.0, v = (y % 181) / 180.0;
        const double lobe = 40.0 * std::exp(-(v * v) / 0.01) * (1.0 + 0.2 * std::cos(6.28 * u));
        for (int c = 0; c < 3; ++c)
          im.Pixel(x, y)[c] = static_cast<float>(0.05 * (c + 1) + lobe * (1.0 - 0.25 * c));
      }
    return im;
  }();
  return image;
}

std::vector<unsigned char> Bytes() {
  std::vector<unsigned char> out;
  for (float v : Composite().rgb)
    out.push_back(static_cast<unsigned char>(std::min(v, 1.0f) * 255));
  return out;
}

const std::string& Dir() {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() /
                   ("brdf-bench-image-io-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir;
}

// The exporter's OpenImageIO writer before brdf::image_io (commit ecb4ec8, export/src/exr.cpp).
void OiioWrite(const std::string& path, const char* format, const OIIO::ImageSpec& spec,
               OIIO::TypeDesc data_type, const void* data) {
  brdf::AtomicOutputPath out_path(path);
  auto out = OIIO::ImageOutput::create(format);
  if (!out || !out->open(out_path.temp_path(), spec) || !out->write_image(data_type, data) ||
      !out->close())
    throw std::runtime_error("OpenImageIO failed to write " + path);
  out.reset();
  out_path.Commit();
}

void OiioExr(bool half, bool zip) {
  const RgbImage& im = Composite();
  OIIO::ImageSpec spec(im.width, im.height, 3, half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B"};
  spec.attribute("compression", zip ? "zip" : "none");
  spec.attribute("Software", "bench");
  OiioWrite(Dir() + "/oiio.exr", "exr", spec, OIIO::TypeDesc::FLOAT, im.rgb.data());
}

void BM_ExrFloatZip_OpenExr(benchmark::State& state) {
  for (auto _ : state)
    WriteExrImage(Dir() + "/a.exr", Composite(), ExrPixelType::kFloat, ExrCompression::kZip,
                  {{"Software", "bench"}});
}
void BM_ExrFloatZip_Oiio(benchmark::State& state) {
  for (auto _ : state) OiioExr(false, true);
}
void BM_ExrHalfZip_OpenExr(benchmark::State& state) {
  for (auto _ : state)
    WriteExrImage(Dir() + "/a.exr", Composite(), ExrPixelType::kHalf, ExrCompression::kZip,
                  {{"Software", "bench"}});
}
void BM_ExrHalfZip_Oiio(benchmark::State& state) {
  for (auto _ : state) OiioExr(true, true);
}
void BM_ExrFloatNone_OpenExr(benchmark::State& state) {
  for (auto _ : state)
    WriteExrImage(Dir() + "/a.exr", Composite(), ExrPixelType::kFloat, ExrCompression::kNone,
                  {{"Software", "bench"}});
}
void BM_ExrFloatNone_Oiio(benchmark::State& state) {
  for (auto _ : state) OiioExr(false, false);
}
void BM_Png_Libpng(benchmark::State& state) {
  const std::vector<unsigned char> bytes = Bytes();
  for (auto _ : state) WritePng8(Dir() + "/a.png", 722, 362, bytes, 3, {{"Software", "bench"}});
}
void BM_Png_Oiio(benchmark::State& state) {
  const std::vector<unsigned char> bytes = Bytes();
  OIIO::ImageSpec spec(722, 362, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", 3);
  spec.attribute("Software", "bench");
  for (auto _ : state)
    OiioWrite(Dir() + "/oiio.png", "png", spec, OIIO::TypeDesc::UINT8, bytes.data());
}

#define BRDF_BENCH(name) BENCHMARK(name)->Unit(benchmark::kMillisecond)->UseRealTime()
BRDF_BENCH(BM_ExrFloatZip_OpenExr);
BRDF_BENCH(BM_ExrFloatZip_Oiio);
BRDF_BENCH(BM_ExrHalfZip_OpenExr);
BRDF_BENCH(BM_ExrHalfZip_Oiio);
BRDF_BENCH(BM_ExrFloatNone_OpenExr);
BRDF_BENCH(BM_ExrFloatNone_Oiio);
BRDF_BENCH(BM_Png_Libpng);
BRDF_BENCH(BM_Png_Oiio);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  std::filesystem::remove_all(Dir());
  return 0;
}
