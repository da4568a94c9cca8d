#include "brdf/exporter/compact_lut.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/geometry.h"
#include "brdf/core/parallel.h"
#include "brdf/core/text_format.h"
#include "brdf/exporter/half.h"
#include "brdf/exporter/lut_compression.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter {
namespace {

constexpr char kMagic[8] = {'B', 'R', 'D', 'F', 'C', 'L', 'U', 'T'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 36;
constexpr int kMaxSlices = 181;
constexpr float kScaleFloor = 6.103515625e-05f;  // 2^−14, as lut_compression.cpp
constexpr float kRelativeFloor = 1e-4f;
// The extrapolated band (θb < θout ≤ 90°) is built to 4× the target: visible at grazing views,
// but not measured.
constexpr float kFilledWeight = 0.25f;

// The grid coordinate of x (degrees, inside [0, kept.back()]) for a kept list: p + (x −
// a_p)/(a_{p+1} − a_p) on the gap [a_p, a_{p+1}] holding x.
float MapValue(const std::vector<std::uint16_t>& kept, double x) {
  const auto it = std::upper_bound(kept.begin() + 1, kept.end() - 1, x);
  const std::size_t p = static_cast<std::size_t>(it - kept.begin()) - 1;
  const double a = kept[p], b = kept[p + 1];
  return static_cast<float>(static_cast<double>(p) + (x - a) / (b - a));
}

// The whole-degree map of a kept list over 0…n−1 (n = 181 or 361), folded at `fold` when
// mirrored (entries beyond it read 2·fold − x).
std::vector<float> MapTable(const std::vector<std::uint16_t>& kept, int n, int fold) {
  std::vector<float> table(n);
  for (int x = 0; x < n; ++x) table[x] = MapValue(kept, (fold > 0 && x > fold) ? 2 * fold - x : x);
  return table;
}

// Bilinear read of the log grid at grid coordinates (mr, mc), as the GLSL decoder does it.
std::array<float, 3> ReadGrid(const std::uint16_t* values, int nrows, int ncols, float mr, float mc,
                              float scale, float epsilon) {
  const int r0 = std::min(static_cast<int>(std::floor(mr)), nrows - 2);
  const int c0 = std::min(static_cast<int>(std::floor(mc)), ncols - 2);
  const float tr = mr - static_cast<float>(r0), tc = mc - static_cast<float>(c0);
  std::array<float, 3> out{};
  for (int c = 0; c < 3; ++c) {
    const auto g = [&](int r, int col) {
      return HalfToFloat(values[(static_cast<std::size_t>(r) * ncols + col) * 3 + c]);
    };
    const float top = g(r0, c0) + (g(r0, c0 + 1) - g(r0, c0)) * tc;
    const float bottom = g(r0 + 1, c0) + (g(r0 + 1, c0 + 1) - g(r0 + 1, c0)) * tc;
    const float l = top + (bottom - top) * tr;
    out[c] = scale * std::max(std::exp2(l) - epsilon, 0.0f);
  }
  return out;
}

// One slice being built: the LUT's log values, its measured mask and the current grid.
class SliceBuilder {
 public:
  SliceBuilder(const Lut& lut, int k, bool mirrored, double theta_b_deg, float scale,
               float floor_value)
      : lut_(lut), k_(k), mirrored_(mirrored), scale_(scale), floor_(floor_value) {
    const int n = Lut::kHeight * Lut::kWidth;
    weight_.resize(n);
    logs_.resize(static_cast<std::size_t>(n) * 3);
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const int at = j * Lut::kWidth + i;
        const double theta_out = TexelThetaOutDeg(lut.theta_in_deg[k], j, i);
        weight_[at] = theta_out <= theta_b_deg + 1e-9 ? 1.0f
                      : theta_out <= 90.0             ? kFilledWeight
                                                      : 0.0f;
        for (int c = 0; c < 3; ++c)
          logs_[at * 3 + c] = FloatToHalf(
              scale > 0 ? std::log2(Clamped(lut.Texel(k, j, i)[c]) / scale + kCompactEpsilon)
                        : 0.0f);
      }
    const int last_col = mirrored ? 180 : 360;
    for (int r = 0; r <= 180; r += 30) rows_.push_back(static_cast<std::uint16_t>(r));
    for (int c = 0; c <= last_col; c += 30) cols_.push_back(static_cast<std::uint16_t>(c));
    if (cols_.back() != last_col) cols_.push_back(static_cast<std::uint16_t>(last_col));
    errors_.assign(n, 0.0f);
    Recompute(0, Lut::kHeight, 0, Lut::kWidth, rows_, cols_, errors_);
  }

  void Run(double target) {
    for (;;) {
      const auto worst = std::max_element(errors_.begin(), errors_.end());
      if (*worst <= target) return;
      const int at = static_cast<int>(worst - errors_.begin());
      const int j = at / Lut::kWidth, i = at % Lut::kWidth;
      const int fi = mirrored_ && i > 180 ? 360 - i : i;
      Candidate best;
      for (int axis = 0; axis < 2; ++axis) {
        const std::vector<std::uint16_t>& kept = axis == 0 ? rows_ : cols_;
        const int other = static_cast<int>(axis == 0 ? cols_.size() : rows_.size());
        if ((static_cast<int>(kept.size()) + 1) * other > kCompactMaxSliceTexels) continue;
        for (const int x : Insertions(kept, axis == 0 ? j : fi)) Try(axis, x, best);
      }
      if (best.axis < 0) return;  // nothing left to insert within the size limit
      (best.axis == 0 ? rows_ : cols_) = best.kept;
      errors_ = std::move(best.errors);
    }
  }

  // Fills the compact form's lists and values of this slice.
  void Store(CompactLut& out) const {
    out.rows[k_] = rows_;
    out.cols[k_] = cols_;
    std::vector<std::uint16_t>& v = out.values[k_];
    v.resize(rows_.size() * cols_.size() * 3);
    for (std::size_t r = 0; r < rows_.size(); ++r)
      for (std::size_t c = 0; c < cols_.size(); ++c)
        for (int ch = 0; ch < 3; ++ch)
          v[(r * cols_.size() + c) * 3 + ch] =
              logs_[(static_cast<std::size_t>(rows_[r]) * Lut::kWidth + cols_[c]) * 3 + ch];
  }

 private:
  struct Candidate {
    int axis = -1;
    std::vector<std::uint16_t> kept;
    std::vector<float> errors;
    double max = 0, sum = 0;
  };

  static float Clamped(float v) { return std::clamp(v, 0.0f, 65504.0f); }

  // Where a row (column) may go for an error at x: the midpoint of x's gap and x itself; for x
  // on a kept line, the midpoints of the gaps on both sides.
  static std::vector<int> Insertions(const std::vector<std::uint16_t>& kept, int x) {
    std::vector<int> out;
    const auto it = std::lower_bound(kept.begin(), kept.end(), x);
    if (it != kept.end() && *it == x) {
      if (it != kept.begin() && *it - *(it - 1) > 1) out.push_back((*it + *(it - 1)) / 2);
      if (it + 1 != kept.end() && *(it + 1) - *it > 1) out.push_back((*it + *(it + 1)) / 2);
    } else {
      const int lo = *(it - 1), hi = *it;
      out.push_back((lo + hi) / 2);
      if (x != (lo + hi) / 2) out.push_back(x);
    }
    return out;
  }

  void Try(int axis, int x, Candidate& best) const {
    std::vector<std::uint16_t> kept = axis == 0 ? rows_ : cols_;
    const auto it = std::lower_bound(kept.begin(), kept.end(), x);
    const int lo = *(it - 1), hi = *it;
    kept.insert(it, static_cast<std::uint16_t>(x));
    std::vector<float> errors = errors_;
    if (axis == 0) {
      Recompute(lo, hi + 1, 0, Lut::kWidth, kept, cols_, errors);
    } else {
      Recompute(0, Lut::kHeight, lo, hi + 1, rows_, kept, errors);
      if (mirrored_) Recompute(0, Lut::kHeight, 360 - hi, 360 - lo + 1, rows_, kept, errors);
    }
    double max = 0, sum = 0;
    for (const float e : errors) max = std::max<double>(max, e), sum += e;
    if (best.axis < 0 || max < best.max || (max == best.max && sum < best.sum)) {
      best.axis = axis;
      best.kept = std::move(kept);
      best.errors = std::move(errors);
      best.max = max, best.sum = sum;
    }
  }

  // The measured texels' errors in rows [j0, j1) × columns [i0, i1) for the grid (rows, cols).
  void Recompute(int j0, int j1, int i0, int i1, const std::vector<std::uint16_t>& rows,
                 const std::vector<std::uint16_t>& cols, std::vector<float>& errors) const {
    const std::vector<float> rmap = MapTable(rows, Lut::kHeight, 0);
    const std::vector<float> cmap = MapTable(cols, Lut::kWidth, mirrored_ ? 180 : 0);
    std::vector<std::uint16_t> grid(rows.size() * cols.size() * 3);
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (std::size_t c = 0; c < cols.size(); ++c)
        for (int ch = 0; ch < 3; ++ch)
          grid[(r * cols.size() + c) * 3 + ch] =
              logs_[(static_cast<std::size_t>(rows[r]) * Lut::kWidth + cols[c]) * 3 + ch];
    const int nr = static_cast<int>(rows.size()), nc = static_cast<int>(cols.size());
    for (int j = std::max(j0, 0); j < std::min(j1, Lut::kHeight); ++j)
      for (int i = std::max(i0, 0); i < std::min(i1, Lut::kWidth); ++i) {
        const int at = j * Lut::kWidth + i;
        if (weight_[at] == 0.0f) continue;
        const std::array<float, 3> d =
            ReadGrid(grid.data(), nr, nc, rmap[j], cmap[i], scale_, kCompactEpsilon);
        const float* ref = lut_.Texel(k_, j, i);
        const float r[3] = {Clamped(ref[0]), Clamped(ref[1]), Clamped(ref[2])};
        const float s = std::max({r[0], r[1], r[2], floor_});
        errors[at] =
            weight_[at] *
            std::max({std::abs(d[0] - r[0]), std::abs(d[1] - r[1]), std::abs(d[2] - r[2])}) / s;
      }
  }

  const Lut& lut_;
  int k_;
  bool mirrored_;
  float scale_, floor_;
  std::vector<float> weight_;  // 1 measured, kFilledWeight above the horizon beyond θb, else 0
  std::vector<std::uint16_t> logs_;  // every texel's g as a half, the grid's candidates
  std::vector<std::uint16_t> rows_, cols_;
  std::vector<float> errors_;
};

// Mirror symmetry f(φd) = f(360° − φd) on the measured range, to within a quarter of the
// target (so folding costs at most that).
bool IsMirrored(const Lut& lut, double theta_b_deg, double target, float floor_value) {
  for (int k = 0; k < lut.slices(); ++k)
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 181; i < Lut::kWidth; ++i) {
        if (TexelThetaOutDeg(lut.theta_in_deg[k], j, i) > theta_b_deg + 1e-9) continue;
        const float* a = lut.Texel(k, j, i);
        const float* b = lut.Texel(k, j, 360 - i);
        float s = floor_value, d = 0;
        for (int c = 0; c < 3; ++c) {
          const float x = std::clamp(a[c], 0.0f, 65504.0f), y = std::clamp(b[c], 0.0f, 65504.0f);
          s = std::max(s, x);
          d = std::max(d, std::abs(x - y));
        }
        if (d / s > 0.25 * target) return false;
      }
  return true;
}

