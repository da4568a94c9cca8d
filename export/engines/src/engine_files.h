// Private: the texts of the per-engine files (importers, shaders, viewer, import settings) and
// what a hand-off describes. engine_export.cpp decides which files go where.
#pragma once

#include <string>
#include <vector>

#include "brdf/core/fitted_material.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/exr.h"
#include "brdf/exporter/packed_volume.h"
#include "brdf/exporter/shader_code.h"

namespace brdf::engines::detail {

// One material's place in the texture (the whole texture for a single LUT).
struct HandoffCell {
  std::string name;
  int x0 = 0, y0 = 0;  // texel origin of the cell
};

// What is handed off: one LUT (one cell at 0, 0) or an atlas.
struct Handoff {
  std::string name;    // file stem: the material, or the atlas prefix's stem
  std::string source;  // where the values came from
  bool atlas = false;
  const exporter::PackedVolume* volume = nullptr;
  // The BC6H form (`--compress bc6h`, or BC6H chosen by `--max-error`): every texture of the
  // hand-off holds these blocks (or their decoded texels), created at the padded size
  // BlocksWide·4 × BlocksHigh·4 (364 × 184, the size WebGL requires and the 2D tiles keep
  // block-aligned); `layout` then has that size. Null: RGB9E5 / RGBA16F.
  const exporter::Bc6hVolume* bc6h = nullptr;
  std::vector<float> bc6h_decoded;  // with bc6h: its texels at the padded size, RGB, x fastest
  std::vector<double> theta_in_deg;
  exporter::ShaderLutLayout layout;
  std::vector<HandoffCell> cells;
  exporter::GridLayout composite;  // slice grid of the flat EXR image (C × R)
  std::vector<std::string> fitted_models_json;
  std::vector<FittedMaterial> fits;  // `brdf fit` results, after fitted_models_json
  // The IBL pack of each cell's LUT (brdf/core/ibl_pack.h), in cell order: the manifest's "ibl"
  // and the rows of NAME_ibl.dds.
  std::vector<IblPack> ibl;
};

// "MeasuredBrdf" for the reference layout (θin 0, 20, 40, 60, a single 361 × 181 LUT), else
// "MeasuredBrdf_<K>x<Δin>from<θin,0>" (+ "_<W>x<H>" for an atlas), with '.' in numbers as 'p';
// a single BC6H LUT (364 × 184, padded to whole blocks) adds "_bc6h" ("MeasuredBrdf_bc6h" for
// the reference layout).
std::string ShaderStem(const exporter::ShaderLutLayout& layout);

// Unity (2021.3 LTS to Unity 6).
std::string UnityImporterCs();
std::string UnityHlsl(const exporter::ShaderLutLayout& layout);
// Unreal Engine 5.
std::string UnrealUsh(const exporter::ShaderLutLayout& layout);
std::string UnrealImportPython();
// Godot 4.
std::string GodotShader(const exporter::ShaderLutLayout& layout);
// The sliced EXR's import settings: VRAM Uncompressed; for the BC6H form (handoff.bc6h) VRAM
// Compressed, high quality (BC6H on desktop), HDR compression always. No mipmaps either way.
std::string GodotSlicesImport(const Handoff& handoff, const std::string& exr_file);
// three.js (r180 or later).
std::string WebModuleJs(const exporter::ShaderLutLayout& layout);
// The viewer reads NAME.manifest.json first and imports the module it names, so one index.html
// serves every layout of the folder.
std::string WebViewerHtml();
std::string WebPackageJson();

inline constexpr int kMinimumThreeRevision = 180;

}  // namespace brdf::engines::detail
