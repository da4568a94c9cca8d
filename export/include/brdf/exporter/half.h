// IEEE 754 binary16 ("half") conversions shared by the texture writers: the BC6H encoder
// (brdf/exporter/bc6h.h) and the engine kit's RGBA16F volumes (brdf/engines/engine_export.h).
#pragma once

#include <cstdint>

namespace brdf::exporter {

// Binary16 bits of any float, rounded to nearest even; overflow (from 65520 up) becomes ±inf,
// NaN stays a quiet NaN, magnitudes below half the smallest subnormal 2^-25 become ±0.
std::uint16_t FloatToHalf(float value);
// The float a binary16 bit pattern holds (exact: every half is a float).
float HalfToFloat(std::uint16_t half);

}  // namespace brdf::exporter