// Little-endian writers and readers of the container.
void Put32(std::string& out, std::uint32_t v) {
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((v >> (8 * b)) & 0xFF));
}
void Put16(std::string& out, std::uint16_t v) {
  out.push_back(static_cast<char>(v & 0xFF));
  out.push_back(static_cast<char>(v >> 8));
}
void PutF32(std::string& out, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  Put32(out, u);
}
void PutF64(std::string& out, double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, 8);
  Put32(out, static_cast<std::uint32_t>(u));
  Put32(out, static_cast<std::uint32_t>(u >> 32));
}

// The payload: everything from byte 36 (after the header) to the end of the grid values.
std::string PayloadOf(const CompactLut& c) {
  std::string out;
  for (const double t : c.theta_in_deg) PutF64(out, t);
  for (int k = 0; k < c.slices(); ++k) {
    Put16(out, static_cast<std::uint16_t>(c.rows[k].size()));
    Put16(out, static_cast<std::uint16_t>(c.cols[k].size()));
  }
  for (int k = 0; k < c.slices(); ++k) {
    for (const std::uint16_t r : c.rows[k]) Put16(out, r);
    for (const std::uint16_t v : c.cols[k]) Put16(out, v);
  }
  for (int k = 0; k < c.slices(); ++k)
    for (const std::uint16_t v : c.values[k]) Put16(out, v);
  return out;
}

