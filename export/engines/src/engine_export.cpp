// The engine hand-off folders: which files go into which engine folder, the manifest, and the
// one call per conversion and per atlas (brdf/engines/engine_export.h).
#include "brdf/engines/engine_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <unordered_map>

#include <fmt/format.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/ibl_pack.h"
#include "brdf/core/lut_brdf.h"
#include "brdf/exporter/bc6h.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/exr.h"
#include "brdf/exporter/half.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/rgb9e5.h"
#include "brdf/exporter/shader_code.h"
#include "brdf/exporter/sidecar.h"
#include "engine_files.h"
#include "fit_results.h"
#include "rgba16f.h"
#include "staged_files.h"

namespace brdf::engines {

namespace fs = std::filesystem;
using ordered_json = nlohmann::ordered_json;
using detail::FallbackMaterialJson;
using detail::Handoff;
using detail::HandoffCell;
using detail::StagedFiles;
using detail::WriteRgba16fDds;

namespace {

enum class Engine { kUnity, kUnreal, kGodot, kWeb };

const char* FolderOf(Engine e) {
  switch (e) {
    case Engine::kUnity:
      return "unity";
    case Engine::kUnreal:
      return "unreal";
    case Engine::kGodot:
      return "godot";
    case Engine::kWeb:
      return "web";
  }
  return "";
}

std::vector<Engine> Selected(const EngineSet& s) {
  std::vector<Engine> out;
  if (s.unity) out.push_back(Engine::kUnity);
  if (s.unreal) out.push_back(Engine::kUnreal);
  if (s.godot) out.push_back(Engine::kGodot);
  if (s.web) out.push_back(Engine::kWeb);
  return out;
}

std::string NumberTag(double v) {
  std::string s = fmt::format("{:g}", v);
  std::replace(s.begin(), s.end(), '.', 'p');
  std::replace(s.begin(), s.end(), '-', 'm');
  return s;
}

// The per-material file names of one engine folder (shared files excluded). `bc6h`: the BC6H
// form, whose Unity folder also holds the block-aligned flipbook EXR.
struct MaterialFiles {
  std::string texture, manifest, tiles, tiles_import, ibl;
};

MaterialFiles FilesOf(Engine e, const std::string& name, bool bc6h = false) {
  MaterialFiles f;
  f.manifest = name + ".manifest.json";
  f.ibl = name + "_ibl.dds";
  switch (e) {
    case Engine::kUnity:
      f.texture = name + ".brdf3d";
      if (bc6h) f.tiles = name + "_flipbook.exr";
      break;
    case Engine::kUnreal:
      f.texture = name + ".dds";
      f.tiles = name + "_tiles.exr";
      break;
    case Engine::kGodot:
      f.texture = name + ".dds";
      f.tiles = name + "_slices.exr";
      f.tiles_import = name + "_slices.exr.import";
      break;
    case Engine::kWeb:
      f.texture = name + ".ktx2";
      break;
  }
  return f;
}

std::string ShaderFile(Engine e, const exporter::ShaderLutLayout& layout) {
  const std::string stem = detail::ShaderStem(layout);
  switch (e) {
    case Engine::kUnity:
      return stem + ".hlsl";
    case Engine::kUnreal:
      return stem + ".ush";
    case Engine::kGodot: {
      // Godot resource names are conventionally snake_case.
      std::string s = "measured_brdf" + stem.substr(std::string("MeasuredBrdf").size());
      return s + ".gdshader";
    }
    case Engine::kWeb: {
      std::string s = "measured_brdf" + stem.substr(std::string("MeasuredBrdf").size());
      return s + ".js";
    }
  }
  return stem;
}

// The BC6H blocks decoded over the whole padded size (BlocksWide·4 × BlocksHigh·4 × depth, RGB
// floats, x fastest): what a texture created at that size returns for every texel, the padding
// (repeats of the nearest edge texel before encoding) included.
std::vector<float> DecodePaddedBc6h(const exporter::Bc6hVolume& v) {
  const int bw = v.BlocksWide(), bh = v.BlocksHigh(), pw = 4 * bw, ph = 4 * bh;
  std::vector<float> out(static_cast<std::size_t>(pw) * ph * v.depth * 3);
  for (int z = 0; z < v.depth; ++z)
    for (int by = 0; by < bh; ++by)
      for (int bx = 0; bx < bw; ++bx) {
        const exporter::Bc6hHalfTexels t =
            exporter::DecodeBc6hBlock(&v.bytes[v.BlockOffset(4 * bx, 4 * by, z)]);
        for (int i = 0; i < 16; ++i) {
          const std::size_t at =
              ((static_cast<std::size_t>(z) * ph + 4 * by + i / 4) * pw + 4 * bx + i % 4) * 3;
          for (int c = 0; c < 3; ++c) out[at + c] = exporter::HalfToFloat(t[i][c]);
        }
      }
  return out;
}

// The same blocks recorded at the padded size (the engine folders' BC6H DDS files): a
// 364 × 184 × K texture whose padding texels repeat the LUT's edge texels.
exporter::Bc6hVolume AtPaddedSize(const exporter::Bc6hVolume& v) {
  exporter::Bc6hVolume padded = v;
  padded.width = 4 * v.BlocksWide();
  padded.height = 4 * v.BlocksHigh();
  return padded;
}

// The 2D form of the BC6H hand-off: the decoded padded slices as C × R tiles of the padded
// size (tile k = slice k, row-major from the top left, tiles past the last slice black), so
// every 4 × 4 block of the image lies inside one tile, as in the 3D texture.
exporter::FloatImage PaddedBc6hComposite(const Handoff& h, const std::vector<float>& decoded) {
  const int pw = h.layout.texture_width, ph = h.layout.texture_height;
  exporter::FloatImage image;
  image.width = h.composite.columns * pw;
  image.height = h.composite.rows * ph;
  image.rgb.assign(static_cast<std::size_t>(image.width) * image.height * 3, 0.0f);
  for (int k = 0; k < h.layout.slices; ++k) {
    const int x0 = h.composite.CellColumn(k) * pw, y0 = h.composite.CellRow(k) * ph;
    for (int y = 0; y < ph; ++y) {
      const float* src = &decoded[((static_cast<std::size_t>(k) * ph + y) * pw) * 3];
      std::copy(src, src + static_cast<std::size_t>(pw) * 3, image.Pixel(x0, y0 + y));
    }
  }
  return image;
}

ordered_json AxesJson(const Handoff& h) {
  const double last = h.layout.theta_in0_deg + h.layout.delta_in_deg * (h.layout.slices - 1);
  return ordered_json{
      {"u",
       {{"meaning", "phi_d: azimuth in the specular frame of theta_in (degrees)"},
        {"range_deg", {0, 360}},
        {"texels_per_cell", 361},
        {"texel_centre_deg", "i * 1 deg, i = 0..360 (column 360 repeats column 0)"}}},
      {"v",
       {{"meaning", "theta_d: polar angle from the mirror direction (degrees)"},
        {"range_deg", {0, 180}},
        {"texels_per_cell", 181},
        {"texel_centre_deg", "j * 1 deg, j = 0..180 (row 0 = the mirror direction)"}}},
      {"w",
       {{"meaning", "theta_in: incidence angle of the light (degrees)"},
        {"range_deg", {h.layout.theta_in0_deg, last}},
        {"texels", h.layout.slices},
        {"texel_centre_deg", fmt::format("{:g} + k * {:g} deg, k = 0..{}", h.layout.theta_in0_deg,
                                         h.layout.delta_in_deg, h.layout.slices - 1)},
        {"beyond_range", "clamp-to-edge: the first or last slice (constant extension)"}}}};
}

ordered_json ProbeJson(const Handoff& h) {
  const exporter::PackedVolume& vol = *h.volume;
  ordered_json probes = ordered_json::array();
  const bool few = h.cells.size() > 4;  // big atlases: three probes per cell and slice
  for (const HandoffCell& cell : h.cells) {
    for (int k = 0; k < vol.depth; ++k) {
      std::vector<std::pair<int, int>> ij = {{0, 0}, {180, 90}};
      if (!few) {
        ij.push_back({90, 45});
        ij.push_back({270, 135});
        ij.push_back({360, 180});
        ij.push_back({45, 10});
      }
      // The brightest texel of the slice (first one on ties): the peak of the lobe. Luminance
      // (Rec.709 weights 0.2126, 0.7152, 0.0722) compared exactly in integers: a texel's is
      // (2126 r_s + 7152 g_s + 722 b_s) · 2^e / 10^4 · 2^−24 with 9-bit mantissas, so the key
      // (2126 r_s + 7152 g_s + 722 b_s) << e (< 2^54) orders texels as their luminance does,
      // without decoding each texel of the slice.
      int best_i = 0, best_j = 0;
      std::uint64_t best = 0;
      bool any = false;
      for (int j = 0; j < 181; ++j) {
        const std::uint32_t* row = &vol.words[vol.Index(cell.x0, cell.y0 + j, k)];
        for (int i = 0; i < 361; ++i) {
          const std::uint32_t w = row[i];
          const std::uint64_t key = std::uint64_t{2126u * (w & 511u) + 7152u * ((w >> 9) & 511u) +
                                                  722u * ((w >> 18) & 511u)}
                                    << (w >> 27);
          if (key > best || !any) best = key, best_i = i, best_j = j, any = true;
        }
      }
      ij.push_back({best_i, best_j});
      for (const auto& [i, j] : ij) {
        const int x = cell.x0 + i, y = cell.y0 + j;
        std::array<float, 3> c{};
        if (h.bc6h) {
          // What a fetch of the BC6H texture returns (the peak was found in the RGB9E5 words).
          const std::size_t at = ((static_cast<std::size_t>(k) * h.layout.texture_height + y) *
                                      h.layout.texture_width +
                                  x) *
                                 3;
          c = {h.bc6h_decoded[at], h.bc6h_decoded[at + 1], h.bc6h_decoded[at + 2]};
        } else {
          c = exporter::DecodeRgb9e5(vol.words[vol.Index(x, y, k)]);
        }
        probes.push_back({{"material", cell.name},
                          {"index", {x, y, k}},
                          {"phi_d_deg", i},
                          {"theta_d_deg", j},
                          {"theta_in_deg", h.layout.theta_in0_deg + k * h.layout.delta_in_deg},
                          {"uvw",
                           {(x + 0.5) / h.layout.texture_width, (y + 0.5) / h.layout.texture_height,
                            (k + 0.5) / vol.depth}},
                          {"rgb", {c[0], c[1], c[2]}}});
      }
    }
  }
  return probes;
}

// What both forms of the kit (RGB9E5 and BC6H) say alike of an engine's folder.
constexpr const char* kUnityVersions =
    "Unity 2021.3 LTS to Unity 6 (URP, HDRP Shader Graph; built-in pipeline)";
constexpr const char* kUnrealVersions = "Unreal Engine 5.1 to 5.5";

ordered_json WebImportJson() {
  return {{"min_filter", "LinearFilter"},
          {"mag_filter", "LinearFilter"},
          {"wrap", "ClampToEdgeWrapping"},
          {"color_space", "NoColorSpace"}};
}

// One member of "engines" in the manifest, in the order every form writes it.
ordered_json SectionJson(Engine e, const std::string& versions, const ordered_json& files,
                         const ordered_json& format, const ordered_json& orientation,
                         const ordered_json& import) {
  return ordered_json{
      {"folder", FolderOf(e)},    {"engine_versions", versions}, {"files", files},
      {"texture_format", format}, {"orientation", orientation},  {"import", import}};
}

// The "engines" member of the BC6H form: every texture BC6H_UF16, created at the padded size.
ordered_json Bc6hEngineSectionJson(Engine e, const Handoff& h, const MaterialFiles& f) {
  const int pw = h.layout.texture_width, ph = h.layout.texture_height, k = h.layout.slices;
  ordered_json files = {
      {"texture", f.texture}, {"shader", ShaderFile(e, h.layout)}, {"manifest", f.manifest}};
  ordered_json orientation, import;
  std::string versions, format;
  const std::string padded = fmt::format(
      "created at {} x {} x {} (the 91 x 46 blocks of each slice; the padding texels repeat the "
      "edge texels, the shader addresses with {} and {})",
      pw, ph, k, pw, ph);
  const std::string tiles = fmt::format(
      "{} x {} tiles of {} x {} texels (block-aligned: texels 0..360 x 0..180 the LUT, the rest "
      "clamped repeats), row-major, top-left first, slice k in tile k; the BC6H texels decoded",
      h.composite.columns, h.composite.rows, pw, ph);
  const ordered_json tiles_json = {{"tile_width", pw},
                                   {"tile_height", ph},
                                   {"columns", h.composite.columns},
                                   {"rows", h.composite.rows}};
  switch (e) {
    case Engine::kUnity:
      versions = kUnityVersions;
      files["importer"] = "Editor/MeasuredBrdfImporter.cs";
      files["flipbook"] = f.tiles;
      format = "GraphicsFormat.RGB_BC6H_UFloat from the KTX2 (vkFormat 131), " + padded;
      orientation["scripted_importer"] =
          "file block rows uploaded in file order, row 0 (theta_d = 0) at v = 0, slice 0 at "
          "w = 0; no flip";
      orientation["flipbook_2d"] = f.tiles + ": " + tiles +
                                   "; imported by MeasuredBrdfFlipbookPostprocessor (in the "
                                   "importer file) as a Texture3D of those tiles";
      import = {
          { "flipbook",
            { {"file", f.tiles},
              {"texture_shape", "Texture3D"},
              {"columns", h.composite.columns},
              {"rows", h.composite.rows},
              {"npot_scale", "None"},
              {"srgb", false},
              {"mipmaps", false},
              {"wrap", "Clamp"},
              {"filter", "Bilinear"},
              {"format", "BC6H"},
              {"texture_compression", "CompressedHQ"},
              { "crunched",
                false } } }};
      break;
    case Engine::kUnreal:
      versions = kUnrealVersions;
      files["import_script"] = "import_measured_brdf.py";
      files["tiles"] = f.tiles;
      format = "DDS DXGI_FORMAT_BC6H_UF16 (95), volume, one mip, " + padded;
      orientation["volume_dds"] =
          "DDS texel (x, y, z) = Volume Texture texel (x, y, z); row 0 (theta_d = 0) first, at "
          "v = 0; no flip";
      orientation["tiles_2d"] = f.tiles + ": " + tiles + " (Source2DTileSizeX/Y)";
      import = {{"srgb", false},
                // The Python API's member name (unreal.TextureCompressionSettings), which the
                // import script reads: TC_HDR_Compressed, "HDR Compressed (RGB, BC6H, DX11)".
                {"compression_settings", "TC_HDR_COMPRESSED"},
                {"mip_gen_settings", "TMGS_NoMipmaps"},
                {"address_mode", "TA_Clamp"},
                {"filter", "TF_Bilinear"},
                { "tiles",
                  tiles_json }};
      break;
    case Engine::kGodot:
      versions = "Godot 4.2 to 4.5 (BC6H 3D DDS: 4.4 and later; sliced EXR: every 4.x)";
      files["tiles"] = f.tiles;
      files["tiles_import"] = f.tiles_import;
      format = "DDS DXGI_FORMAT_BC6H_UF16 (95), volume, one mip, " + padded;
      orientation["bc6h_dds"] =
          "DDS texel (x, y, z) = Texture3D texel (x, y, z); row 0 (theta_d = 0) first, at v = 0; "
          "no flip";
      orientation["sliced_exr"] = f.tiles + ": " + tiles + " (slices/horizontal, slices/vertical)";
      import = {{"slices_horizontal", h.composite.columns},
                {"slices_vertical", h.composite.rows},
                {"compress_mode", "VRAM Compressed"},
                {"high_quality", true},
                {"hdr_compression", "Always"},
                {"mipmaps", false},
                { "sampler",
                  "filter_linear, repeat_disable" }};
      break;
    case Engine::kWeb:
      versions =
          fmt::format("three.js r{} (0.{}.0) or later, WebGL 2 with EXT_texture_compression_bptc",
                      detail::kMinimumThreeRevision, detail::kMinimumThreeRevision);
      files["viewer"] = "index.html?material=" + h.name;
      format = fmt::format(
          "KTX2 vkFormat 131 (VK_FORMAT_BC6H_UFLOAT_BLOCK), {} x {} x {} in the file; "
          "loadMeasuredBrdfTexture {} (WebGL creates BPTC textures only at multiples of 4)",
          h.volume->width, h.volume->height, k, padded);
      orientation["webgl"] =
          "KTX2 blocks uploaded as stored (compressedTexImage3D, "
          "COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT); "
          "row 0 (theta_d = 0) at v = 0";
      import = WebImportJson();
      break;
  }
  return SectionJson(e, versions, files, format, orientation, import);
}

// What one engine's folder holds and how it imports (a member of "engines" in the manifest).
ordered_json EngineSectionJson(Engine e, const Handoff& h) {
  const exporter::PackedVolume& vol = *h.volume;
  const MaterialFiles f = FilesOf(e, h.name, h.bc6h != nullptr);
  if (h.bc6h) return Bc6hEngineSectionJson(e, h, f);
  ordered_json files = {
      {"texture", f.texture}, {"shader", ShaderFile(e, h.layout)}, {"manifest", f.manifest}};
  ordered_json texture;
  ordered_json orientation, import;
  std::string versions;
  const std::string tiles =
      fmt::format("{} x {} tiles of {} x {} texels, row-major, top-left first, slice k in tile k",
                  h.composite.columns, h.composite.rows, vol.width, vol.height);
  switch (e) {
    case Engine::kUnity:
      versions = kUnityVersions;
      files["importer"] = "Editor/MeasuredBrdfImporter.cs";
      texture["format"] = "GraphicsFormat.E5B9G9R9_UFloatPack32 (fallback R16G16B16A16_SFloat)";
      orientation["scripted_importer"] =
          "file texel (x, y, z) = Texture3D texel (x, y, z): rows uploaded in file order, row 0 "
          "(theta_d = 0) at v = 0, slice 0 at w = 0; no flip";
      orientation["flipbook_2d"] =
          "the composite EXR (../" + h.name + ".exr) imported with Texture Shape 3D, Columns " +
          std::to_string(h.composite.columns) + ", Rows " + std::to_string(h.composite.rows) +
          ": " + tiles +
          "; exact tiles, no gutters; Non-Power of 2 None, sRGB off, no mipmaps, clamp, bilinear; "
          "check slice order against the probe texels";
      import = {
          { "flipbook",
            { {"columns", h.composite.columns},
              {"rows", h.composite.rows},
              {"npot_scale", "None"},
              {"srgb", false},
              { "mipmaps",
                false } } }};
      break;
    case Engine::kUnreal:
      versions = kUnrealVersions;
      files["import_script"] = "import_measured_brdf.py";
      files["tiles"] = f.tiles;
      texture["format"] = "DDS DXGI_FORMAT_R16G16B16A16_FLOAT (10), volume, one mip; alpha 1";
      orientation["volume_dds"] =
          "DDS texel (x, y, z) = Volume Texture texel (x, y, z); row 0 (theta_d = 0) first, at "
          "v = 0; no flip";
      orientation["tiles_2d"] = f.tiles + ": " + tiles + " (Source2DTileSizeX/Y)";
      import = {{"srgb", false},
                {"compression_settings", "TC_HDR"},
                {"mip_gen_settings", "TMGS_NoMipmaps"},
                {"address_mode", "TA_Clamp"},
                {"filter", "TF_Bilinear"},
                { "tiles",
                  { {"tile_width", vol.width},
                    {"tile_height", vol.height},
                    {"columns", h.composite.columns},
                    { "rows",
                      h.composite.rows } } }};
      break;
    case Engine::kGodot:
      versions = "Godot 4.2 to 4.5 (RGB9E5 3D DDS: 4.4 and later; sliced EXR: every 4.x)";
      files["tiles"] = f.tiles;
      files["tiles_import"] = f.tiles_import;
      texture["format"] = "DDS DXGI_FORMAT_R9G9B9E5_SHAREDEXP (67), volume, one mip";
      orientation["rgb9e5_dds"] =
          "DDS texel (x, y, z) = Texture3D texel (x, y, z); row 0 (theta_d = 0) first, at v = 0; "
          "no flip";
      orientation["sliced_exr"] = f.tiles + ": " + tiles + " (slices/horizontal, slices/vertical)";
      import = {{"slices_horizontal", h.composite.columns},
                {"slices_vertical", h.composite.rows},
                {"compress_mode", "VRAM Uncompressed"},
                {"mipmaps", false},
                { "sampler",
                  "filter_linear, repeat_disable" }};
      break;
    case Engine::kWeb:
      versions = fmt::format("three.js r{} (0.{}.0) or later, WebGL 2",
                             detail::kMinimumThreeRevision, detail::kMinimumThreeRevision);
      files["viewer"] = "index.html?material=" + h.name;
      texture["format"] = "KTX2 vkFormat 123 (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32), uncompressed";
      orientation["ktx2loader"] =
          "KTX2 texel (x, y, z) = Data3DTexture texel (x, y, z) (KTXorientation rdi; three.js "
          "does not flip 3D textures); row 0 (theta_d = 0) at v = 0";
      import = WebImportJson();
      break;
  }
  return SectionJson(e, versions, files, texture["format"], orientation, import);
}

// The manifest's "ibl": for a LUT its pack (IblPackJson) with "texture"; for an atlas "texture"
// and "cells", one pack per cell with its material and row.
ordered_json IblJson(const Handoff& h) {
  constexpr int kRows = IblPack::kRows;
  ordered_json texture = {
      {"file", h.name + "_ibl.dds"},
      {"format", "DDS DXGI_FORMAT_R16G16B16A16_FLOAT (10), 2D, one mip; halves of the values here"},
      {"width", kRows},
      {"height", h.ibl.size()},
      {"row_of_material", "row m = cell m (0 for a single LUT), row 0 first in the file, at v = 0"},
      {"texels",
       "texel i: (specular_rgb, alpha_eq) at mu_i; the diffuse part is not in the "
       "texture: D_fit(mu) = c0 + c1 t + c2 t^2 (t = 1 - mu) from "
       "diffuse_quadratic_rgb, material constants"},
      {"sampling",
       fmt::format("linear, clamp-to-edge, no mipmaps, no sRGB decode; u = clamp(mu * {0}, 0.5, "
                   "{1}) / {0}, v = (row + 0.5) / height; D_fit at the same clamped mu = u",
                   kRows, kRows - 0.5)}};
  if (!h.atlas) {
    ordered_json j = ordered_json::parse(IblPackJson(h.ibl.at(0)));
    j["texture"] = texture;
    j["row"] = 0;
    return j;
  }
  ordered_json cells = ordered_json::array();
  for (std::size_t m = 0; m < h.ibl.size(); ++m) {
    ordered_json c = {{"material", h.cells[m].name}, {"row", m}};
    c.update(ordered_json::parse(IblPackJson(h.ibl[m])));
    cells.push_back(std::move(c));
  }
  return ordered_json{{"texture", texture}, {"cells", cells}};
}

// One manifest per material for every engine folder of the conversion (the same text in each,
// hard-linked): the common description, then "engines" with one member per selected engine.
std::string ManifestJson(const Handoff& h, const std::vector<Engine>& engines) {
  const exporter::PackedVolume& vol = *h.volume;
  ordered_json cells = ordered_json::array();
  for (const HandoffCell& c : h.cells)
    cells.push_back({{"material", c.name}, {"x0", c.x0}, {"y0", c.y0}});
  ordered_json sections = ordered_json::object();
  for (Engine e : engines) sections[FolderOf(e)] = EngineSectionJson(e, h);
  ordered_json j = {
      {"kind", "brdf-engine-manifest"},
      {"format_version", 1},
      {"name", h.name},
      {"source", h.source},
      {"atlas", h.atlas},
      {"texture",
       {{"width", h.layout.texture_width},
        {"height", h.layout.texture_height},
        {"depth", vol.depth},
        {"mip_levels", 1},
        {"block_format", h.bc6h ? "bc6h_ufloat" : "none"},
        {"lut_texels", {vol.width, vol.height}},
        {"colour_space", "linear Rec.709 RGB; sample without sRGB decode"},
        {"sampler", "linear (trilinear), clamp-to-edge on u, v and w, no mipmaps"}}},
      {"theta_in_deg", h.theta_in_deg},
      {"axes", AxesJson(h)},
      {"texel_centre_mapping",
       {{"centre_exact", exporter::TexelCentreFormula()},
        {"cell", fmt::format("u = (x0 + phi_d/1deg + 0.5)/{}, v = (y0 + theta_d/1deg + 0.5)/{}, "
                             "clamped to the cell's outer texel centres{}",
                             h.layout.texture_width, h.layout.texture_height,
                             h.bc6h ? " (BC6H: the padded size, in place of 361 and 181)" : "")},
        {"published", exporter::PublishedFormula()}}},
      {"units",
       "f_r in 1/sr, linear Rec.709 RGB, not multiplied by cos(theta); radiance = f_r * "
       "E * max(n.l, 0) for a directional light of irradiance E at normal incidence"},
      {"shader_contract",
       "MeasuredBrdf(n, l, v): unit vectors away from the surface in one frame; tangent frame "
       "from the light (x = l projected on the tangent plane, phi_in = 0); omega_d = "
       "S(theta_in) v; theta_d = atan2(|omega_d.xy|, omega_d.z)"},
      {"cells", cells},
      {"probe_texels", ProbeJson(h)},
      {"fallback_material", FallbackMaterialJson(h.fitted_models_json, h.fits)},
      {"ibl", IblJson(h)},
      {"engines", sections},
      {"tool", {{"name", "brdf-toolchain"}, {"version", exporter::BrdfToolVersion()}}}};
  return j.dump(2) + "\n";
}

// The regular outputs an engine file can be a hard link to (empty when not written), and the
// data to write instead when it is not there.
struct Sources {
  std::string ktx2_path, dds_path, exr_path;  // OUT/NAME.ktx2, .dds, .exr
  std::function<std::string()> ktx2_bytes;
  std::function<exporter::FloatImage()> composite;
};

// Files every material of a layout shares (importer, shaders, viewer): their text is a function
// of their path alone, so once this process has written one or found it identical, later
// materials of the batch only check that it is still there with that size (one stat) instead of
// generating the text and reading the file again.
class SharedFiles {
 public:
  static SharedFiles& Instance() {
    static SharedFiles instance;
    return instance;
  }
  // Writes `path` with text() when it is missing or different; returns true when written.
  template <class Text>
  bool Ensure(const std::string& path, Text&& text) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (const auto it = sizes_.find(path); it != sizes_.end()) {
        std::error_code ec;
        if (fs::file_size(path, ec) == it->second && !ec) return false;
      }
    }
    const std::string bytes = text();
    const bool write = !SameContent(path, bytes);
    if (write) WriteFileAtomically(path, bytes);
    const std::lock_guard<std::mutex> lock(mutex_);
    sizes_[path] = bytes.size();
    return write;
  }

