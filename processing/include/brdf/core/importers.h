// One entry point for every third-party measurement format: `brdf import`, `brdf info` and
// `brdf eval` open files through ImportFile.
//
// Point-cloud formats (Zemax and LightTools BSDF tables, CSV point clouds, goniometer tables)
// become a Measurement directly. RGL `.bsdf` and MERL `.binary` files are evaluable BRDFs, not
// point clouds: they are loaded by their readers (rgl.h, merl.h) and turned into a
// Measurement by a virtual capture; ImportFile recognises them and says so (see ImportFile).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "brdf/core/measurement.h"

namespace brdf {

enum class ImportFormat { kAuto, kRgl, kZemax, kLightTools, kMerl, kCsv, kGonio };

// "auto", "rgl", "zemax", "lighttools", "merl", "csv", "gonio" (the --format spellings).
std::string ImportFormatName(ImportFormat format);
// Inverse of ImportFormatName; throws InvalidArgument listing the names.
ImportFormat ImportFormatFromName(std::string_view name);

// Identifies a file by its content first and its extension second:
//   RGL        starts with "tensor_file\0"
//   MERL       extension .binary, or exactly 12 + 3·90·90·180·8 bytes starting 90, 90, 180
//   Zemax      a text whose header has AngleOfIncidence or SampleRotation
//   LightTools a text whose header has ScatterAzimuth/ScatterRadial and blocks with AOI
//   gonio      a CSV header starting Incident_angle,Measure_angle
//   CSV        a CSV header naming theta_in, theta_out, r, g, b
// Throws FormatError naming the file when none matches, IoError when it cannot be read.
// The remedy of that FormatError is RemedyKind::kNameFormat.
ImportFormat DetectImportFormat(const std::string& path);

// How many leading bytes the content rule looks at.
inline constexpr std::size_t kImportDetectionBytes = 64 * 1024;

// The first kImportDetectionBytes of `path` (fewer for a shorter file). Throws IoError.
std::string ReadDetectionHead(const std::string& path);

// The same rule over bytes already read: `head` is the file's first bytes (up to
// kImportDetectionBytes), `file_size` its size, `extension` its lower- or upper-case extension
// with the dot (".bsdf"). Returns kAuto when no format matches.
ImportFormat DetectImportFormatFromHead(std::string_view head, std::uint64_t file_size,
                                        std::string_view extension);

struct ImportOptions {
  // Accept transmission (BTDF) tables, mirrored into the reflection hemisphere (zemax.h).
  bool allow_btdf = false;
};

// Reads `path` as a Measurement (f_r in 1/sr, linear Rec.709, our frame of docs/design.md §4).
// kAuto detects the format with DetectImportFormat. For kRgl and kMerl it throws
// InvalidArgument with RemedyKind::kCaptureEvaluable: those need a virtual capture
// (CaptureNoiseFree in brdf/core/virtual_capture.h).
// Throws FormatError / IoError from the readers, naming file and line or byte offset.
Measurement ImportFile(const std::string& path, ImportFormat format = ImportFormat::kAuto,
                       const ImportOptions& options = {});

}  // namespace brdf
