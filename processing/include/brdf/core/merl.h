// MERL BRDF database `.binary` files (Matusik, Pfister, Brand & McMillan 2003).
//
// A MERL file tabulates one isotropic material over Rusinkiewicz half/difference angles:
// three int32 (90, 90, 180), then 3 × 1,458,000 float64 — the red plane, then green, then
// blue — at index (i_θh·90 + i_θd)·180 + i_φd with
//   i_θh = floor(√(θh / 90°) · 90)   (denser near the specular peak),
//   i_θd = floor(θd / 90° · 90),  i_φd = floor(φd / 180° · 180), φd folded into [0°, 180°)
// (reciprocity makes φd and φd + 180° equal), each clamped to the table. A stored value times
// the channel scale (R 1/1500, G 1.15/1500, B 1.66/1500) is f_r in 1/sr, not multiplied by
// cosθ. Negative values mean "not measured".
//
// Evaluation returns the value of the bin the direction pair falls in (no interpolation,
// like the database's reference code). The error against the underlying BRDF is therefore
// bounded by how much f_r varies across one bin: θh bins are 90·(2i+1)/8100 degrees wide
// (0.011° at the pole, 2° at grazing), θd and φd bins 1°.
//
// No genuine MERL file ships with the project; ../shared/brdf-data/reference/
// merl_binary_sha256.tsv lists the SHA-256 of all 100 published files so a user-supplied file
// can be identified (IdentifyMerlFile).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/brdf_source.h"

namespace brdf {

inline constexpr int kMerlThetaHalfBins = 90;
inline constexpr int kMerlThetaDiffBins = 90;
inline constexpr int kMerlPhiDiffBins = 180;
inline constexpr std::size_t kMerlBinsPerChannel = 90 * 90 * 180;  // 1,458,000
inline constexpr std::uint64_t kMerlFileBytes = 12 + 3 * kMerlBinsPerChannel * 8;
// Stored value × scale = f_r (1/sr), per channel R, G, B.
inline constexpr std::array<double, 3> kMerlScale = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

// A MERL table cell: the three indices defined above.
struct MerlBin {
  int theta_half = 0;  // 0..89
  int theta_diff = 0;  // 0..89
  int phi_diff = 0;    // 0..179
  std::size_t Index() const {
    return (static_cast<std::size_t>(theta_half) * kMerlThetaDiffBins + theta_diff) *
               kMerlPhiDiffBins +
           phi_diff;
  }
};

// The bin a direction pair falls in. `wi` (to the light) and `wo` (to the viewer) are unit
// vectors in the local frame; the result is meaningful only when both are above the horizon.
MerlBin MerlBinOf(const Vec3& wi, const Vec3& wo);

// The direction pair at the centre of a bin (θh at the centre of its √-spaced interval, θd
// and φd at their half degrees, φh = 0). Either direction may lie below the horizon for bins
// near grazing.
void MerlBinCenter(const MerlBin& bin, Vec3& wi, Vec3& wo);

struct MerlInfo {
  std::array<std::uint64_t, 3> unmeasured_bins{};  // negative entries per channel (R, G, B)
};

// A MERL file as a BrdfSource: 35 MB of doubles, immutable after loading, thread-safe.
class MerlBrdf final : public BrdfSource {
 public:
  // Reads and checks a file: size exactly kMerlFileBytes, header (90, 90, 180), every value
  // finite. Throws IoError / FormatError naming the file, byte offset, expected and found.
  static MerlBrdf Load(const std::string& path);
  // Same checks on the bytes of a whole file; `file` names it in messages.
  static MerlBrdf FromBytes(std::span<const std::uint8_t> bytes, std::string file);

  // f_r in 1/sr (RGB, not multiplied by cosθo) of the bin the pair falls in; 0 below the
  // horizon and, per channel, in bins the file marks as not measured.
  Rgb Eval(const Vec3& wi, const Vec3& wo) const override;
  // False when any channel of the pair's bin is marked not measured (or the pair is below
  // the horizon), so a caller can tell a measured black from a hole.
  bool IsMeasured(const Vec3& wi, const Vec3& wo) const;
  bool HasValue(const Vec3& wi, const Vec3& wo) const override { return IsMeasured(wi, wo); }

  std::string Name() const override { return name_; }
  const MerlInfo& info() const { return info_; }

 private:
  MerlBrdf() = default;
  std::vector<double> values_;  // f_r already scaled, 3 planes; negative = not measured
  MerlInfo info_;
  std::string name_;
};

// The bytes of a MERL file holding `source` sampled at every bin centre (MerlBinCenter).
// Bins whose centre pair lies at or below the horizon are written as −1 (not measured), as
// are values that are not finite.
std::string EncodeMerlBinary(const BrdfSource& source);
// Writes EncodeMerlBinary(source) to `path` atomically. Throws IoError.
void WriteMerlBinary(const std::string& path, const BrdfSource& source);

// One line of the published SHA-256 table: "material<TAB>size_bytes<TAB>sha256".
struct MerlDigest {
  std::string material;  // "alum-bronze"
  std::uint64_t size_bytes = 0;
  std::string sha256;  // 64 lower-case hex digits
};

// Reads the table (lines starting with '#' are comments). `path` empty means the
// BRDF_MERL_SHA256_TABLE environment variable; InvalidArgument when neither is given.
// Throws IoError / FormatError naming the line.
std::vector<MerlDigest> ReadMerlDigestTable(const std::string& path = "");
// The same parse of a table's text; `file` names it in messages.
std::vector<MerlDigest> ParseMerlDigestTable(std::string_view text, const std::string& file);

// The MERL material whose published digest matches the file's SHA-256 and size, or nullopt
// for a file that is not one of the published ones (e.g. a synthetic file). The table is read
// at run time from `table_path` (or BRDF_MERL_SHA256_TABLE); it is never bundled.
std::optional<std::string> IdentifyMerlFile(const std::string& merl_path,
                                            const std::string& table_path = "");

}  // namespace brdf