 private:
  static bool SameContent(const std::string& path, std::string_view bytes) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) != bytes.size()) return false;
    return ReadFileText(path, bytes.size()) == bytes;
  }
  std::mutex mutex_;
  std::unordered_map<std::string, std::uintmax_t> sizes_;
};

// Stages one engine folder's per-material files in `staged` and writes its shared files;
// returns the shared files it had to write.
std::vector<std::string> StageEngineFolder(Engine e, const fs::path& dir, const Handoff& h,
                                           const Sources& src, StagedFiles& staged,
                                           std::string& manifest_temp, const std::string& manifest,
                                           const std::string& ibl_dds) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir))
    throw IoError(dir.string() + ": cannot create the engine folder" +
                  (ec ? ": " + ec.message() : std::string()));
  const MaterialFiles f = FilesOf(e, h.name, h.bc6h != nullptr);
  const std::string shader = ShaderFile(e, h.layout);
  std::vector<std::string> written;
  const auto path_of = [&](const std::string& file) { return (dir / file).string(); };
  const auto shared = [&](const std::string& file, auto&& text) {
    if (SharedFiles::Instance().Ensure(path_of(file), text)) written.push_back(path_of(file));
  };
  const auto linked = [&](const std::string& file, const std::string& source,
                          const std::function<std::string()>& bytes) {
    if (!staged.Link(source, path_of(file))) staged.Write(path_of(file), bytes());
  };
  // The tiled/sliced EXR: the regular composite EXR when there is one (same layout), else a
  // half-float one written here.
  const auto tiles = [&](const std::string& file) {
    const std::string path = path_of(file);
    if (h.bc6h) {
      // The block-aligned tiles of the BC6H form (never the regular 361 × 181 composite).
      exporter::WriteExr(
          path, PaddedBc6hComposite(h, h.bc6h_decoded),
          exporter::ExrOptions(exporter::ExrPixelType::kHalf, exporter::ExrCompression::kZip),
          {{"brdf:theta_in_deg", exporter::FormatThetaList(h.theta_in_deg)},
           {"brdf:layout",
            fmt::format("{} x {} tiles of {} x {} (the LUT's 361 x 181 texels, then clamped "
                        "repeats to whole 4 x 4 blocks), row-major, top-left first; BC6H texels",
                        h.composite.columns, h.composite.rows, h.layout.texture_width,
                        h.layout.texture_height)},
           {"brdf:texel_convention", exporter::TexelCentreFormula()}});
      written.push_back(path);
      return;
    }
    if (staged.Link(src.exr_path, path)) return;
    exporter::WriteExr(
        path, src.composite(),
        exporter::ExrOptions(exporter::ExrPixelType::kHalf, exporter::ExrCompression::kNone),
        {{"brdf:theta_in_deg", exporter::FormatThetaList(h.theta_in_deg)},
         {"brdf:layout",
          fmt::format("{} x {} tiles of {} x {}, row-major, top-left first", h.composite.columns,
                      h.composite.rows, h.volume->width, h.volume->height)},
         {"brdf:texel_convention", exporter::TexelCentreFormula()}});
    written.push_back(path);
  };
  switch (e) {
    case Engine::kUnity:
      linked(f.texture, src.ktx2_path, src.ktx2_bytes);
      if (h.bc6h) tiles(f.tiles);
      shared("Editor/MeasuredBrdfImporter.cs", [&] {
        std::error_code dir_ec;
        fs::create_directories(dir / "Editor", dir_ec);
        return detail::UnityImporterCs();
      });
      shared(shader, [&] { return detail::UnityHlsl(h.layout); });
      break;
    case Engine::kUnreal:
      tiles(f.tiles);
      if (h.bc6h)
        staged.Write(path_of(f.texture), exporter::EncodeDds(AtPaddedSize(*h.bc6h)));
      else
        staged.WriteWith(path_of(f.texture),
                         [&](StagedFiles::Writer& w) { WriteRgba16fDds(w, *h.volume); });
      shared(shader, [&] { return detail::UnrealUsh(h.layout); });
      shared("import_measured_brdf.py", [] { return detail::UnrealImportPython(); });
      break;
    case Engine::kGodot:
      if (h.bc6h)
        staged.Write(path_of(f.texture), exporter::EncodeDds(AtPaddedSize(*h.bc6h)));
      else
        linked(f.texture, src.dds_path, [&] { return exporter::EncodeDds(*h.volume); });
      tiles(f.tiles);
      staged.Write(path_of(f.tiles_import), detail::GodotSlicesImport(h, f.tiles));
      shared(shader, [&] { return detail::GodotShader(h.layout); });
      break;
    case Engine::kWeb:
      linked(f.texture, src.ktx2_path, src.ktx2_bytes);
      shared(shader, [&] { return detail::WebModuleJs(h.layout); });
      shared("index.html", [] { return detail::WebViewerHtml(); });
      shared("package.json", [] { return detail::WebPackageJson(); });
      // The same lookup as plain GLSL files for other WebGL 2 / OpenGL code.
      shared(detail::ShaderStem(h.layout) + ".es300.glsl", [&] {
        return exporter::MeasuredBrdfGlslFile(exporter::GlslVersion::kEs300, h.layout);
      });
      shared(detail::ShaderStem(h.layout) + ".450.glsl",
             [&] { return exporter::MeasuredBrdfGlslFile(exporter::GlslVersion::k450, h.layout); });
      // The decoder of the compact form (`--compress compact`, .brdfc) of a single LUT.
      if (h.layout.texture_width == Lut::kWidth && h.layout.texture_height == Lut::kHeight)
        shared(detail::ShaderStem(h.layout) + ".compact.es300.glsl",
               [&] { return exporter::CompactBrdfGlslFile(h.layout); });
      break;
  }
  staged.Write(path_of(f.ibl), ibl_dds);
  // The manifest: written into the first folder, hard-linked (from its temporary name) into
  // the others.
  const std::string manifest_path = path_of(f.manifest);
  if (!staged.Link(manifest_temp, manifest_path)) {
    staged.Write(manifest_path, manifest);
    manifest_temp = staged.temp_path_of_last();
  }
  return written;
}

