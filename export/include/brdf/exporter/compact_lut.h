// The compact form of a LUT (`--compress compact`, docs/formats/compact.md, docs/design.md §7):
// an adaptive log grid per slice, 20–600× smaller than RGB9E5, with a certified error.
//
// What it is. Each θin slice k of the LUT (docs/design.md §5: 361 × 181 texels over the
// specular frame, φd = i°, θd = j°) keeps the texels of a few of its rows, rows_k (θd values,
// ascending, always 0 and 180), and a few of its columns, cols_k (φd values, ascending, always 0
// and the last column of the domain), and stores at each kept texel
//     g = log2(f/S + ε)   per channel, as a half float,
// S the LUT's largest value (clamped to [0, 65504]) and ε = 10⁻⁵. A mirrored LUT (isotropic
// data symmetric about the plane of incidence, f(φd) = f(360° − φd)) keeps columns of 0…180°
// only and reads φd > 180° at 360° − φd.
//
// How it is read (the one rule of CompactLut::SampleSlice, the GLSL decoder and `brdf eval`).
// Two piecewise-linear maps send a slice's θd and φd to grid coordinates: m(x) = p + (x −
// a_p)/(a_{p+1} − a_p) for a_p ≤ x ≤ a_{p+1} of the kept list (a mirrored column list is read at
// min(φd, 360° − φd)). Both maps are tabulated at whole degrees (181 and 361 entries per slice)
// and read linearly between, which is exact since their breakpoints are whole degrees. With
// p0 = min(floor(m), n − 2) and t = m − p0 on each axis, the grid's four log values around (mθ,
// mφ) are interpolated bilinearly, then f = S·max(2^g − ε, 0). θin is read as the LUT is:
// linear between the two nearest slices at the same (θd, φd), clamped at both ends
// (Lut::SampleAngles, reciprocity included).
//
// How it is built (BuildCompactLut). Greedily per slice, from a coarse grid (every 30°): the
// texel with the largest error over the measured range (θout ≤ θb, the certified-error measure
// of lut_compression.h, on the half-quantized values exactly as decoded) gets a new row or a new
// column through its gap (the midpoint of the gap, or the texel's own row or column, whichever
// leaves the slice's error lower), until the slice's largest error is at most the target or the
// grid would exceed kCompactMaxSliceTexels. The grid values are the LUT's own texels, so the
// form interpolates the LUT in the log domain, where lobes are nearly quadratic and the dark
// tails nearly linear. Deterministic; slices are independent and built on `jobs` threads.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/lut.h"
#include "brdf/exporter/metadata.h"

namespace brdf::exporter {

inline constexpr float kCompactEpsilon = 1e-5f;
// A slice grid stops growing at this many texels (a quarter of the slice): beyond it the form
// is no longer compact and the build reports the error it reached.
inline constexpr int kCompactMaxSliceTexels = 361 * 181 / 4;
// The default target of `--compress compact` without `--max-error`: 2 % on the measured range.
inline constexpr double kCompactDefaultMaxError = 0.02;

struct CompactLut {
  std::vector<double> theta_in_deg;  // K values, k·Δin
  bool mirrored = false;             // columns cover φd 0…180°, read at min(φd, 360° − φd)
  float scale = 0;                   // S
  float epsilon = kCompactEpsilon;   // ε
  // Per slice: kept θd rows and φd columns (whole degrees), and rows × cols × 3 half floats
  // (row-major, columns fastest, then R, G, B) of g = log2(f/S + ε).
  std::vector<std::vector<std::uint16_t>> rows, cols, values;

  int slices() const { return static_cast<int>(theta_in_deg.size()); }
  // 180 (mirrored) or 360: the last column a column list ends with.
  int LastColumn() const { return mirrored ? 180 : 360; }
  // Bytes of the stored payload: header, θin list, lists and grid values (the container of
  // docs/formats/compact.md without its embedded sidecar).
  std::uint64_t PayloadBytes() const;
  // The grid texels over all slices.
  std::uint64_t GridTexels() const;

  // The whole-degree map tables of slice k as the decoders use them: rows → 181 entries (θd =
  // 0…180°), columns → 361 entries (φd = 0…360°, mirrored ones folded).
  std::vector<float> RowMap(int k) const;
  std::vector<float> ColumnMap(int k) const;
  // The value of slice k at (θd, φd) in degrees (θd clamped to [0, 180], φd to [0, 360]).
  std::array<float, 3> SampleSlice(int k, double theta_d_deg, double phi_d_deg) const;
  // Every texel centre of the LUT decoded (K·181·361·3 floats in Lut order): what the
  // certified error is measured on.
  std::vector<float> DecodeTexels() const;
  // The evaluation rule of Lut::SampleAngles (reciprocity, slice interpolation, clamping).
  std::array<float, 3> SampleAngles(double theta_in_deg, double theta_out_deg,
                                    double phi_out_deg) const;
};

struct CompactBuild {
  CompactLut compact;
  CertifiedError error;  // format "compact_log_grid", bytes = PayloadBytes()
  bool met_target = false;
};

// Builds the compact form aiming at `target_max_error` (a fraction, on the measured range θout ≤
// θb) and certifies it with MeasureCompressionError on DecodeTexels(). Throws InvalidArgument
// for an unexportable LUT or a target outside (0, 1).
CompactBuild BuildCompactLut(const Lut& lut, double theta_b_deg, double target_max_error,
                             int jobs = 1);

// The container (docs/formats/compact.md): magic "BRDFCLUT", the payload, then the sidecar JSON
// text (may be empty).
std::string SerializeCompactLut(const CompactLut& compact, const std::string& sidecar_json);
// CRC-32 of the payload bytes as SerializeCompactLut lays them out (what the sidecar records).
std::uint32_t CompactPayloadCrc32(const CompactLut& compact);
void WriteCompactLut(const std::string& path, const CompactLut& compact,
                     const std::string& sidecar_json);

struct LoadedCompact {
  CompactLut compact;
  std::string sidecar_json;
};
// True when `bytes` start with the container's magic.
bool IsCompactLutFile(const std::uint8_t* bytes, std::size_t size);
// Parses a container; every field checked, errors name `file`, the byte and both values.
// Throws FormatError.
LoadedCompact ParseCompactLut(const std::vector<std::uint8_t>& bytes, const std::string& file);
// Reads one (at most 64 MiB). Throws IoError / FormatError.
LoadedCompact ReadCompactLutFile(const std::string& path);

// A compact LUT as a BrdfSource (as LutBrdf is for a LUT): `brdf eval` of a .brdfc file.
class CompactBrdf final : public BrdfSource {
 public:
  CompactBrdf(CompactLut compact, std::string name)
      : compact_(std::move(compact)), name_(std::move(name)) {}
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  std::string Name() const override { return name_; }
  const CompactLut& compact() const { return compact_; }

 private:
  CompactLut compact_;
  std::string name_;
};

}  // namespace brdf::exporter
