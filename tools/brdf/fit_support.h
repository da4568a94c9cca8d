// `--extrapolate auto` for `brdf convert` and `brdf atlas`: the docs/design.md §6 parameters
// fitted per input (processing::ChooseExtrapolationAuto). Defined in cmd_fit.cpp.
#pragma once

#include <optional>
#include <string>

#include "brdf/processing/extrapolation.h"
#include "brdf/sources/detect.h"

namespace brdf::cli {

struct AutoExtrapolationChoice {
  processing::ExtrapolationParams params;
  std::string record_json;  // for the sidecar's "fitted_models": p, l, band errors, the GGX fit
  // Why the fit was not used (processing::AutoExtrapolationResult::not_used), a full sentence
  // starting with the path; empty when it was.
  std::string warning;
};

// For a capture or material file: opens it as `brdf convert` does, fits GGX and chooses p, l.
// Inputs with their own extrapolation (beside file, material member), which comes first, and
// other kinds (exported LUTs carry their extrapolation): nullopt.
std::optional<AutoExtrapolationChoice> AutoExtrapolationFor(const std::string& path,
                                                            sources::FileKind kind);

}  // namespace brdf::cli
