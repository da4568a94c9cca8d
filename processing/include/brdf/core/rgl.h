// RGL-EPFL measured materials: the `.bsdf` "tensor file" and its evaluation.
//
// The RGL material database (Dupuy & Jakob 2018, "An Adaptive Parameterization for Efficient
// Material Acquisition and Rendering") stores each material as a tensor file: a small header
// naming typed, C-ordered arrays ("fields") at absolute byte offsets. The BRDF is not a plain
// table over directions. Each incidence slice θi stores a VNDF (the distribution of visible
// microfacet normals seen from ωi) as a density on the unit square, and the RGB reflectance
// is tabulated in the *warped* space of that density, so the table resolution follows the
// lobe. To evaluate f_r(ωi, ωo):
//   1. h = normalize(ωi + ωo), mapped to the unit square by u(θ) = √(θ / (π/2)),
//      u(φ) = (φ + π) / 2π, with φ taken relative to φi for isotropic files;
//   2. that point is pushed through the inverse of the VNDF warp (marginal CDF along φ,
//      conditional CDF along θ, each incidence slice normalised separately and blended
//      linearly in θi) to find the warped-space position s;
//   3. f_r·cosθo = rgb(s) · ndf(h) / (4 · σ(ωi)), negative (out-of-gamut) RGB clipped to 0;
//      when the file's `jacobian` flag is 0 the table already holds f_r·cosθo and the
//      ndf/σ factor is omitted (as Mitsuba 3's `measured` plugin does).
// This follows the published reference loader rgl-epfl/brdf-loader (powitacq_rgb); the
// implementation here is our own, in double precision, and agrees with an independent NumPy
// oracle (tests/python/rgl_oracle.py) to ~1e-11 relative; the reference loader itself, in
// float, differs from both by its rounding (≤ 5e-5 relative, ≤ 5e-4 at grazing angles).
//
// Files are read whole (they are ~0.7–1 MB; anisotropic ones a few tens of MB) and refused
// before any allocation when larger than kMaxRglFileBytes. Every count, offset and dimension
// is checked against the file size; problems are FormatErrors naming the file, the byte
// offset, what was expected and what was found.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/brdf_source.h"

namespace brdf {

// Largest tensor file accepted (checked before reading).
inline constexpr std::uint64_t kMaxRglFileBytes = 512ull << 20;

// Element types of a tensor file field (the numbering is the file's).
enum class TensorDtype : std::uint8_t {
  kUInt8 = 1,
  kInt8 = 2,
  kUInt16 = 3,
  kInt16 = 4,
  kUInt32 = 5,
  kInt32 = 6,
  kUInt64 = 7,
  kInt64 = 8,
  kFloat16 = 9,
  kFloat32 = 10,
  kFloat64 = 11,
};

// "uint8", "float32", ...; "dtype <n>" for numbers outside the table.
std::string TensorDtypeName(TensorDtype dtype);
// Bytes per element; 0 for numbers outside the table.
std::size_t TensorDtypeSize(TensorDtype dtype);

// One field of a parsed tensor file. The data lies at [data_offset, data_offset + data_bytes)
// of the file, C order (last dimension contiguous), little-endian.
struct TensorField {
  std::string name;
  TensorDtype dtype = TensorDtype::kUInt8;
  std::vector<std::uint64_t> shape;  // rank = shape.size(); rank 0 is one element
  std::uint64_t data_offset = 0;
  std::uint64_t data_bytes = 0;
  std::uint64_t header_offset = 0;  // where this field's header entry starts (for messages)

  std::uint64_t element_count() const;
  std::string ShapeString() const;  // "[1, 8, 3, 32, 32]"
};

// A tensor file held in memory: header parsed and checked, data not yet interpreted.
class TensorFile {
 public:
  // Parses `bytes` (the whole file). `file` names the source in error messages.
  // Throws FormatError (bad magic or version, truncated header, unknown dtype, a field whose
  // data lies outside the file, duplicate field names, a name that is not UTF-8).
  static TensorFile Parse(std::vector<std::uint8_t> bytes, std::string file);
  // Reads and parses a file; IoError if unreadable, FormatError as above or when the file is
  // larger than `max_bytes`.
  static TensorFile Read(const std::string& path, std::uint64_t max_bytes = kMaxRglFileBytes);

  const std::string& file() const { return file_; }
  std::uint64_t size_bytes() const { return bytes_.size(); }
  const std::vector<TensorField>& fields() const { return fields_; }
  // nullptr when there is no field of that name.
  const TensorField* Find(std::string_view name) const;
  // The field, or a FormatError "field '<name>': expected present, got missing".
  const TensorField& Require(std::string_view name) const;
  // The raw bytes of a field's data.
  std::span<const std::uint8_t> Data(const TensorField& field) const;
  // The field's elements as float; FormatError unless its dtype is float32.
  std::vector<float> Float32(const TensorField& field) const;

