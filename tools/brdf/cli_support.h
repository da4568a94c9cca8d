// Helpers shared by the brdf subcommands (no CLI11 here).
#pragma once

#include <exception>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/processing/extrapolation.h"

namespace brdf::cli {

// What the user can do about an error, in the tool's own words ("run 'brdf repair cap.bpc
// --out FIXED.bpc', then resume FIXED.bpc"); empty for RemedyKind::kNone. `command` is the
// subcommand that failed ("info", "import"), for remedies that depend on its options.
std::string RemedyText(const Remedy& remedy, const std::string& command = {});

// The one line printed for an error: its message, then "; <remedy>" when it carries one.
std::string ErrorLine(const std::exception& error, const std::string& command = {});

// --extrapolate P,L (processing::ParseExtrapolation), a bad value reported under the option's
// name. Throws InvalidArgument.
processing::ExtrapolationParams ParseExtrapolationOption(const std::string& text);

// The command-line arguments joined with ", " (for "nothing found in a, b").
std::string JoinArguments(const std::vector<std::string>& arguments);

// Lower-case extension including the dot (".bpc"), or "" when there is none.
std::string LowerExtension(const std::string& path);

// Checks an output path before any work is done: it must end in `extension` (".bpc"), must
// not be the input file itself, and must not exist unless `force` (a .bpc or .csv in the way
// may be a measurement nobody can repeat; brdf::CheckWritableOutput, the rule of every
// writing command; `folders_created`: the command creates the output's folder itself, as
// `fit` does). `option` names the option in messages ("--out"). Throws InvalidArgument,
// OutputExistsError or IoError.
void CheckOutputPath(const std::string& out, const std::string& input, const char* extension,
                     bool force, const char* option = "--out", bool folders_created = false);

// Creates `folder` and its parents (nothing for an empty path); throws IoError naming it when
// that fails ("x: cannot create the output folder: Not a directory").
void CreateOutputFolder(const std::string& folder);

// Prints one note on stderr naming the temporary files of killed runs that
// brdf::CheckWritableOutputs removed (nothing when there were none).
// After `capture` or `import` wrote the capture `out`: a warning on stderr for each reason the
// verdict of brdf/sources/capture.h gives another command to refuse it (every reader, or the LUT
// exports alone for a θin list that is not k·Δin), so the user hears it now, not at the first
// convert.
void WarnAboutVerdict(const std::string& out);

void ReportRemovedTemporaries(const std::vector<std::string>& removed);

}  // namespace brdf::cli
