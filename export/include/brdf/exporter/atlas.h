// Atlases: many materials in one texture for deferred renderers (docs/design.md §5).
//
// Each θin slice of the atlas is a grid of Cm = ceil(√M) × Rm = ceil(M/Cm) cells of 361 × 181
// texels; material m sits in column m mod Cm, row m div Cm, so its texel (i, j) of slice k is
// atlas texel (x, y, z) = ((m mod Cm)·361 + i, (m div Cm)·181 + j, k). Unused cells are zero.
// The 3D texture (KTX2, DDS) is Cm·361 × Rm·181 × K; the EXR arranges the K slice grids exactly
// like the single-LUT composite (exr.h). All materials must share one θin list: the slice
// index is the same for every cell.
//
// A JSON manifest names every material, its cell (column, row, texel origin), the θin list,
// the grid sizes and the texel convention, including how a shader addresses a cell:
//   u = (x0 + φd/1° + 0.5)/(Cm·361), v = (y0 + θd/1° + 0.5)/(Rm·181), w as for one LUT,
// with u, v clamped to the cell's outer texel centres so filtering never reads a neighbour.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/lut.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/exr.h"
#include "brdf/exporter/lut_compression.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf::exporter {

struct AtlasLayout {
  int materials = 0, slices = 0;
  GridLayout cells;      // Cm × Rm material cells in each slice
  GridLayout composite;  // C × R slice grids in the flat EXR image
  int TextureWidth() const { return cells.columns * Lut::kWidth; }
  int TextureHeight() const { return cells.rows * Lut::kHeight; }
  int ImageWidth() const { return composite.columns * TextureWidth(); }
  int ImageHeight() const { return composite.rows * TextureHeight(); }
};
// Throws InvalidArgument for materials < 1 or slices < 1.
AtlasLayout ComputeAtlasLayout(int materials, int slices);

struct AtlasMaterial {
  std::string name;
  const Lut* lut = nullptr;  // not owned; must outlive the call
  std::string source;        // where the LUT came from (for the manifest)
  // Saturated samples per measured slice (the manifest's "saturated_samples"); absent: unknown.
  std::optional<std::vector<SaturatedCount>> saturated_samples = std::nullopt;
  // What filled θout > θb (the manifest's "extrapolation"); absent: nothing was extrapolated
  // or it is unknown (an exported LUT).
  std::optional<ExtrapolationInfo> extrapolation = std::nullopt;
  // Fitted models as complete JSON texts, e.g. `--extrapolate auto`'s choice with its GGX fit:
  // the manifest's "fitted_models" of the material, as a LUT sidecar's (sidecar.h).
  std::vector<std::string> fitted_models_json = {};
  // The blind-spot fill's record (processing::BeyondReportJson: measured_theta_in,
  // extrapolated_theta_in, method, leave-last-slice-out error), the manifest's "beyond" of the
  // material, as a LUT sidecar's; empty: no fill recorded.
  std::string beyond_json = {};
};

struct Atlas {
  AtlasLayout layout;
  std::vector<double> theta_in_deg;
  std::vector<std::string> names, sources;
  std::vector<std::optional<std::vector<SaturatedCount>>> saturated_samples;  // per material
  std::vector<std::optional<ExtrapolationInfo>> extrapolation;                // per material
  std::vector<std::vector<std::string>> fitted_models_json;                   // per material
  std::vector<std::string> beyond_json;  // per material (AtlasMaterial::beyond_json)
  PackedVolume volume;                   // Cm·361 × Rm·181 × K, RGB9E5
  // Set by CompressAtlasBc6h: the same texture as BC6H blocks (the KTX2 and DDS then hold these
  // and the manifest describes them) and each material's certified error over its cell.
  std::optional<Bc6hVolume> bc6h;
  std::vector<CertifiedError> certified_error;  // per material, when bc6h is set
};

// Packs the materials. Throws InvalidArgument if there are none, a LUT is unexportable, names
// repeat, or θin lists differ ("materials 'gold' (θin 0, 20, 40, 60) and 'felt' (θin 0, 30, 60)
// have different θin sets; an atlas needs one θin list").
Atlas BuildAtlas(const std::vector<AtlasMaterial>& materials);

