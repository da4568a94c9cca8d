// Per-engine hand-off folders: the files a technical artist drops into Unity, Unreal Engine 5,
// Godot 4 or a three.js page so the measured material imports and renders with no manual
// steps beyond dropping them in (`brdf convert --engine ...`, `brdf atlas --engine ...`).
//
// Every engine folder sits beside the regular outputs (OUT/unity/, OUT/unreal/, OUT/godot/,
// OUT/web/) and holds, for a material NAME:
//   unity/   NAME.brdf3d          the KTX2 bytes under an extension no other importer claims
//            Editor/MeasuredBrdfImporter.cs   ScriptedImporter → Texture3D
//                                 (GraphicsFormat.E5B9G9R9_UFloatPack32, RGBAHalf fallback,
//                                 linear, clamp, no mips); also offered for .ktx2 files
//            MeasuredBrdf*.hlsl   Shader Graph Custom Function MeasuredBrdf_float (URP/HDRP)
//                                 and the built-in pipeline lighting model MeasuredBrdf
//   unreal/  NAME.dds             RGBA16F volume DDS (DXGI 10, one mip, depth K)
//            NAME_tiles.exr       the K slices as 361 × 181 tiles (the composite EXR, for
//                                 the Volume Texture from a 2D texture route)
//            MeasuredBrdf*.ush    include for a Custom material node
//            import_measured_brdf.py  editor script: imports the DDS (or builds the Volume
//                                 Texture from the tiles), sRGB off, TC_HDR, clamp, no mips
//   godot/   NAME.dds             the RGB9E5 3D DDS with one mip (byte-identical to OUT/NAME.dds)
//            NAME_slices.exr (+ .import)  the sliced-EXR route with its import settings
//            measured_brdf*.gdshader  spatial shader with a light() function
//   web/     NAME.ktx2, measured_brdf*.js (ES module: KTX2Loader, ShaderMaterial),
//            index.html (viewer: ?material=NAME), package.json (three ≥ r180),
//            MeasuredBrdf*.es300.glsl and MeasuredBrdf*.450.glsl (the lookup as GLSL files)
//   each     NAME_ibl.dds         the IBL pack as an RGBA16F 2D texture (EncodeIblPackDds below)
//            NAME.manifest.json   axes and ranges, texel-centre mapping, units, colour space,
//                                 probe texels (index → RGB f_r), the IBL pack under "ibl"
//                                 (brdf/core/ibl_pack.h; one per cell for atlases), and under
//                                 "engines"
//                                 each folder's files, texture format, orientation per import path
//                                 and import settings (one text, hard-linked into every engine
//                                 folder of the conversion)
// The BC6H form (options.compression kBc6h, or BC6H chosen by max_error; docs/engines.md, "BC6H
// hand-off"): the KTX2 / .brdf3d hold the BC6H blocks, the Unreal and Godot NAME.dds are BC6H
// volumes (DXGI 95) recorded at the padded size 364 × 184 × K, the 2D forms (unity/
// NAME_flipbook.exr, unreal/NAME_tiles.exr, godot/NAME_slices.exr) are 364 × 184 tiles of the
// decoded blocks, import settings keep BC6H, and the shaders (MeasuredBrdf*_bc6h.*) address
// 364 × 184. No engine kit samples the compact form: ExportLutWithEngines refuses kCompact with
// engines and lets max_error choose between BC6H and RGB9E5 only.
// Shader files carry the LUT layout in their constants; they are named MeasuredBrdf.* for the
// reference layout (θin 0, 20, 40, 60, one material) and MeasuredBrdf_<tag>.* otherwise, so
// materials of one layout share one file and different layouts never overwrite each other.
// Shared files written by several conversions of one batch have identical bytes and are
// written only when missing or different. The engine copies of OUT/NAME.ktx2, .dds and .exr are
// hard links to them when they were written (else written in full: the EXR then in half).
//
// A fit is carried as a fallback material: `brdf fit` results (FittedMaterial values:
// engine-model parameters such as unreal-defaultlit or unity-urp-lit, analytic models, each
// with its report) passed to ExportLutWithEngines (`brdf convert --engine-fits DIR`), written as
// their material files, and the fits the metadata carries (TextureMetadata::fitted_models_json,
// e.g. --extrapolate auto's GGX, verbatim), go into every manifest's "fallback_material":
// {"models": [...], "gltf": glTF 2.0 values derived from an unreal-defaultlit fit or null};
// null when there is no fit.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/fitted_material.h"
#include "brdf/core/lut.h"
#include "brdf/exporter/atlas.h"
#include "brdf/exporter/half.h"
#include "brdf/exporter/lut_export.h"
#include "brdf/exporter/metadata.h"
#include "brdf/exporter/packed_volume.h"

