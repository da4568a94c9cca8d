// The virtual capture `brdf import` makes of an evaluable BRDF file (RGL .bsdf, MERL .binary):
// noise-free f_r at the reference geometry, MERL's unmeasured bins flagged invalid. Shared by
// `brdf import` and `brdf fit` until the input rules move into a library.
#pragma once

#include <string>

#include "brdf/core/importers.h"
#include "brdf/core/measurement.h"

namespace brdf::cli {

// `format` is ImportFormat::kRgl or kMerl. Throws FormatError / IoError naming the file.
Measurement CaptureEvaluable(const std::string& path, ImportFormat format);

}  // namespace brdf::cli
