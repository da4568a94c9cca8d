#include "remedy.h"

#include <exception>
#include <vector>

#include "brdf/core/text_format.h"

namespace py = pybind11;

namespace brdf::python {

std::string PythonRemedyText(const Remedy& remedy) {
  const std::string& f = remedy.file;
  const std::string missing =
      remedy.theta_in_deg.empty()
          ? std::string()
          : " (it captures θin " + ShortNumberListText(remedy.theta_in_deg) + "°)";
  switch (remedy.kind) {
    case RemedyKind::kNone:
      return {};
    case RemedyKind::kResumeCapture:
      return "to continue the capture, call brdf.capture(...) again with the arguments that made "
             "it and resume=True" +
             missing + "; it keeps the first " + std::to_string(remedy.valid_bytes) +
             " intact bytes";
    case RemedyKind::kRepairCapture:
      return "run 'brdf repair " + f +
             " --out FIXED.bpc' to keep every slice a LUT can use, then call brdf.capture(...) "
             "with "
             "out='FIXED.bpc' and resume=True" +
             missing;
    case RemedyKind::kRecapture:
      return "recapture the sample";
    case RemedyKind::kForceOverwrite:
      return std::string("pass overwrite=True to replace ") + (f.empty() ? "them" : "it");
    case RemedyKind::kAllowBtdf:
      return "'brdf import --allow-btdf' stores it mirrored into the reflection hemisphere";
    case RemedyKind::kNameFormat:
      return "if you know its format, 'brdf import --format NAME' reads it";
    case RemedyKind::kCaptureEvaluable:
      return "'brdf import " + f +
             " --out FILE.bpc' captures it noise-free at the reference geometry; brdf.open "
             "evaluates it directly";
    case RemedyKind::kEvaluateSingleLut:
      return "open one material's own LUT (written by brdf.convert)";
  }
  return {};
}

std::string ErrorMessage(const Error& error) {
  std::string line = error.what();
  const std::string remedy = PythonRemedyText(error.remedy());
  if (!remedy.empty()) line += "; " + remedy;
  return line;
}

void RegisterExceptions(py::module_& m) {
  // Handles that live as long as the interpreter (pybind11's own pattern for exception types).
  static py::handle error, io_error, format_error, invalid_argument;
  error = py::exception<Error>(m, "Error", PyExc_RuntimeError).release();
  format_error = py::exception<FormatError>(m, "FormatError", PyExc_ValueError).release();
  invalid_argument =
      py::exception<InvalidArgument>(m, "InvalidArgument", PyExc_ValueError).release();
  io_error = py::exception<IoError>(m, "IoError", PyExc_OSError).release();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const IoError& e) {
      PyErr_SetString(io_error.ptr(), ErrorMessage(e).c_str());
    } catch (const FormatError& e) {
      PyErr_SetString(format_error.ptr(), ErrorMessage(e).c_str());
    } catch (const InvalidArgument& e) {
      PyErr_SetString(invalid_argument.ptr(), ErrorMessage(e).c_str());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), ErrorMessage(e).c_str());
    }
  });
}

}  // namespace brdf::python
