// What a file is, decided once for every command and tool (`brdf info`, `eval`, `convert`,
// `atlas`, `import`, the viewer, the fitter).
//
// The rule, first match wins:
//  1. magic bytes: the .bpc magic (89 'BPC' 0d 0a 1a 0a) → capture; «KTX 20» → KTX2 texture;
//     "DDS " → DDS texture; "tensor_file\0" → RGL BRDF; a MERL header 90, 90, 180 on a file of
//     exactly the MERL size → MERL BRDF;
//  2. JSON (the first non-blank byte is '{' or '[', or the extension is .json): a
//     "<name>.extrapolate.json" holds extrapolation parameters; otherwise by content: "kind":
//     "brdf-lut-sidecar" → LUT sidecar, "kind": "brdf-atlas-manifest" → atlas manifest, an
//     object with a "model" member → material file (docs/design.md §9), anything else →
//     other JSON;
//  3. the extension of a binary format whose magic is missing (.bpc, .ktx2, .dds, .binary): the
//     kind it claims, so that format's reader reports the damage precisely (byte 0: expected the
//     magic, got ...);
//  4. text tables by content (DetectImportFormatFromHead, brdf/core/importers.h): Zemax,
//     LightTools, goniometer table, CSV point cloud;
//  5. otherwise unknown.
// Only regular files are classified: directories, FIFOs and devices are refused unread.
#pragma once

#include <optional>
#include <string>

#include "brdf/core/importers.h"

namespace brdf::sources {

enum class FileKind {
  kCapture,        // .bpc point cloud
  kMaterial,       // analytic material .json
  kKtx2,           // exported RGB9E5 texture (LUT or atlas)
  kDds,            // exported RGB9E5 texture (LUT or atlas)
  kSidecar,        // LUT sidecar .json
  kAtlasManifest,  // atlas manifest .json
  kExtrapolation,  // <name>.extrapolate.json
  kOtherJson,      // a JSON file that is none of the above
  kRgl,            // RGL .bsdf (evaluable BRDF)
  kMerl,           // MERL .binary (evaluable BRDF)
  kZemax,          // Zemax BSDF table
  kLightTools,     // LightTools BSDF table
  kCsv,            // CSV point cloud
  kGonio,          // spectral goniometer table
  kCompactLut,     // exported compact LUT (.brdfc, brdf/exporter/compact_lut.h)
  kUnknown,        // none of the above
};

// "capture (.bpc)", "material file", "KTX2 texture", ... (for messages).
const char* FileKindName(FileKind kind);

// Classifies `path` by the rule above. Reads at most the first 64 KiB, and a JSON file whole (at
// most 16 MiB). Throws IoError (missing, unreadable, not a regular file) and FormatError (a
// .json whose text does not parse as JSON).
FileKind DetectFileKind(const std::string& path);

// Kind groups.
inline bool IsTexture(FileKind k) { return k == FileKind::kKtx2 || k == FileKind::kDds; }
// Textures and the JSON files that describe one (OpenExportedTexture).
inline bool IsExportedLut(FileKind k) {
  return IsTexture(k) || k == FileKind::kSidecar || k == FileKind::kAtlasManifest;
}
// A third-party measurement (`brdf import` reads it): the matching ImportFormat, else nullopt.
std::optional<ImportFormat> ImportFormatOf(FileKind kind);
// The kind an ImportFormat names (kAuto → kUnknown).
FileKind FileKindOf(ImportFormat format);

// The output name of an input: its file name without the extension ("gold.bpc" → "gold").
std::string OutputNameOf(const std::string& path);

// What a written file records as its source: the input's file name alone ("/home/ana/gold.bpc"
// → "gold.bpc"). Sidecars, manifests and captures are shipped and shared, so they never carry
// the converting machine's folders (docs/robustness.md).
std::string RecordedSourceName(const std::string& path);

// The suffix of per-material extrapolation files, ".extrapolate.json".
inline constexpr const char* kExtrapolationSuffix = ".extrapolate.json";

}  // namespace brdf::sources
