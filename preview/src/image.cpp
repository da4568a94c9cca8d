// Preview images: comparison, side-by-side panels, the tone map and file output.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/measurement.h"
#include "brdf/image_io/image_io.h"
#include "brdf/preview/preview.h"
#include "preview_internal.h"

namespace brdf::preview {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

void CheckImage(const PreviewImage& image, const char* what) {
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  if (image.width < 1 || image.height < 1 || image.rgb.size() != pixels * 3 ||
      (!image.object.empty() && image.object.size() != pixels))
    throw InvalidArgument(std::string("preview: inconsistent ") + what + " image");
}

}  // namespace

ImageDifference CompareImages(const PreviewImage& image, const PreviewImage& reference) {
  CheckImage(image, "compared");
  CheckImage(reference, "reference");
  if (image.width != reference.width || image.height != reference.height)
    throw InvalidArgument("preview: cannot compare a " + std::to_string(image.width) + " × " +
                          std::to_string(image.height) + " image with a " +
                          std::to_string(reference.width) + " × " +
                          std::to_string(reference.height) + " one");
  ImageDifference d;
  double squares = 0.0, reference_sum = 0.0;
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  for (std::size_t p = 0; p < pixels; ++p) {
    const bool in_image = image.object.empty() || image.object[p];
    const bool in_reference = reference.object.empty() || reference.object[p];
    if (!in_image && !in_reference) continue;
    ++d.pixels;
    for (int c = 0; c < 3; ++c) {
      const double diff = static_cast<double>(image.rgb[3 * p + c]) - reference.rgb[3 * p + c];
      squares += diff * diff;
      reference_sum += reference.rgb[3 * p + c];
      d.max_abs = std::max(d.max_abs, std::fabs(diff));
    }
  }
  if (d.pixels == 0) return d;
  const double n = 3.0 * static_cast<double>(d.pixels);
  d.rms = std::sqrt(squares / n);
  const double mean = reference_sum / n;
  d.relative_rms = mean > 0.0 ? d.rms / mean : (d.rms > 0.0 ? INFINITY : 0.0);
  return d;
}

PreviewImage SideBySide(const PreviewImage& a, const PreviewImage& b, double difference_gain) {
  CheckImage(a, "left");
  CheckImage(b, "right");
  if (a.width != b.width || a.height != b.height)
    throw InvalidArgument("preview: side-by-side images must have the same size");
  constexpr int kGutter = 4;
  PreviewImage out;
  out.width = 3 * a.width + 2 * kGutter;
  out.height = a.height;
  out.rgb.assign(static_cast<std::size_t>(out.width) * out.height * 3, 0.0f);
  out.object.assign(static_cast<std::size_t>(out.width) * out.height, 0);
  out.samples_per_pixel = std::min(a.samples_per_pixel, b.samples_per_pixel);
  out.seconds = a.seconds + b.seconds;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const std::size_t src = static_cast<std::size_t>(y) * a.width + x;
      const float* pa = &a.rgb[3 * src];
      const float* pb = &b.rgb[3 * src];
      const bool oa = a.object.empty() || a.object[src];
      const bool ob = b.object.empty() || b.object[src];
      auto put = [&](int panel, const float rgb[3], bool object) {
        const std::size_t dst =
            static_cast<std::size_t>(y) * out.width + panel * (a.width + kGutter) + x;
        std::copy(rgb, rgb + 3, &out.rgb[3 * dst]);
        out.object[dst] = object ? 1 : 0;
      };
      put(0, pa, oa);
      put(1, pb, ob);
      const double dl =
          detail::Luminance({pa[0] - double(pb[0]), pa[1] - double(pb[1]), pa[2] - double(pb[2])});
      const float mag = static_cast<float>(std::fabs(dl) * difference_gain);
      const float diff[3] = {dl > 0 ? mag : 0.0f, 0.0f, dl < 0 ? mag : 0.0f};
      put(2, diff, oa || ob);
    }
  return out;
}

std::vector<std::uint8_t> ToneMap(const PreviewImage& image, double exposure_ev,
                                  ToneMapCurve curve) {
  CheckImage(image, "tone-mapped");
  const double scale = std::exp2(exposure_ev);
  std::vector<std::uint8_t> out(image.rgb.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    double x = image.rgb[i] > 0.0f ? image.rgb[i] * scale : 0.0;  // NaN, negatives → black
    if (curve == ToneMapCurve::kReinhard) x = std::isinf(x) ? 1.0 : x / (1.0 + x);
    x = std::min(x, 1.0);
    const double encoded = x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
    out[i] = static_cast<std::uint8_t>(std::lround(255.0 * encoded));
  }
  return out;
}

void WritePreviewImage(const std::string& path, const PreviewImage& image, double exposure_ev,
                       ToneMapCurve curve,
                       const std::vector<std::pair<std::string, std::string>>& attributes) {
  CheckImage(image, "written");
  std::vector<std::pair<std::string, std::string>> attrs(attributes.begin(), attributes.end());
  attrs.emplace_back("Software", std::string("brdf-toolchain ") + SoftwareVersion());
  if (EndsWith(path, ".png")) {
    image_io::WritePng8(path, image.width, image.height, ToneMap(image, exposure_ev, curve), 3,
                        attrs);
  } else if (EndsWith(path, ".exr")) {
    image_io::RgbImage rgb;
    rgb.width = image.width;
    rgb.height = image.height;
    rgb.rgb = image.rgb;
    attrs.emplace_back("brdf:samples_per_pixel", std::to_string(image.samples_per_pixel));
    image_io::WriteExrImage(path, rgb, image_io::ExrPixelType::kFloat,
                            image_io::ExrCompression::kZip, attrs);
  } else {
    throw InvalidArgument(path + ": the preview is written as .exr (linear HDR) or .png " +
                          "(tone-mapped); the extension names which");
  }
}

namespace detail {

// Through brdf::image_io: .exr by OpenEXR, .hdr by the OpenImageIO module it loads on first use.
RgbImage ReadEnvironmentImage(const std::string& path) {
  if (!EndsWith(path, ".exr") && !EndsWith(path, ".hdr"))
    throw InvalidArgument(path + ": an environment map must be an equirectangular .exr or .hdr");
  image_io::RgbImage image =
      EndsWith(path, ".exr") ? image_io::ReadExrImage(path).image : image_io::ReadRgbImage(path);
  return {image.width, image.height, std::move(image.rgb)};
}

}  // namespace detail
}  // namespace brdf::preview