std::vector<std::string> WriteHandoff(const fs::path& base, const Handoff& h, const Sources& src,
                                      const EngineSet& engines) {
  const std::vector<Engine> selected = Selected(engines);
  const std::string manifest = ManifestJson(h, selected);
  std::vector<const IblPack*> packs;
  for (const IblPack& p : h.ibl) packs.push_back(&p);
  const std::string ibl_dds = EncodeIblPackDds(packs);
  StagedFiles staged;
  std::string manifest_temp;
  std::vector<std::string> shared;
  for (Engine e : selected) {
    const auto w =
        StageEngineFolder(e, base / FolderOf(e), h, src, staged, manifest_temp, manifest, ibl_dds);
    shared.insert(shared.end(), w.begin(), w.end());
  }
  staged.Commit();
  std::vector<std::string> written = staged.paths();
  written.insert(written.end(), shared.begin(), shared.end());
  return written;
}

}  // namespace

namespace detail {

std::string ShaderStem(const exporter::ShaderLutLayout& l) {
  const bool reference_slices = l.slices == 4 && l.delta_in_deg == 20 && l.theta_in0_deg == 0;
  const bool single = l.texture_width == 361 && l.texture_height == 181;
  // A single BC6H LUT, padded to whole blocks (an atlas is a multiple of 361 × 181).
  const bool bc6h = l.texture_width == 364 && l.texture_height == 184;
  if (reference_slices && single) return "MeasuredBrdf";
  if (reference_slices && bc6h) return "MeasuredBrdf_bc6h";
  std::string s = fmt::format("MeasuredBrdf_{}x{}from{}", l.slices, NumberTag(l.delta_in_deg),
                              NumberTag(l.theta_in0_deg));
  if (bc6h)
    s += "_bc6h";
  else if (!single)
    s += fmt::format("_{}x{}", l.texture_width, l.texture_height);
  return s;
}

}  // namespace detail