 private:
  std::string file_;
  std::vector<std::uint8_t> bytes_;
  std::vector<TensorField> fields_;
};

// One field to write with EncodeTensorFile: `data` holds the C-ordered little-endian
// elements (element_count × dtype size bytes).
struct TensorFieldData {
  std::string name;
  TensorDtype dtype = TensorDtype::kFloat32;
  std::vector<std::uint64_t> shape;
  std::string data;
};

// The bytes of a version 1.0 tensor file holding `fields` in order, data blocks 8-byte
// aligned after the header (the layout of the RGL files). Used by tests and the fuzzing seed
// generator; throws InvalidArgument when a field's data size does not match its shape.
std::string EncodeTensorFile(std::span<const TensorFieldData> fields);

// What an RGL file declares, for `brdf info` and metadata.
struct RglInfo {
  std::string description;          // the file's `description` text (UTF-8)
  std::vector<double> theta_i_rad;  // incidence slices, radians, increasing
  std::vector<double> phi_i_rad;    // one entry (0) for isotropic files
  bool isotropic = true;            // phi_i has at most 2 entries (as the reference loader)
  bool jacobian = true;             // the `jacobian` flag (see the class comment)
  int vndf_theta_res = 0;           // VNDF grid: vertices along u(θ) and u(φ)
  int vndf_phi_res = 0;
  int rgb_res = 0;               // RGB table: rgb_res × rgb_res per slice and channel
  std::uint64_t rgb_values = 0;  // all RGB entries, and how many are negative
  std::uint64_t negative_rgb_values = 0;
};

class RglTabulatedBrdf;

// QuadratureApproximation returns no table whose self-check (RglTabulatedBrdf::
// self_check_p99_error) exceeds this: the preview then evaluates the file exactly. 14 of the
// 18 real files check at 0.5–3.4 % (cc_ibiza_sunset 0.9 %, chm_light_blue 3.4 %); chm_mint
// (15 %), chm_orange (8 %), cc_green_malachite (6 %) and ilm_solo_m_68 (5.5 %) have RGB tables
// with creases the interpolation cannot follow (mostly at grazing incidence) and are declined:
// with its table chm_mint's preview was 2.3 % off the brute force instead of 0.8 %.
inline constexpr double kRglApproximationMaxP99Error = 0.05;

// How finely RglBrdf::Tabulate samples (see RglTabulatedBrdf); the defaults are what
// QuadratureApproximation uses and what the stated errors were measured with.
struct RglTabulationSettings {
  // Incidence samples per interval of theta_i: doubled from 1 until linear interpolation
  // predicts the new midpoints within this relative (weighted RMS) error, at most
  // max_samples_per_interval.
  double incidence_tolerance = 0.002;
  int max_samples_per_interval = 8;
  // Table cells per VNDF cell along u(θm) and along u(φm − φi): enough that one table cell
  // spans at most 1 / cells_per_rgb_cell of an RGB cell in warped space (in every slice), from
  // 1 to max_cells_per_vndf_cell.
  double cells_per_rgb_cell = 1.0;
  int max_cells_per_vndf_cell = 8;
  // Largest table (bytes, at the most incidence samples the refinement may make): cells per
  // RGB cell are reduced by steps of 0.8 until it fits, down to one cell per VNDF cell.
  std::size_t max_table_bytes = 10u << 20;
  // Threads building the table; 0: one per core.
  int jobs = 0;
};

// An RGL material as a BrdfSource. Thread-safe to evaluate (immutable after loading); about
// 3 × the file size in memory (the warp tables are kept in double). Eval allocates nothing.
class RglBrdf final : public BrdfSource {
 public:
  // Reads and checks a file. Throws IoError / FormatError naming the file, byte offset (or
  // field), expected and found values.
  static RglBrdf Load(const std::string& path);
  // Builds the evaluator from a parsed tensor file (fields checked as by Load).
  static RglBrdf FromTensorFile(const TensorFile& tensor, std::string name);

  RglBrdf(RglBrdf&&) noexcept;
  RglBrdf& operator=(RglBrdf&&) noexcept;
  ~RglBrdf() override;

  // f_r in 1/sr, linear RGB, NOT multiplied by cosθo. `wi` points to the light, `wo` to the
  // viewer, unit vectors in the local frame (z = normal). 0 when either is at or below the
  // horizon (or not finite).
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  // f_r·cosθo: what the reference loader's eval() returns (the rendering-equation integrand).
  Rgb EvalCosine(const Vec3& wi, const Vec3& wo) const;

  // The file name without its folder ("paper_white_rgb.bsdf").
  std::string Name() const override { return name_; }
  const RglInfo& info() const;

  // The tabulated form (RglTabulatedBrdf); null for a file with more than one phi_i (or a
  // sigma table that varies with φ), which has none. InvalidArgument for settings out of range.
  std::unique_ptr<RglTabulatedBrdf> Tabulate(const RglTabulationSettings& settings) const;
  // Tabulate() with the default settings, or null when there is no table or its self-check
  // exceeds kRglApproximationMaxP99Error.
  std::unique_ptr<BrdfSource> QuadratureApproximation() const override;

