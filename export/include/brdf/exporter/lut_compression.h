// Compressed LUTs (`--compress bc6h`): the BC6H payload and the certified error it carries
// (docs/design.md §7).
//
// A compressed LUT is encoded with EncodeBc6hVolume (bc6h.h), decoded again exactly as a GPU
// samples it, and compared texel by texel with the float LUT it came from. The error of a texel
// is e = max_c |d_c − r_c| / max(max_c r_c, 10^−4·R, 2^−14) with r the LUT clamped to
// [0, 65504] and R its largest value (metadata.h's ErrorStatistics); texels are
// split by their outgoing polar angle θout (cos θout = cos θin·cos θd − sin θin·sin θd·cos φd,
// the specular frame of docs/design.md §5 undone) into the measured range θout ≤ θb and the
// filled range θout > θb (the extrapolation and the below-horizon edge extension). Max, p99 and
// median of each range (nearest-rank percentiles) go into the sidecar, and `brdf info` prints
// them.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/metadata.h"

namespace brdf::exporter {

// kNone: RGB9E5 KTX2/DDS; kBc6h: BC6H KTX2/DDS; kCompact: the compact form (compact_lut.h), one
// .brdfc file in place of the KTX2 and DDS.
enum class LutCompression { kNone, kBc6h, kCompact };

// "none", "bc6h" or "compact". Throws InvalidArgument naming the value and the known ones.
LutCompression ParseLutCompression(std::string_view text);

// θout in degrees of LUT texel (row j = θd in degrees, column i = φd in degrees) of the slice at
// θin.
double TexelThetaOutDeg(double theta_in_deg, int j, int i);

// The certified error of `decoded` (a LUT's K·181·361·3 floats in Lut order) against
// `reference`, with θb splitting the measured from the filled range (90° when nothing was
// extrapolated). `format` and the byte counts are left for the caller. Throws InvalidArgument
// on a size mismatch.
CertifiedError MeasureCompressionError(const Lut& reference, const std::vector<float>& decoded,
                                       double theta_b_deg);

// MeasureCompressionError of RGB9E5 words decoded into `decoded`, recorded as the "rgb9e5"
// format whose texture holds `bytes` (a LUT's packed volume, or a whole atlas for one of its
// cells): what `--max-error` compares when it keeps RGB9E5.
CertifiedError MeasureRgb9e5Error(const Lut& reference, const std::vector<float>& decoded,
                                  double theta_b_deg, std::uint64_t bytes);

struct CompressedLut {
  Bc6hVolume blocks;
  CertifiedError error;  // complete: format "bc6h_ufloat", bytes, rgb9e5_bytes
};

// Encodes the LUT as BC6H on `jobs` threads (0 = one per core) and measures the result. Throws
// InvalidArgument for an unexportable LUT (ValidateLutForExport).
CompressedLut CompressLutBc6h(const Lut& lut, double theta_b_deg, int jobs = 1);

}  // namespace brdf::exporter
