// What a file holds: the one description `brdf info` prints (as text or --json), the Python
// module's `Source.info()` returns, and any other host can show.
//
// DescribeFile reads a capture (.bpc), a material file, an exported LUT or atlas (.ktx2, .dds,
// sidecar or manifest .json) or a third-party measurement (RGL, MERL, Zemax, LightTools, CSV,
// goniometer table) and returns one JSON document (UTF-8 text, the document
// printed by `brdf info --json`). It applies the same rules the other commands apply, so its
// verdict cannot disagree with them:
//  - captures: sources::AssessCapture (brdf/sources/capture.h), the damaged-capture rule;
//  - tables: processing::FindLutInputProblems with any θin set, the rule `eval` applies;
//  - textures: sources::OpenExportedTexture, the CRC and layout checks every reader makes.
// "usable" (present for captures and tables) is false exactly when one of those commands
// refuses the file, and "refusals" lists why, one line each; "evaluable" says whether eval,
// preview, fit and brdf-view accept it, and for captures "convertible" whether convert and
// atlas do too (they alone refuse a θin list that is not k·Δin: CaptureAssessment's
// export_refusals).
//
// A library names no commands: where the description offers a remedy (resume a capture, capture
// an evaluable file, ...), the host phrases it. `phrase` receives the structured remedy
// (brdf/core/error.h) and returns the words its users type; an empty string offers nothing.
//
// Errors: a file that cannot be read at all (missing, unknown kind, unparseable) throws the
// brdf::Error its reader throws; everything else is described.
#pragma once

#include <functional>
#include <string>

#include "brdf/core/error.h"

namespace brdf::sources {

using RemedyPhrasing = std::function<std::string(const Remedy&)>;

// The description of `file` (a path, or a material library name: ResolveSource) as JSON text
// indented by two spaces; non-finite statistics are null.
std::string DescribeFile(const std::string& file, const RemedyPhrasing& phrase);

}  // namespace brdf::sources
