#include "brdf/core/text_format.h"

#include <cstdio>

namespace brdf {
namespace {

std::string Format(const char* format, double value) {
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

std::string Hex32Text(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", value);
  return text;
}

std::string ExactNumberText(double value) { return Format("%.17g", value); }
std::string ShortNumberText(double value) { return Format("%g", value); }

std::string ShortNumberListText(const std::vector<double>& values) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : ", ") + ShortNumberText(v);
  return out;
}

}  // namespace brdf
