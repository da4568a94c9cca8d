// Private JSON helpers shared by the sidecar, the atlas manifest and the KTX2/EXR metadata.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/compact_lut.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter::detail {

using nlohmann::ordered_json;

// What the metadata says about a stored payload, whatever its texel format.
struct PayloadSummary {
  bool bc6h = false;  // BC6H_UF16 blocks, else RGB9E5 words
  int width = 0, height = 0, depth = 0;
  std::uint64_t bytes = 0;
  std::uint32_t crc32 = 0;
  bool compact = false;  // the compact log grid (compact_lut.h), else as bc6h says
};
PayloadSummary Summarize(const PackedVolume& payload);
PayloadSummary Summarize(const Bc6hVolume& payload);
PayloadSummary Summarize(const CompactLut& payload);

// {"frame": ..., "width": 361, "height": 181, "slices": K, "phi_d_deg": {...}, ...}
ordered_json GridJson(const PayloadSummary& payload, const std::vector<double>& theta_in_deg);
// {"centre_exact": TexelCentreFormula(), "published": PublishedFormula(), "glsl": snippet}
ordered_json TexelConventionJson(const std::vector<double>& theta_in_deg);
// {"encoding": ..., "texel_order": ..., "bytes": N, "checksum": {"algorithm": "crc32", ...}}
// With "format": "bc6h_ufloat" first for BC6H blocks (absent for RGB9E5, the original form).
ordered_json PayloadJson(const PayloadSummary& payload);
// The sidecar's "compression" member for a certified error.
ordered_json CertifiedErrorJson(const CertifiedError& e);
CertifiedError ParseCertifiedError(const ordered_json& object, const std::string& file);
// "0x1234abcd" (as brdf::Hex32Text writes it) back to the number; throws FormatError naming
// `file` and `position`.
std::uint32_t ParseHex32(const std::string& text, const std::string& file,
                         const std::string& position);

// Parses caller-supplied JSON (a fitted model); throws InvalidArgument naming `what`.
ordered_json ParseEmbeddedJson(const std::string& text, const std::string& what);
// Parses a whole document; throws FormatError with the parser's byte position.
ordered_json ParseJsonDocument(std::string_view text, const std::string& file);

// {"method": ..., "p": P, "l": L, "theta_b_deg": θb} (docs/design.md §6), as the sidecar and
// the atlas manifest record it.
ordered_json ExtrapolationJson(const ExtrapolationInfo& e);

// [{"theta_in_deg": 0, "count": 0}, ...] and back; the parser throws FormatError naming
// "member '<member>[k].count'" etc.
ordered_json SaturatedCountsJson(const std::vector<SaturatedCount>& counts);
std::vector<SaturatedCount> ParseSaturatedCounts(const ordered_json& array, const std::string& file,
                                                 const std::string& member);

// Typed member access that throws FormatError(file, "member '<prefix><name>'", ...).
class JsonFields {
 public:
  JsonFields(const ordered_json& object, std::string file, std::string prefix = {});
  const ordered_json& Get(const char* name) const;
  std::string String(const char* name) const;
  double Number(const char* name) const;
  int Int(const char* name) const;
  std::uint64_t UInt64(const char* name) const;
  const ordered_json& Object(const char* name) const;
  std::vector<double> NumberArray(const char* name) const;
  std::vector<std::string> StringArray(const char* name) const;

 private:
  [[noreturn]] void Fail(const char* name, const std::string& expected) const;
  const ordered_json& object_;
  std::string file_, prefix_;
};

}  // namespace brdf::exporter::detail
