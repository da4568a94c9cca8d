// Shared by the two compiled parts of the Python module (_brdf: open, eval, info, captures;
// _brdf_tools: fit, convert, preview, capture, loaded on first use so that `import brdf` does not
// load Ceres, the USB stack and the previewer).
//
// PythonRemedyText: the module's words for a library Remedy (brdf/core/error.h), what a Python
// user does next, naming the module's calls where it has one (brdf.capture(..., resume=True),
// overwrite=True) and the installed `brdf` command where it has none (`brdf repair`,
// `brdf import`). It phrases the remedies in Source.info() / brdf.info() and is appended, after
// "; ", to the message of an exception whose error carries a remedy, as the CLI appends its own
// wording. The sentences are listed in docs/python.md ("Errors").
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "brdf/core/error.h"

namespace brdf::python {

// "" for RemedyKind::kNone.
std::string PythonRemedyText(const Remedy& remedy);

// The exception's message: the library's one line, then "; " and PythonRemedyText if any.
std::string ErrorMessage(const Error& error);

// _brdf: defines brdf.Error (RuntimeError), IoError (OSError), FormatError and
// InvalidArgument (ValueError) on `m` and the translator from brdf::Error (global in pybind11,
// so it serves _brdf_tools too, which imports _brdf first).
void RegisterExceptions(pybind11::module_& m);

}  // namespace brdf::python