EngineSet ParseEngines(std::string_view list) {
  EngineSet s;
  if (list.empty() || list == "none") return s;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string_view item = list.substr(start, comma - start);
    if (item == "unity") {
      s.unity = true;
    } else if (item == "unreal") {
      s.unreal = true;
    } else if (item == "godot") {
      s.godot = true;
    } else if (item == "web") {
      s.web = true;
    } else if (item == "all") {
      s = {true, true, true, true};
    } else {
      throw InvalidArgument("unknown engine '" + std::string(item) +
                            "' (known: unity, unreal, godot, web, all)");
    }
    start = comma + 1;
  }
  return s;
}

std::vector<std::string> EngineFolderNames(const EngineSet& engines) {
  std::vector<std::string> out;
  for (Engine e : Selected(engines)) out.push_back(FolderOf(e));
  return out;
}

std::vector<std::string> EngineOutputPaths(const std::string& out_dir, const std::string& name,
                                           const EngineSet& engines, bool bc6h) {
  std::vector<std::string> paths;
  const fs::path base(out_dir);
  for (Engine e : Selected(engines)) {
    const MaterialFiles f = FilesOf(e, name, bc6h);
    for (const std::string* file : {&f.texture, &f.tiles, &f.tiles_import, &f.ibl, &f.manifest})
      if (!file->empty()) paths.push_back((base / FolderOf(e) / *file).string());
  }
  return paths;
}

