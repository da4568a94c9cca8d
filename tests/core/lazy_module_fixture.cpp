// A module that links a project library (brdf::core, built position-independent), as the
// fitter's module links brdf::processing and Ceres: lazy_module_test loads it through
// brdf::LazyModule and calls its entry point.
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/lazy_module.h"

BRDF_DEFINE_MODULE_ABI()

// Writes brdf::BytePosition(offset) into *out; never throws.
BRDF_MODULE_ENTRY void brdf_test_byte_position(unsigned long long offset, std::string* out) {
  *out = brdf::BytePosition(offset);
}