class Reader {
 public:
  Reader(const std::vector<std::uint8_t>& bytes, std::string file)
      : bytes_(bytes), file_(std::move(file)) {}
  std::size_t at() const { return at_; }
  void Need(std::size_t n, const char* what) const {
    if (bytes_.size() - at_ < n)
      throw FormatError(file_, BytePosition(at_), fmt::format("{} ({} bytes)", what, n),
                        fmt::format("end of file after {} bytes", bytes_.size()),
                        "the compact LUT is cut short");
  }
  std::uint32_t U32(const char* what) {
    Need(4, what);
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= static_cast<std::uint32_t>(bytes_[at_ + b]) << (8 * b);
    at_ += 4;
    return v;
  }
  std::uint16_t U16(const char* what) {
    Need(2, what);
    const std::uint16_t v = static_cast<std::uint16_t>(bytes_[at_] | (bytes_[at_ + 1] << 8));
    at_ += 2;
    return v;
  }
  float F32(const char* what) {
    const std::uint32_t u = U32(what);
    float v;
    std::memcpy(&v, &u, 4);
    return v;
  }
  double F64(const char* what) {
    const std::uint64_t lo = U32(what), hi = U32(what);
    const std::uint64_t u = lo | (hi << 32);
    double v;
    std::memcpy(&v, &u, 8);
    return v;
  }
  [[noreturn]] void Fail(std::size_t at, const std::string& expected,
                         const std::string& got) const {
    throw FormatError(file_, BytePosition(at), expected, got);
  }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::string file_;
  std::size_t at_ = 0;
};

}  // namespace

