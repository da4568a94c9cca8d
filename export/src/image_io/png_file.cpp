// 8-bit RGB PNG through libpng, see brdf/image_io/image_io.h.
#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/image_io/image_io.h"

namespace brdf::image_io {
namespace {

struct EncodeState {
  std::vector<unsigned char>* bytes;
  char message[256];
};

void AppendBytes(png_structp png, png_bytep data, png_size_t length) {
  auto* state = static_cast<EncodeState*>(png_get_io_ptr(png));
  state->bytes->insert(state->bytes->end(), data, data + length);
}

void NoFlush(png_structp) {}

// libpng reports errors by longjmp; the message is kept for the exception thrown afterwards.
void KeepError(png_structp png, png_const_charp message) {
  auto* state = static_cast<EncodeState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", message);
  png_longjmp(png, 1);
}

void IgnoreWarning(png_structp, png_const_charp) {}

// Encodes into `state->bytes`. Only trivially destructible locals live in this frame, because
// libpng leaves it with longjmp on error. Returns false on error (message in state).
bool Encode(EncodeState* state, int width, int height, png_bytepp rows, png_textp text,
            int text_count, int zlib_level, bool fast) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, state, KeepError, IgnoreWarning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, state, AppendBytes, NoFlush);
  png_set_compression_level(png, zlib_level);
  if (fast) {
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_strategy(png, Z_RLE);
  }
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (text_count > 0) png_set_text(png, info, text, text_count);
  png_set_rows(png, info, rows);
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

void WritePng8(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb8, int zlib_level, const StringAttributes& text,
               bool fast) {
  if (width < 1 || height < 1 || rgb8.size() != static_cast<std::size_t>(width) * height * 3)
    throw InvalidArgument(fmt::format("{}: PNG: inconsistent image {} × {} with {} bytes", path,
                                      width, height, rgb8.size()));
  if (zlib_level < 0 || zlib_level > 9)
    throw InvalidArgument(
        fmt::format("{}: PNG: zlib level must be 0 to 9, got {}", path, zlib_level));
  // libpng takes non-const strings and row pointers; these copies keep the caller's data const.
  std::vector<std::string> keys, values;
  for (const auto& [key, value] : text) {
    if (key.empty() || key.size() > 79)
      throw InvalidArgument(path + ": PNG text keyword must have 1 to 79 characters: '" + key +
                            "'");
    keys.push_back(key);
    values.push_back(value);
  }
  std::vector<png_text> chunks(text.size());
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    chunks[i] = png_text{};
    chunks[i].compression = PNG_TEXT_COMPRESSION_NONE;
    chunks[i].key = keys[i].data();
    chunks[i].text = values[i].data();
    chunks[i].text_length = values[i].size();
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    rows[y] = const_cast<png_bytep>(rgb8.data() + static_cast<std::size_t>(y) * width * 3);
  std::vector<unsigned char> bytes;
  EncodeState state{&bytes, "libpng could not allocate its state"};
  if (!Encode(&state, width, height, rows.data(), chunks.data(), static_cast<int>(chunks.size()),
              zlib_level, fast))
    throw IoError(path + ": encoding the PNG failed: " + state.message);
  WriteFileAtomically(path,
                      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace brdf::image_io