// Compresses the atlas texture as BC6H (bc6h.h) on `jobs` threads and measures every
// material's cell against its float LUT (lut_compression.h; θb from its extrapolation, else
// 90°). Blocks straddle cell borders (361 and 181 are not multiples of 4), so a block may mix two
// materials; each cell's certified error includes that. Fills atlas.bc6h and certified_error.
void CompressAtlasBc6h(Atlas& atlas, const std::vector<AtlasMaterial>& materials, int jobs = 1);

// `--max-error E` for an atlas (a fraction, on each material's measured range θout ≤ θb). The
// atlas is one texture in one texel format, so BC6H is chosen when every material's cell meets
// E with BC6H (CompressAtlasBc6h), else RGB9E5 (atlas.bc6h reset; the compact form is per
// material and never chosen). Either way atlas.certified_error then holds each material's
// error for the chosen format, with E as its bound and whether it is met; unused cells hold no
// material and are not measured. Returns kBc6h or kNone. Throws InvalidArgument for E outside
// (0, 1).
LutCompression ChooseAtlasCompression(Atlas& atlas, const std::vector<AtlasMaterial>& materials,
                                      double max_error, int jobs = 1);

// The flat float image of the atlas (EXR layout above), from the unquantised LUTs.
FloatImage AtlasImage(const std::vector<AtlasMaterial>& materials);

// The manifest JSON. `files` lists the written file names (no folder).
std::string AtlasManifestJson(const Atlas& atlas, const std::vector<std::string>& files);

// The files WriteAtlas writes for `prefix`, in its order: PREFIX.ktx2, .dds, .exr, .json (the
// list a caller's overwrite check covers before any work).
std::vector<std::string> AtlasOutputPaths(const std::string& prefix);

// Writes PREFIX.ktx2, PREFIX.dds, PREFIX.exr and PREFIX.json (the manifest), each atomically,
// and returns the paths written. The manifest is also embedded in the KTX2 ("brdf.atlas") and
// the EXR ("brdf:atlas"). Throws InvalidArgument / IoError.
// With compression kBc6h the KTX2 and DDS hold the BC6H form (CompressAtlasBc6h) and the
// manifest records it ("payload" of the blocks, a "compression" member per material). With
// max_error > 0, `compression` is ignored and ChooseAtlasCompression picks BC6H or RGB9E5; the
// manifest's "compression" members record the chosen format's error per material, the bound and
// whether it is met.
std::vector<std::string> WriteAtlas(const std::string& prefix,
                                    const std::vector<AtlasMaterial>& materials,
                                    const ExrOptions& exr_options = {},
                                    LutCompression compression = LutCompression::kNone,
                                    int jobs = 1, double max_error = 0);

// Material m's cell of an atlas volume, decoded into a LUT with the given θin list.
Lut ExtractAtlasCell(const PackedVolume& atlas_volume, const AtlasLayout& layout, int m,
                     std::vector<double> theta_in_deg);

// What a manifest says, parsed back.
struct AtlasManifestEntry {
  std::string name, source;
  int index = 0, column = 0, row = 0, x0 = 0, y0 = 0;
  // Absent: the manifest did not record them.
  std::optional<std::vector<SaturatedCount>> saturated_samples = std::nullopt;
  std::optional<ExtrapolationInfo> extrapolation = std::nullopt;
  std::vector<std::string> fitted_models_json = {};              // each a compact JSON text
  std::optional<CertifiedError> certified_error = std::nullopt;  // a compressed atlas's
  std::string beyond_json = {};  // the "beyond" member as compact JSON text; empty: absent
};
struct AtlasManifest {
  std::vector<double> theta_in_deg;
  std::vector<AtlasManifestEntry> materials;
  AtlasLayout layout;
  int texture_width = 0, texture_height = 0;
  std::string payload_format = "rgb9e5";  // or "bc6h_ufloat"
  std::uint64_t payload_bytes = 0;
  std::uint32_t payload_crc32 = 0;
};
// Throws FormatError naming the member.
AtlasManifest ParseAtlasManifest(std::string_view json_text,
                                 const std::string& file = "<manifest>");

}  // namespace brdf::exporter