std::uint64_t CompactLut::GridTexels() const {
  std::uint64_t n = 0;
  for (int k = 0; k < slices(); ++k) n += rows[k].size() * cols[k].size();
  return n;
}

std::uint64_t CompactLut::PayloadBytes() const {
  std::uint64_t n = kHeaderBytes + 8ull * slices() + 4ull * slices();
  for (int k = 0; k < slices(); ++k) n += 2ull * (rows[k].size() + cols[k].size());
  return n + GridTexels() * 6;
}

std::vector<float> CompactLut::RowMap(int k) const { return MapTable(rows[k], Lut::kHeight, 0); }

std::vector<float> CompactLut::ColumnMap(int k) const {
  return MapTable(cols[k], Lut::kWidth, mirrored ? 180 : 0);
}

std::array<float, 3> CompactLut::SampleSlice(int k, double theta_d_deg, double phi_d_deg) const {
  // The maps are linear between whole degrees, so reading them directly equals the decoders'
  // linear reads of their tables.
  const double td = std::clamp(theta_d_deg, 0.0, 180.0);
  double pd = std::clamp(phi_d_deg, 0.0, 360.0);
  if (mirrored && pd > 180.0) pd = 360.0 - pd;
  return ReadGrid(values[k].data(), static_cast<int>(rows[k].size()),
                  static_cast<int>(cols[k].size()), MapValue(rows[k], td), MapValue(cols[k], pd),
                  scale, epsilon);
}