 private:
  struct Tables;
  RglBrdf(std::unique_ptr<Tables> tables, std::string name);
  std::unique_ptr<Tables> tables_;
  std::string name_;
};

// A tabulated form of an isotropic RGL file, for the preview's quadrature (RglBrdf::
// QuadratureApproximation; docs/preview.md, docs/benchmarks.md "RGL tabulated evaluation").
//
// What is tabulated. RglBrdf computes f_r·cosθo = g(θi, u_m) · ndf(u_m) / (4 σ(θi)), where
// u_m = (u(θm), u(φm − φi)) is the half vector on the unit square and g = rgb(warp⁻¹(u_m; θi))
// the RGB looked up through the inverse VNDF warp. Here g is sampled with RglBrdf's own code
// on a grid and interpolated trilinearly:
//   - incidence: every node of the file's theta_i (RglBrdf has a kink at each; between nodes it
//     blends the two slices linearly), plus 2^k − 1 evenly spaced samples inside each interval,
//     k chosen per interval by doubling until the new midpoints are predicted by linear
//     interpolation within `incidence_tolerance` (0.2 % weighted RMS; at most 8 samples);
//   - u(θm) and u(φm − φi): the VNDF grid's vertices (128 × 128 in the real files), each VNDF
//     cell split further where the warp is steep, so that one table cell spans at most one RGB
//     cell in warped space (at most 8 splits per cell; within a 10 MiB budget).
//   Real 128 × 128 files: 41–57 incidence samples × ~150 × 130–190 vertices, RGB as 16-bit
//   fractions of each sample's per-channel maximum (6 bytes per vertex): 4.8–9.7 MB, built in
//   35–50 ms of CPU on 2 threads (the self-check included).
// What is exact. ndf(u_m) (a 1-D table in θm for the isotropic files) is looked up exactly:
// it carries the sharp part of the lobe (the file's RGB holds the reflectance with that
// factor divided out, so g is the smooth remainder), so interpolating ndf too would cost
// accuracy at the mirror direction while saving one 1-D lookup. 1/(4σ(θi)) is folded
// into each incidence sample's scale: σ (the projected microsurface area) is smooth in θi.
// Files with jacobian = 0 tabulate g the same way without the ndf/σ factor.
//
// Measured error (against the float64 NumPy oracle, tests/python/rgl_tabulated_check.py,
// 30,000 pairs per file: a third uniform, a third near the mirror direction, a third at the
// incidence nodes): where f·cosθo is at least 1 % of the sample's largest value, the relative
// difference is under 2–3 % for 99 % of the pairs of cc_ibiza_sunset, chm_light_blue,
// paper_white and cg_sunflower, under 4–11 % for 99.9 %; the largest differences (14–70 %)
// lie on creases of the RGB table (values changing by a factor within one of its cells, e.g.
// at the edge of the measured region), in θi or φm − φi, where any interpolant between RglBrdf's
// values differs; chm_mint is the worst file (p99 13 %, at grazing incidence). Directional
// albedos (over ωo at fixed ωi and over ωi at fixed ωo) agree within 0.4 % on every file
// tested. The preview of cc_ibiza_sunset at 512² moves from 0.525 to 0.572 % RMS from the
// brute-force reference, chm_light_blue from 0.594 to 0.560 %. Speed: 1.75–2.1 × fewer ns per
// call than RglBrdf on random pairs (the half-vector coordinates are computed in single
// precision here; the rest is mostly the texel loads of a table larger than the L2 cache), and
// 1.45 × less CPU for the whole preview of cc_ibiza_sunset on one thread.
class RglTabulatedBrdf final : public BrdfSource {
 public:
  RglTabulatedBrdf(RglTabulatedBrdf&&) noexcept;
  RglTabulatedBrdf& operator=(RglTabulatedBrdf&&) noexcept;
  ~RglTabulatedBrdf() override;

  // As RglBrdf::Eval and RglBrdf::EvalCosine (same directions, units and zeros), from the
  // table. Thread-safe; allocates nothing.
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  Rgb EvalCosine(const Vec3& wi, const Vec3& wo) const;
  // The file's name with " (tabulated)" appended.
  std::string Name() const override { return name_; }
  // Memory held by the table, bytes; incidence samples and vertices per axis.
  std::size_t table_bytes() const;
  int incidence_samples() const;
  int vertices_theta() const;
  int vertices_phi() const;
  // The self-check made when the table is built: at 16,384 fixed pseudo-random direction pairs
  // (half cosine-distributed, half within a few degrees of the mirror direction), the 99th
  // percentile of |tabulated − RglBrdf| / RglBrdf over the values (per channel) of f_r·cosθo
  // that are at least 1 % of the largest one. RglBrdf::QuadratureApproximation declines the
  // table above kRglApproximationMaxP99Error.
  double self_check_p99_error() const;

 private:
  friend class RglBrdf;
  struct Table;
  RglTabulatedBrdf(std::unique_ptr<Table> table, std::string name);
  std::unique_ptr<Table> table_;
  std::string name_;
};

}  // namespace brdf