namespace {

// The marker every shared file carries in its first lines (importer, shaders, viewer, package).
constexpr std::string_view kManagedMarker = "generated by brdf-toolchain";

// Shared files `e` may write into `dir`: the fixed names, and the existing files named like a
// layout's shader file (prefix + suffix).
std::vector<std::string> SharedFileCandidates(Engine e, const fs::path& dir) {
  std::vector<std::string> fixed;
  std::vector<std::pair<std::string, std::string>> shaders;  // prefix, suffix
  switch (e) {
    case Engine::kUnity:
      fixed = {"Editor/MeasuredBrdfImporter.cs"};
      shaders = {{"MeasuredBrdf", ".hlsl"}};
      break;
    case Engine::kUnreal:
      fixed = {"import_measured_brdf.py"};
      shaders = {{"MeasuredBrdf", ".ush"}};
      break;
    case Engine::kGodot:
      shaders = {{"measured_brdf", ".gdshader"}};
      break;
    case Engine::kWeb:
      fixed = {"index.html", "package.json"};
      shaders = {
          {"measured_brdf", ".js"}, {"MeasuredBrdf", ".es300.glsl"}, {"MeasuredBrdf", ".450.glsl"}};
      break;
  }
  std::vector<std::string> out;
  for (const std::string& f : fixed) out.push_back((dir / f).string());
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    for (const auto& [prefix, suffix] : shaders)
      if (name.size() > prefix.size() + suffix.size() && name.starts_with(prefix) &&
          name.ends_with(suffix))
        out.push_back(it->path().string());
  }
  return out;
}