namespace brdf {
struct IblPack;
}  // namespace brdf

namespace brdf::engines {

struct EngineSet {
  bool unity = false, unreal = false, godot = false, web = false;
  bool Any() const { return unity || unreal || godot || web; }
};
// "unity", "unreal", "godot", "web", comma separated, or "all"; "" or "none" selects nothing.
// Throws InvalidArgument naming an unknown entry and the known ones.
EngineSet ParseEngines(std::string_view list);

// The folder names of the selected engines, in the order unity, unreal, godot, web.
std::vector<std::string> EngineFolderNames(const EngineSet& engines);

// What one conversion wrote.
struct EngineExportResult {
  exporter::LutExportResult lut;     // the regular outputs (ExportLut)
  std::vector<std::string> written;  // engine files, in engine order
};

// The one call `brdf convert` makes per input: exporter::ExportLut into OUT_DIR, then the
// engine folders OUT_DIR/<engine>/ for the selected engines (created when missing). Every file
// is written atomically; the per-material engine files of one call are synced together (each
// file's data before its rename, then each folder once), so no partial file is ever visible
// under a final name. Throws InvalidArgument / IoError.
// `fits`: `brdf fit` results for this material (ReadFitResults), carried into every
// manifest's "fallback_material" as their material files with the fit's error (after the fits
// the metadata carries); an unreal-defaultlit fit also gives the glTF 2.0 values
// (GltfFromUnrealDefaultLit).
EngineExportResult ExportLutWithEngines(const std::string& out_dir, const Lut& lut,
                                        exporter::TextureMetadata metadata,
                                        const exporter::LutExportOptions& options,
                                        const EngineSet& engines,
                                        const std::vector<FittedMaterial>& fits = {});

// The `brdf fit` results for material `name` in `fits_dir`: every file NAME.<model>.json there
// (the names `brdf fit INPUT... --out DIR` writes), each a material JSON object with its
// "model" and the fit report "fit" (rmse in 1/sr, per-slice errors), read by
// ParseFittedMaterialJson, in file-name order; none is fine (an empty list). Throws IoError
// when `fits_dir` is not a folder and FormatError naming a file that is not a fit result.
std::vector<FittedMaterial> ReadFitResults(const std::string& fits_dir, const std::string& name);

// glTF 2.0 material values (pbrMetallicRoughness with KHR_materials_specular) equivalent to an
// Unreal DefaultLit fit (brdf/core/models.h UnrealDefaultLit): baseColorFactor = Base Color
// (alpha 1), metallicFactor = Metallic, roughnessFactor = Roughness (both square it to GGX α),
// and the dielectric F0 = 0.08·Specular expressed as KHR_materials_specular's
// 0.04·specularColorFactor·specularFactor with specularFactor 1 and specularColorFactor
// 2·Specular (grey; the extension allows factors above 1). Differences that remain: glTF's
// Fresnel-weighted diffuse and Smith G against Unreal's Lambert and Vis_SmithJointApprox.
// `fit`: one unreal-defaultlit fit. Returns the JSON object text {"material": {...glTF
// material...}, "from": "unreal-defaultlit", "rmse": the fit's RMSE in 1/sr}. Throws
// InvalidArgument for another model.
std::string GltfFromUnrealDefaultLit(const FittedMaterial& fit);

// The files the engine folders would receive for `name` (for collision checks and cleanup);
// `bc6h`: the BC6H form may be written (it adds unity/NAME_flipbook.exr).
std::vector<std::string> EngineOutputPaths(const std::string& out_dir, const std::string& name,
                                           const EngineSet& engines, bool bc6h = false);

// What `--engine` must submit to brdf::CheckWritableOutputs (the one overwrite rule,
// brdf/core/file_util.h) before any work, for a run writing the materials (or atlas stems)
// `names` into `out_dir`: every per-material engine file (EngineOutputPaths), and every shared
// file the run could replace (importer, shaders, viewer, package.json; for shader files named
// after a layout, those already in the folder, since the layouts are known only after reading
// the inputs) that exists and was not written by this tool. A shared file this tool wrote (it
// says "generated by brdf-toolchain" in its first 512 bytes) is managed: it is brought up to
// date without --force, as one batch's materials all share it; any other file there is the
// user's and is replaced only with --force. Existing paths that are not regular files are
// listed too, so CheckWritableOutputs refuses them even with --force.
std::vector<std::string> EngineOutputsToCheck(const std::string& out_dir,
                                              const std::vector<std::string>& names,
                                              const EngineSet& engines, bool bc6h = false);

// The one call `brdf atlas` makes: exporter::WriteAtlas(prefix, ...), then the engine folders
// beside the prefix (<dir of prefix>/<engine>/<stem of prefix>.*), with shaders addressing
// cells (MeasuredBrdfCell with the cell origin the manifest lists per material).
// Returns every path written. Throws InvalidArgument / IoError.
// `compression`, `jobs` and `max_error` go to WriteAtlas (the engine folders stay RGB9E5).
std::vector<std::string> WriteAtlasWithEngines(
    const std::string& prefix, const std::vector<exporter::AtlasMaterial>& materials,
    const exporter::ExrOptions& exr_options, const EngineSet& engines,
    exporter::LutCompression compression = exporter::LutCompression::kNone, int jobs = 1,
    double max_error = 0);

// The RGBA16F payload of the Unreal DDS: every RGB9E5 channel converted to IEEE half
// directly from its mantissa and exponent (Rgb9e5ChannelToHalf: exact, no rounding), alpha =
// 1.0; 8 bytes per texel, little-endian, texels in PackedVolume order. The conversion export
// uses streams the same bytes into the file chunk by chunk instead of building this string.
std::string Rgba16fBytes(const exporter::PackedVolume& volume);
// The whole RGBA16F volume DDS (exporter::DdsVolumeHeader with DXGI format 10).
std::string EncodeRgba16fDds(const exporter::PackedVolume& volume);
// The IBL packs (brdf/core/ibl_pack.h) of a LUT (one) or of an atlas's cells (in cell order) as
// a DDS RGBA16F 2D texture (DXGI 10, one mip) of IblPack::kRows texels × packs.size() rows,
// row m for pack m, row 0 first in the file (at v = 0 without a flip); texel i of a row holds
// (S_r, S_g, S_b, α_eq) at μ_i, each float rounded to the nearest half (the diffuse part is the
// pack's diffuse_quadratic, passed as material constants). A linearly filtered, clamp-to-edge
// fetch at u = clamp(μ·kRows, 0.5, kRows − 0.5)/kRows returns IblPack::At(μ)'s specular and α.
// Throws InvalidArgument for no packs or a pack without kRows rows.
std::string EncodeIblPackDds(const std::vector<const IblPack*>& packs);

// Binary16 bits of the RGB9E5 channel value mantissa · 2^(exponent − 24) (mantissa 0..511,
// exponent 0..31; throws InvalidArgument outside). Exact: every such value has at most 9
// significant bits and lies in [2^−24, 65408], which half represents without rounding
// (subnormals below 2^−14).
std::uint16_t Rgb9e5ChannelToHalf(std::uint32_t mantissa, std::uint32_t exponent);
// IEEE 754 binary16 from any float (brdf/exporter/half.h), also used for the RGBA16F volumes.
using exporter::FloatToHalf;

}  // namespace brdf::engines