std::vector<float> CompactLut::DecodeTexels() const {
  std::vector<float> out(static_cast<std::size_t>(slices()) * Lut::kHeight * Lut::kWidth * 3);
  for (int k = 0; k < slices(); ++k) {
    const std::vector<float> rmap = RowMap(k), cmap = ColumnMap(k);
    const int nr = static_cast<int>(rows[k].size()), nc = static_cast<int>(cols[k].size());
    for (int j = 0; j < Lut::kHeight; ++j)
      for (int i = 0; i < Lut::kWidth; ++i) {
        const std::array<float, 3> d =
            ReadGrid(values[k].data(), nr, nc, rmap[j], cmap[i], scale, epsilon);
        std::memcpy(&out[((static_cast<std::size_t>(k) * Lut::kHeight + j) * Lut::kWidth + i) * 3],
                    d.data(), sizeof(float) * 3);
      }
  }
  return out;
}

std::array<float, 3> CompactLut::SampleAngles(double theta_in, double theta_out_deg,
                                              double phi_out_deg) const {
  Lut shell;  // the θin list alone: the exchange rule and the slice coordinate
  shell.theta_in_deg = theta_in_deg;
  if (shell.ExchangesLightAndView(theta_in, theta_out_deg)) {
    std::swap(theta_in, theta_out_deg);
    phi_out_deg = -phi_out_deg;
  }
  const Vec3 w_out = SphericalDirectionDeg(theta_out_deg, phi_out_deg);
  const Vec3 w_d = SpecularFrame::FromThetaInDeg(theta_in).ToSpecular(w_out);
  const double theta_d = RadToDeg(ThetaOf(w_d)), phi_d = RadToDeg(PhiOf(w_d));
  // Slice taps as a GPU takes them along w (clamp-to-edge). Clamped before the integer
  // conversion: a file's θin step may be tiny (any ascending k·Δ list parses), and a huge
  // coordinate must still read the last slice.
  const double x = std::clamp(shell.SliceCoordinate(theta_in), -1.0, static_cast<double>(slices()));
  const double fl = std::floor(x);
  const int k0 = std::clamp(static_cast<int>(fl), 0, slices() - 1);
  const int k1 = std::clamp(static_cast<int>(fl) + 1, 0, slices() - 1);
  const float t = static_cast<float>(x - fl);
  const std::array<float, 3> a = SampleSlice(k0, theta_d, phi_d);
  const std::array<float, 3> b = SampleSlice(k1, theta_d, phi_d);
  return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

CompactBuild BuildCompactLut(const Lut& lut, double theta_b_deg, double target, int jobs) {
  ValidateLutForExport(lut);
  if (!(target > 0 && target < 1))
    throw InvalidArgument(
        fmt::format("compact LUT: the error target must be a fraction in (0, 1), got {}", target));
  CompactBuild out;
  CompactLut& c = out.compact;
  c.theta_in_deg = lut.theta_in_deg;
  float brightest = 0;
  for (const float v : lut.texels) brightest = std::max(brightest, std::clamp(v, 0.0f, 65504.0f));
  c.scale = brightest;
  const float floor_value = std::max(kScaleFloor, kRelativeFloor * brightest);
  c.mirrored = IsMirrored(lut, theta_b_deg, target, floor_value);
  const int k_count = lut.slices();
  c.rows.resize(k_count), c.cols.resize(k_count), c.values.resize(k_count);
  ParallelChunks(static_cast<std::size_t>(k_count), 1, ResolveJobs(jobs), nullptr,
                 [&](std::size_t begin, std::size_t end) {
                   for (std::size_t k = begin; k < end; ++k) {
                     SliceBuilder b(lut, static_cast<int>(k), c.mirrored, theta_b_deg, c.scale,
                                    floor_value);
                     b.Run(target);
                     b.Store(c);
                   }
                 });
  out.error = MeasureCompressionError(lut, c.DecodeTexels(), theta_b_deg);
  out.error.format = "compact_log_grid";
  out.error.bytes = c.PayloadBytes();
  out.error.rgb9e5_bytes = static_cast<std::uint64_t>(k_count) * Lut::kHeight * Lut::kWidth * 4;
  out.met_target = out.error.measured.max <= target;
  return out;
}

std::uint32_t CompactPayloadCrc32(const CompactLut& compact) {
  const std::string p = PayloadOf(compact);
  return Crc32(p.data(), p.size());
}

std::string SerializeCompactLut(const CompactLut& c, const std::string& sidecar_json) {
  const std::string payload = PayloadOf(c);
  std::string out(kMagic, sizeof kMagic);
  Put32(out, kVersion);
  Put32(out, static_cast<std::uint32_t>(c.slices()));
  Put32(out, c.mirrored ? 1u : 0u);
  PutF32(out, c.scale);
  PutF32(out, c.epsilon);
  Put32(out, Crc32(payload.data(), payload.size()));
  Put32(out, static_cast<std::uint32_t>(sidecar_json.size()));
  out += payload;
  out += sidecar_json;
  return out;
}

void WriteCompactLut(const std::string& path, const CompactLut& compact,
                     const std::string& sidecar_json) {
  WriteFileAtomically(path, SerializeCompactLut(compact, sidecar_json));
}

bool IsCompactLutFile(const std::uint8_t* bytes, std::size_t size) {
  return size >= sizeof kMagic && std::memcmp(bytes, kMagic, sizeof kMagic) == 0;
}

LoadedCompact ParseCompactLut(const std::vector<std::uint8_t>& bytes, const std::string& file) {
  Reader in(bytes, file);
  in.Need(kHeaderBytes, "the compact LUT header");
  if (!IsCompactLutFile(bytes.data(), bytes.size()))
    in.Fail(0, "the magic \"BRDFCLUT\"", "other bytes (not a compact LUT)");
  in.U32("magic"), in.U32("magic");
  LoadedCompact out;
  CompactLut& c = out.compact;
  if (const std::uint32_t v = in.U32("version"); v != kVersion)
    in.Fail(8, "format version 1", std::to_string(v));
  const std::uint32_t k_count = in.U32("slice count");
  if (k_count < 1 || k_count > kMaxSlices)
    in.Fail(12, fmt::format("1 to {} slices", kMaxSlices), std::to_string(k_count));
  const std::uint32_t flags = in.U32("flags");
  if (flags > 1) in.Fail(16, "flags 0 or 1 (bit 0: mirrored)", std::to_string(flags));
  c.mirrored = flags == 1;
  c.scale = in.F32("scale");
  if (!(std::isfinite(c.scale) && c.scale >= 0 && c.scale <= 65504))
    in.Fail(20, "a scale in [0, 65504]", fmt::format("{}", c.scale));
  c.epsilon = in.F32("epsilon");
  if (!(c.epsilon > 0 && c.epsilon < 1))
    in.Fail(24, "an epsilon in (0, 1)", fmt::format("{}", c.epsilon));
  const std::uint32_t crc = in.U32("checksum");
  const std::uint32_t sidecar_bytes = in.U32("sidecar length");
  const std::size_t payload_start = in.at();
  for (std::uint32_t k = 0; k < k_count; ++k) {
    const std::size_t at = in.at();
    const double t = in.F64("theta_in");
    if (!(std::isfinite(t) && t >= 0 && t <= 90))
      in.Fail(at, "theta_in in [0, 90] degrees", fmt::format("{}", t));
    c.theta_in_deg.push_back(t);
  }
  for (std::uint32_t k = 0; k < k_count; ++k) {
    const double want =
        c.theta_in_deg[0] + k * (k_count > 1 ? c.theta_in_deg[1] - c.theta_in_deg[0] : 0);
    if ((k_count > 1 && !(c.theta_in_deg[1] > c.theta_in_deg[0])) ||
        std::abs(c.theta_in_deg[k] - want) > 1e-6)
      in.Fail(payload_start + 8 * k, "an ascending theta_in list k * delta",
              fmt::format("{}", c.theta_in_deg[k]));
  }
  std::vector<std::pair<int, int>> sizes;
  for (std::uint32_t k = 0; k < k_count; ++k) {
    const std::size_t at = in.at();
    const int nr = in.U16("row count"), nc = in.U16("column count");
    if (nr < 2 || nr > Lut::kHeight || nc < 2 || nc > c.LastColumn() + 1)
      in.Fail(at, fmt::format("2 to 181 rows and 2 to {} columns", c.LastColumn() + 1),
              fmt::format("{} rows, {} columns", nr, nc));
    sizes.emplace_back(nr, nc);
  }
  c.rows.resize(k_count), c.cols.resize(k_count), c.values.resize(k_count);
  const auto read_list = [&](std::vector<std::uint16_t>& list, int n, int last, const char* what) {
    const std::size_t at = in.at();
    for (int p = 0; p < n; ++p) list.push_back(in.U16(what));
    bool ok = list.front() == 0 && list.back() == last;
    for (int p = 1; p < n && ok; ++p) ok = list[p] > list[p - 1];
    if (!ok)
      in.Fail(at, fmt::format("ascending {} from 0 to {}", what, last), "a list that is not");
  };
  for (std::uint32_t k = 0; k < k_count; ++k) {
    read_list(c.rows[k], sizes[k].first, 180, "theta_d rows");
    read_list(c.cols[k], sizes[k].second, c.LastColumn(), "phi_d columns");
  }
  for (std::uint32_t k = 0; k < k_count; ++k) {
    const std::size_t n = static_cast<std::size_t>(sizes[k].first) * sizes[k].second * 3;
    in.Need(2 * n, "grid values");
    for (std::size_t v = 0; v < n; ++v) {
      const std::size_t at = in.at();
      const std::uint16_t h = in.U16("grid value");
      const float f = HalfToFloat(h);
      // g = log2(f/S + ε) lies in [log2 ε, log2(1 + ε)]; a little room for rounding.
      if (!(f >= std::log2(c.epsilon) - 1 && f <= 1))
        in.Fail(at, "a log2 value in [log2(epsilon) - 1, 1]", fmt::format("{}", f));
      c.values[k].push_back(h);
    }
  }
  const std::size_t payload_end = in.at();
  const std::uint32_t got = Crc32(bytes.data() + payload_start, payload_end - payload_start);
  if (got != crc) in.Fail(28, fmt::format("payload checksum {}", Hex32Text(crc)), Hex32Text(got));
  in.Need(sidecar_bytes, "the embedded sidecar");
  out.sidecar_json.assign(reinterpret_cast<const char*>(bytes.data()) + payload_end, sidecar_bytes);
  if (bytes.size() != payload_end + sidecar_bytes)
    in.Fail(payload_end + sidecar_bytes, "the end of the file",
            fmt::format("{} more bytes", bytes.size() - payload_end - sidecar_bytes));
  return out;
}

LoadedCompact ReadCompactLutFile(const std::string& path) {
  return ParseCompactLut(ReadFileBytes(path, 64u << 20), path);
}

Rgb CompactBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return {0.0, 0.0, 0.0};
  const double theta_in_deg = RadToDeg(ThetaOf(wi));
  const double phi_deg = std::hypot(wi.x, wi.y) > 0.0
                             ? WrapDeg360(RadToDeg(PhiOf(wo)) - RadToDeg(PhiOf(wi)))
                             : RadToDeg(PhiOf(wo));
  const std::array<float, 3> f =
      compact_.SampleAngles(theta_in_deg, RadToDeg(ThetaOf(wo)), phi_deg);
  return {f[0], f[1], f[2]};
}

}  // namespace brdf::exporter