// True when `path` is a regular file this tool wrote (kManagedMarker near its start).
bool IsManagedSharedFile(const std::string& path) {
  try {
    return ReadFileHead(path, 512).find(kManagedMarker) != std::string::npos;
  } catch (const Error&) {
    return false;
  }
}

}  // namespace

std::vector<std::string> EngineOutputsToCheck(const std::string& out_dir,
                                              const std::vector<std::string>& names,
                                              const EngineSet& engines, bool bc6h) {
  std::vector<std::string> paths;
  for (const std::string& name : names)
    for (std::string& p : EngineOutputPaths(out_dir, name, engines, bc6h))
      paths.push_back(std::move(p));
  for (Engine e : Selected(engines))
    for (std::string& p : SharedFileCandidates(e, fs::path(out_dir) / FolderOf(e))) {
      std::error_code ec;
      const fs::file_status st = fs::status(p, ec);
      if (ec || !fs::exists(st)) continue;
      if (fs::is_regular_file(st) && IsManagedSharedFile(p)) continue;
      paths.push_back(std::move(p));
    }
  return paths;
}

EngineExportResult ExportLutWithEngines(const std::string& out_dir, const Lut& lut,
                                        exporter::TextureMetadata metadata,
                                        const exporter::LutExportOptions& options,
                                        const EngineSet& engines,
                                        const std::vector<FittedMaterial>& fits) {
  EngineExportResult result;
  const exporter::PackedVolume packed = exporter::PackLut(lut);
  exporter::LutExportOptions lut_options = options;
  if (engines.Any()) {
    // No engine kit samples the compact form (the web kit ships its GLSL decoder, but no
    // loader): --max-error picks BC6H or RGB9E5 for the hand-offs.
    if (options.max_error <= 0 && options.compression == exporter::LutCompression::kCompact)
      throw InvalidArgument(
          "--compress compact: no engine kit samples the compact form; with --engine use "
          "--compress bc6h, --max-error (BC6H or RGB9E5), or no --compress");
    lut_options.max_error_allows_compact = false;
  }
  result.lut = exporter::ExportLut(out_dir, lut, packed, metadata, lut_options);
  if (!engines.Any()) return result;
  Handoff h;
  h.name = metadata.name;
  h.source = metadata.source;
  h.volume = &packed;
  h.theta_in_deg = lut.theta_in_deg;
  h.layout = exporter::LutShaderLayout(lut.theta_in_deg);
  if (result.lut.bc6h) {
    h.bc6h = &*result.lut.bc6h;
    h.bc6h_decoded = DecodePaddedBc6h(*h.bc6h);
    h.layout.texture_width = 4 * h.bc6h->BlocksWide();
    h.layout.texture_height = 4 * h.bc6h->BlocksHigh();
    metadata.certified_error = result.lut.certified_error;
  }
  h.cells = {{metadata.name, 0, 0}};
  h.composite = exporter::SquareishGrid(lut.slices());
  h.fitted_models_json = metadata.fitted_models_json;
  h.fits = fits;
  // Image-based lighting: the pack of this LUT evaluated by its own rule (brdf/core/ibl_pack.h).
  h.ibl = {ComputeIblPack(LutBrdf(lut, metadata.name))};
  const fs::path dir(out_dir);
  const auto main_file = [&](bool written, const char* ext) {
    return written ? (dir / (metadata.name + ext)).string() : std::string();
  };
  Sources src;
  src.ktx2_path = main_file(options.formats.ktx2, ".ktx2");
  src.dds_path = main_file(options.formats.dds, ".dds");
  src.exr_path = main_file(options.formats.exr, ".exr");
  src.ktx2_bytes = [&] {
    if (h.bc6h)
      return exporter::EncodeKtx2(
          *h.bc6h, {{"brdf.sidecar", exporter::SidecarJson(*h.bc6h, lut.theta_in_deg, metadata)}});
    return exporter::EncodeKtx2(
        packed, {{"brdf.sidecar", exporter::SidecarJson(packed, lut.theta_in_deg, metadata)}});
  };
  src.composite = [&] { return exporter::CompositeImage(lut); };
  result.written = WriteHandoff(dir, h, src, engines);
  return result;
}

