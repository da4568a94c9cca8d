#include "brdf/exporter/atlas.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/text_format.h"
#include "brdf/exporter/dds.h"
#include "brdf/exporter/ktx2.h"
#include "brdf/exporter/rgb9e5.h"
#include "json_util.h"

namespace brdf::exporter {

using detail::ordered_json;

AtlasLayout ComputeAtlasLayout(int materials, int slices) {
  if (materials < 1) throw InvalidArgument("atlas: need at least one material");
  if (slices < 1) throw InvalidArgument("atlas: need at least one θin slice");
  AtlasLayout layout;
  layout.materials = materials;
  layout.slices = slices;
  layout.cells = SquareishGrid(materials);
  layout.composite = SquareishGrid(slices);
  return layout;
}

namespace {

// Validates the list and returns the common θin list.
std::vector<double> CheckMaterials(const std::vector<AtlasMaterial>& materials) {
  if (materials.empty()) throw InvalidArgument("atlas: need at least one material");
  std::set<std::string> names;
  for (const AtlasMaterial& m : materials) {
    if (m.lut == nullptr) throw InvalidArgument("atlas: material '" + m.name + "' has no LUT");
    try {
      ValidateLutForExport(*m.lut);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument("atlas: material '" + m.name + "': " + e.what());
    }
    if (!names.insert(m.name).second)
      throw InvalidArgument("atlas: material name '" + m.name +
                            "' appears twice; names must be unique");
  }
  const AtlasMaterial& first = materials.front();
  for (const AtlasMaterial& m : materials)
    if (m.lut->theta_in_deg != first.lut->theta_in_deg)
      throw InvalidArgument(fmt::format(
          "atlas: materials '{}' (θin {}) and '{}' (θin {}) have different θin sets; an atlas "
          "needs one θin list",
          first.name, FormatThetaList(first.lut->theta_in_deg), m.name,
          FormatThetaList(m.lut->theta_in_deg)));
  return first.lut->theta_in_deg;
}

}  // namespace

Atlas BuildAtlas(const std::vector<AtlasMaterial>& materials) {
  Atlas atlas;
  atlas.theta_in_deg = CheckMaterials(materials);
  atlas.layout = ComputeAtlasLayout(static_cast<int>(materials.size()),
                                    static_cast<int>(atlas.theta_in_deg.size()));
  PackedVolume& v = atlas.volume;
  v.width = atlas.layout.TextureWidth();
  v.height = atlas.layout.TextureHeight();
  v.depth = atlas.layout.slices;
  v.words.assign(static_cast<std::size_t>(v.width) * v.height * v.depth, 0u);
  for (std::size_t m = 0; m < materials.size(); ++m) {
    atlas.names.push_back(materials[m].name);
    atlas.sources.push_back(materials[m].source);
    atlas.saturated_samples.push_back(materials[m].saturated_samples);
    atlas.extrapolation.push_back(materials[m].extrapolation);
    atlas.fitted_models_json.push_back(materials[m].fitted_models_json);
    atlas.beyond_json.push_back(materials[m].beyond_json);
    const Lut& lut = *materials[m].lut;
    const int x0 = atlas.layout.cells.CellColumn(static_cast<int>(m)) * Lut::kWidth;
    const int y0 = atlas.layout.cells.CellRow(static_cast<int>(m)) * Lut::kHeight;
    for (int k = 0; k < v.depth; ++k)
      for (int j = 0; j < Lut::kHeight; ++j) {
        std::uint32_t* row = &v.words[v.Index(x0, y0 + j, k)];
        for (int i = 0; i < Lut::kWidth; ++i) row[i] = EncodeRgb9e5(lut.Texel(k, j, i));
      }
  }
  return atlas;
}

void CompressAtlasBc6h(Atlas& atlas, const std::vector<AtlasMaterial>& materials, int jobs) {
  const AtlasLayout& l = atlas.layout;
  const int w = l.TextureWidth(), h = l.TextureHeight(), d = l.slices;
  std::vector<float> texels(static_cast<std::size_t>(w) * h * d * 3, 0.0f);
  const auto cell_origin = [&](std::size_t m) {
    return std::array<int, 2>{l.cells.CellColumn(static_cast<int>(m)) * Lut::kWidth,
                              l.cells.CellRow(static_cast<int>(m)) * Lut::kHeight};
  };
  for (std::size_t m = 0; m < materials.size(); ++m) {
    const auto [x0, y0] = cell_origin(m);
    for (int k = 0; k < d; ++k)
      for (int j = 0; j < Lut::kHeight; ++j)
        std::copy_n(materials[m].lut->Texel(k, j, 0), Lut::kWidth * 3,
                    &texels[((static_cast<std::size_t>(k) * h + y0 + j) * w + x0) * 3]);
  }
  atlas.bc6h = EncodeBc6hVolume(texels.data(), w, h, d, jobs);
  const std::vector<float> decoded = DecodeBc6hVolume(*atlas.bc6h);
  atlas.certified_error.clear();
  for (std::size_t m = 0; m < materials.size(); ++m) {
    const auto [x0, y0] = cell_origin(m);
    std::vector<float> cell(static_cast<std::size_t>(d) * Lut::kHeight * Lut::kWidth * 3);
    for (int k = 0; k < d; ++k)
      for (int j = 0; j < Lut::kHeight; ++j)
        std::copy_n(&decoded[((static_cast<std::size_t>(k) * h + y0 + j) * w + x0) * 3],
                    Lut::kWidth * 3,
                    &cell[((static_cast<std::size_t>(k) * Lut::kHeight + j) * Lut::kWidth) * 3]);
    const std::optional<ExtrapolationInfo>& x = materials[m].extrapolation;
    CertifiedError e = MeasureCompressionError(*materials[m].lut, cell, x ? x->theta_b_deg : 90.0);
    e.format = "bc6h_ufloat";
    e.bytes = atlas.bc6h->ByteSize();
    e.rgb9e5_bytes = atlas.volume.ByteSize();
    atlas.certified_error.push_back(e);
  }
}

LutCompression ChooseAtlasCompression(Atlas& atlas, const std::vector<AtlasMaterial>& materials,
                                      double max_error, int jobs) {
  if (!(max_error > 0 && max_error < 1))
    throw InvalidArgument(
        fmt::format("atlas: --max-error must be a fraction in (0, 1), got {}", max_error));
  CompressAtlasBc6h(atlas, materials, jobs);
  const bool bc6h_meets =
      std::all_of(atlas.certified_error.begin(), atlas.certified_error.end(),
                  [&](const CertifiedError& e) { return e.measured.max <= max_error; });
  if (!bc6h_meets) {
    // RGB9E5: each material's cell of the packed words, decoded, against its float LUT.
    atlas.bc6h.reset();
    atlas.certified_error.clear();
    for (std::size_t m = 0; m < materials.size(); ++m) {
      const Lut cell =
          ExtractAtlasCell(atlas.volume, atlas.layout, static_cast<int>(m), atlas.theta_in_deg);
      const std::optional<ExtrapolationInfo>& x = materials[m].extrapolation;
      atlas.certified_error.push_back(MeasureRgb9e5Error(
          *materials[m].lut, cell.texels, x ? x->theta_b_deg : 90.0, atlas.volume.ByteSize()));
    }
  }
  for (CertifiedError& e : atlas.certified_error) {
    e.max_error_bound = max_error;
    e.max_error_met = e.measured.max <= max_error;
  }
  return bc6h_meets ? LutCompression::kBc6h : LutCompression::kNone;
}

FloatImage AtlasImage(const std::vector<AtlasMaterial>& materials) {
  const std::vector<double> theta = CheckMaterials(materials);
  const AtlasLayout layout =
      ComputeAtlasLayout(static_cast<int>(materials.size()), static_cast<int>(theta.size()));
  FloatImage image;
  image.width = layout.ImageWidth();
  image.height = layout.ImageHeight();
  image.rgb.assign(static_cast<std::size_t>(image.width) * image.height * 3, 0.0f);
  for (int k = 0; k < layout.slices; ++k) {
    const int sx = layout.composite.CellColumn(k) * layout.TextureWidth();
    const int sy = layout.composite.CellRow(k) * layout.TextureHeight();
    for (std::size_t m = 0; m < materials.size(); ++m) {
      const int x0 = sx + layout.cells.CellColumn(static_cast<int>(m)) * Lut::kWidth;
      const int y0 = sy + layout.cells.CellRow(static_cast<int>(m)) * Lut::kHeight;
      for (int j = 0; j < Lut::kHeight; ++j) {
        const float* src = materials[m].lut->Texel(k, j, 0);
        float* dst = &image.rgb[(static_cast<std::size_t>(y0 + j) * image.width + x0) * 3];
        std::copy(src, src + Lut::kWidth * 3, dst);
      }
    }
  }
  return image;
}

Lut ExtractAtlasCell(const PackedVolume& atlas_volume, const AtlasLayout& layout, int m,
                     std::vector<double> theta_in_deg) {
  if (m < 0 || m >= layout.materials)
    throw InvalidArgument(
        fmt::format("atlas: material index {} outside 0..{}", m, layout.materials - 1));
  if (atlas_volume.width != layout.TextureWidth() ||
      atlas_volume.height != layout.TextureHeight() || atlas_volume.depth != layout.slices)
    throw InvalidArgument(
        fmt::format("atlas: a {} × {} × {} volume does not match the layout {} × {} × {}",
                    atlas_volume.width, atlas_volume.height, atlas_volume.depth,
                    layout.TextureWidth(), layout.TextureHeight(), layout.slices));
  PackedVolume cell;
  cell.width = Lut::kWidth;
  cell.height = Lut::kHeight;
  cell.depth = layout.slices;
  cell.words.resize(static_cast<std::size_t>(cell.width) * cell.height * cell.depth);
  const int x0 = layout.cells.CellColumn(m) * Lut::kWidth;
  const int y0 = layout.cells.CellRow(m) * Lut::kHeight;
  for (int k = 0; k < cell.depth; ++k)
    for (int j = 0; j < cell.height; ++j) {
      const std::uint32_t* src = &atlas_volume.words[atlas_volume.Index(x0, y0 + j, k)];
      std::copy(src, src + cell.width, &cell.words[cell.Index(0, j, k)]);
    }
  return UnpackLut(cell, std::move(theta_in_deg));
}

std::string AtlasManifestJson(const Atlas& atlas, const std::vector<std::string>& files) {
  const AtlasLayout& l = atlas.layout;
  ordered_json j;
  j["kind"] = "brdf-atlas-manifest";
  j["format_version"] = 1;
  j["theta_in_deg"] = atlas.theta_in_deg;
  ordered_json materials = ordered_json::array();
  for (int m = 0; m < l.materials; ++m) {
    const int column = l.cells.CellColumn(m), row = l.cells.CellRow(m);
    materials.push_back({{"index", m},
                         {"name", atlas.names[m]},
                         {"source", atlas.sources[m]},
                         {"cell",
                          {{"column", column},
                           {"row", row},
                           {"x0", column * Lut::kWidth},
                           {"y0", row * Lut::kHeight},
                           {"width", Lut::kWidth},
                           {"height", Lut::kHeight}}}});
    if (static_cast<std::size_t>(m) < atlas.saturated_samples.size() && atlas.saturated_samples[m])
      materials.back()["saturated_samples"] =
          detail::SaturatedCountsJson(*atlas.saturated_samples[m]);
    const auto i = static_cast<std::size_t>(m);
    if (i < atlas.extrapolation.size() && atlas.extrapolation[i])
      materials.back()["extrapolation"] = detail::ExtrapolationJson(*atlas.extrapolation[i]);
    if (i < atlas.certified_error.size())
      materials.back()["compression"] = detail::CertifiedErrorJson(atlas.certified_error[i]);
    if (i < atlas.fitted_models_json.size() && !atlas.fitted_models_json[i].empty()) {
      ordered_json fitted = ordered_json::array();
      for (const std::string& text : atlas.fitted_models_json[i])
        fitted.push_back(detail::ParseEmbeddedJson(text, "fitted model"));
      materials.back()["fitted_models"] = std::move(fitted);
    }
    if (i < atlas.beyond_json.size() && !atlas.beyond_json[i].empty())
      materials.back()["beyond"] =
          detail::ParseEmbeddedJson(atlas.beyond_json[i], "blind-spot fill record");
  }
  j["materials"] = std::move(materials);
  j["grid"] = {
      {"cell_width", Lut::kWidth},
      {"cell_height", Lut::kHeight},
      {"cell_columns", l.cells.columns},
      {"cell_rows", l.cells.rows},
      {"cell_order", "material m at column m mod cell_columns, row m div cell_columns"},
      {"texture_width", l.TextureWidth()},
      {"texture_height", l.TextureHeight()},
      {"texture_depth", l.slices},
      {"image_slice_columns", l.composite.columns},
      {"image_slice_rows", l.composite.rows},
      {"image_width", l.ImageWidth()},
      {"image_height", l.ImageHeight()},
      {"image_order",
       "slice k at column k mod image_slice_columns, row k div "
       "image_slice_columns (row-major, ascending theta_in, top-left first)"},
      {"delta_in_deg",
       atlas.theta_in_deg.size() >= 2 ? atlas.theta_in_deg[1] - atlas.theta_in_deg[0] : 0.0}};
  ordered_json convention = detail::TexelConventionJson(atlas.theta_in_deg);
  convention["atlas_cell"] =
      "u = (x0 + phi_d/1deg + 0.5)/texture_width, v = (y0 + theta_d/1deg + 0.5)/texture_height, "
      "w as for one LUT; clamp u to [(x0 + 0.5)/texture_width, (x0 + 360.5)/texture_width] and v "
      "to [(y0 + 0.5)/texture_height, (y0 + 180.5)/texture_height] so filtering stays inside the "
      "cell";
  j["texel_convention"] = std::move(convention);
  j["values"] = "f_r in 1/sr, linear Rec.709 RGB, not multiplied by cos(theta); unused cells are 0";
  j["tool"] = {{"name", "brdf-toolchain"}, {"version", BrdfToolVersion()}};
  j["payload"] = atlas.bc6h ? detail::PayloadJson(detail::Summarize(*atlas.bc6h))
                            : detail::PayloadJson(detail::Summarize(atlas.volume));
  j["files"] = files;
  return j.dump(2) + "\n";
}

std::vector<std::string> AtlasOutputPaths(const std::string& prefix) {
  return {prefix + ".ktx2", prefix + ".dds", prefix + ".exr", prefix + ".json"};
}

std::vector<std::string> WriteAtlas(const std::string& prefix,
                                    const std::vector<AtlasMaterial>& materials,
                                    const ExrOptions& exr_options, LutCompression compression,
                                    int jobs, double max_error) {
  Atlas atlas = BuildAtlas(materials);
  if (max_error > 0)
    ChooseAtlasCompression(atlas, materials, max_error, jobs);
  else if (compression == LutCompression::kBc6h)
    CompressAtlasBc6h(atlas, materials, jobs);
  const std::string stem = std::filesystem::path(prefix).filename().string();
  const std::vector<std::string> files = {stem + ".ktx2", stem + ".dds", stem + ".exr",
                                          stem + ".json"};
  const std::string manifest = AtlasManifestJson(atlas, files);
  std::vector<std::string> written;
  if (atlas.bc6h) {
    WriteKtx2(prefix + ".ktx2", *atlas.bc6h, KeyValues{{"brdf.atlas", manifest}});
    written.push_back(prefix + ".ktx2");
    WriteDds(prefix + ".dds", *atlas.bc6h);
  } else {
    WriteKtx2(prefix + ".ktx2", atlas.volume, KeyValues{{"brdf.atlas", manifest}});
    written.push_back(prefix + ".ktx2");
    WriteDds(prefix + ".dds", atlas.volume);
  }
  written.push_back(prefix + ".dds");
  WriteExr(
      prefix + ".exr", AtlasImage(materials), exr_options,
      {{"brdf:atlas", manifest},
       {"brdf:theta_in_deg", FormatThetaList(atlas.theta_in_deg)},
       {"brdf:layout",
        fmt::format("{} x {} slice grids of {} x {} material cells (361 x 181 each), "
                    "row-major, ascending theta_in, top-left first",
                    atlas.layout.composite.columns, atlas.layout.composite.rows,
                    atlas.layout.cells.columns, atlas.layout.cells.rows)},
       {"brdf:payload_crc32", Hex32Text(atlas.bc6h ? atlas.bc6h->Crc32() : atlas.volume.Crc32())}});
  written.push_back(prefix + ".exr");
  WriteFileAtomically(prefix + ".json", manifest);
  written.push_back(prefix + ".json");
  return written;
}

AtlasManifest ParseAtlasManifest(std::string_view json_text, const std::string& file) {
  const ordered_json j = detail::ParseJsonDocument(json_text, file);
  detail::JsonFields f(j, file);
  if (f.String("kind") != "brdf-atlas-manifest")
    throw FormatError(file, "member 'kind'", "\"brdf-atlas-manifest\"", j["kind"].dump());
  AtlasManifest m;
  m.theta_in_deg = f.NumberArray("theta_in_deg");
  detail::JsonFields g(f.Object("grid"), file, "grid.");
  m.texture_width = g.Int("texture_width");
  m.texture_height = g.Int("texture_height");
  const ordered_json& list = f.Get("materials");
  if (!list.is_array() || list.empty())
    throw FormatError(file, "member 'materials'", "a non-empty array", list.type_name());
  if (m.theta_in_deg.empty())
    throw FormatError(file, "member 'theta_in_deg'", "at least one value", "an empty array");
  m.layout =
      ComputeAtlasLayout(static_cast<int>(list.size()), static_cast<int>(m.theta_in_deg.size()));
  if (g.Int("cell_columns") != m.layout.cells.columns || g.Int("cell_rows") != m.layout.cells.rows)
    throw FormatError(file, "member 'grid.cell_columns'",
                      fmt::format("{} × {} cells for {} materials", m.layout.cells.columns,
                                  m.layout.cells.rows, list.size()),
                      fmt::format("{} × {}", g.Int("cell_columns"), g.Int("cell_rows")));
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string prefix = fmt::format("materials[{}].", i);
    detail::JsonFields e(list[i], file, prefix);
    detail::JsonFields c(e.Object("cell"), file, prefix + "cell.");
    AtlasManifestEntry entry{e.String("name"), e.String("source"), e.Int("index"), c.Int("column"),
                             c.Int("row"),     c.Int("x0"),        c.Int("y0")};
    if (list[i].contains("saturated_samples"))
      entry.saturated_samples = detail::ParseSaturatedCounts(list[i]["saturated_samples"], file,
                                                             prefix + "saturated_samples");
    if (list[i].contains("extrapolation")) {
      detail::JsonFields x(e.Object("extrapolation"), file, prefix + "extrapolation.");
      entry.extrapolation =
          ExtrapolationInfo{x.Number("p"), x.Number("l"), x.Number("theta_b_deg")};
    }
    if (list[i].contains("fitted_models")) {
      const ordered_json& fitted = list[i]["fitted_models"];
      if (!fitted.is_array())
        throw FormatError(file, "member '" + prefix + "fitted_models'", "an array",
                          fitted.type_name());
      for (const ordered_json& x : fitted) entry.fitted_models_json.push_back(x.dump());
    }
    if (list[i].contains("compression"))
      entry.certified_error = detail::ParseCertifiedError(e.Object("compression"), file);
    if (list[i].contains("beyond") && list[i]["beyond"].is_object())
      entry.beyond_json = list[i]["beyond"].dump();
    m.materials.push_back(std::move(entry));
  }
  detail::JsonFields p(f.Object("payload"), file, "payload.");
  if (f.Object("payload").contains("format")) m.payload_format = p.String("format");
  if (m.payload_format != "rgb9e5" && m.payload_format != "bc6h_ufloat")
    throw FormatError(file, "member 'payload.format'", "\"rgb9e5\" or \"bc6h_ufloat\"",
                      "\"" + m.payload_format + "\"");
  m.payload_bytes = p.UInt64("bytes");
  detail::JsonFields c(p.Object("checksum"), file, "payload.checksum.");
  m.payload_crc32 = detail::ParseHex32(c.String("value"), file, "member 'payload.checksum.value'");
  return m;
}

}  // namespace brdf::exporter