std::vector<std::string> WriteAtlasWithEngines(
    const std::string& prefix, const std::vector<exporter::AtlasMaterial>& materials,
    const exporter::ExrOptions& exr_options, const EngineSet& engines,
    exporter::LutCompression compression, int jobs, double max_error) {
  std::vector<std::string> written =
      exporter::WriteAtlas(prefix, materials, exr_options, compression, jobs, max_error);
  if (!engines.Any()) return written;
  const exporter::Atlas atlas = exporter::BuildAtlas(materials);
  const fs::path prefix_path(prefix);
  Handoff h;
  h.name = prefix_path.filename().string();
  h.atlas = true;
  h.volume = &atlas.volume;
  h.theta_in_deg = atlas.theta_in_deg;
  h.layout = exporter::LutShaderLayout(atlas.theta_in_deg);
  h.layout.texture_width = atlas.layout.TextureWidth();
  h.layout.texture_height = atlas.layout.TextureHeight();
  h.composite = atlas.layout.composite;
  for (int m = 0; m < atlas.layout.materials; ++m) {
    h.cells.push_back({atlas.names[m], atlas.layout.cells.CellColumn(m) * Lut::kWidth,
                       atlas.layout.cells.CellRow(m) * Lut::kHeight});
    h.source += (m ? ", " : "") + atlas.sources[m];
  }
  // One IBL pack per cell, from the material's own LUT (the atlas holds the same texels).
  for (const exporter::AtlasMaterial& m : materials)
    h.ibl.push_back(ComputeIblPack(LutBrdf(*m.lut, m.name)));
  const fs::path base = prefix_path.has_parent_path() ? prefix_path.parent_path() : fs::path(".");
  Sources src;  // WriteAtlas wrote all three
  src.ktx2_path = prefix + ".ktx2";
  src.dds_path = prefix + ".dds";
  src.exr_path = prefix + ".exr";
  src.ktx2_bytes = [&] {
    return exporter::EncodeKtx2(
        atlas.volume,
        {{"brdf.atlas", exporter::AtlasManifestJson(atlas, {h.name + ".ktx2", h.name + ".dds",
                                                            h.name + ".exr", h.name + ".json"})}});
  };
  src.composite = [&] { return exporter::AtlasImage(materials); };
  const auto w = WriteHandoff(base, h, src, engines);
  written.insert(written.end(), w.begin(), w.end());
  return written;
}

}  // namespace brdf::engines
