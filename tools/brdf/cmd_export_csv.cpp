// `brdf export-csv FILE.bpc --out FILE.csv`: a capture as a CSV point cloud any spreadsheet
// reads (layout in brdf/core/csv.h). Every float is printed in its shortest round-trip form,
// so `brdf import FILE.csv` gives back the capture's values bit for bit.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "brdf/core/csv.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/measurement.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/detect.h"
#include "brdf/sources/material_library.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

namespace {

// The CSV layout holds finite numbers only (csv.h); a NaN or inf in a capture (which .bpc
// stores losslessly) would make a file our own reader refuses, so it is refused here, with the
// sample named, before anything is written.
void CheckFinite(const Measurement& m, const std::string& file) {
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    const Slice& s = m.slices[i];
    for (std::size_t j = 0; j < s.samples.size(); ++j) {
      const Sample& x = s.samples[j];
      bool finite = std::isfinite(x.theta_in_deg) && std::isfinite(x.phi_in_deg) &&
                    std::isfinite(x.theta_out_deg) && std::isfinite(x.phi_out_deg);
      for (int c = 0; c < 3; ++c) {
        finite = finite && std::isfinite(x.rgb[c]);
        if (s.has_sigma) finite = finite && std::isfinite(x.sigma[c]);
      }
      if (!finite)
        throw FormatError(file, "slice " + std::to_string(i) + ", sample " + std::to_string(j),
                          "finite angles and values (a CSV point cloud holds numbers only)",
                          "NaN or infinity", "the .bpc itself is intact; only CSV cannot hold it");
    }
  }
}

// The capture's "slice i, sample j" written on `position` ("line N") of `text` (FormatCsv: a
// header, then one line per sample in slice order); `position` itself when it is not a data line.
std::string SampleOfCsvLine(const Measurement& m, const std::string& text,
                            const std::string& position) {
  unsigned long long line = 0;
  if (std::sscanf(position.c_str(), "line %llu", &line) != 1) return "the CSV's " + position;
  std::uint64_t header_lines = 0, n = 0;
  for (std::size_t pos = 0; pos < text.size(); pos = text.find('\n', pos) + 1) {
    ++n;
    if (text.compare(pos, 8, "theta_in") == 0) header_lines = n;
    if (header_lines != 0 || text.find('\n', pos) == std::string::npos) break;
  }
  if (header_lines == 0 || line <= header_lines) return "the CSV's " + position;
  std::uint64_t index = static_cast<std::uint64_t>(line) - header_lines - 1;
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    if (index < m.slices[i].samples.size())
      return "slice " + std::to_string(i) + ", sample " + std::to_string(index);
    index -= m.slices[i].samples.size();
  }
  return "the CSV's " + position;
}

}  // namespace

int RunExportCsv(const ExportCsvOptions& options) {
  // A library material name stands for its file (brdf/sources/material_library.h).
  const std::string file = sources::ResolveSource(options.file);
  // By content, as every command recognises a file (a capture under another name is one).
  const sources::FileKind kind = sources::DetectFileKind(file);
  if (kind != sources::FileKind::kCapture)
    throw InvalidArgument(file + ": a " + sources::FileKindName(kind) +
                          "; export-csv reads .bpc captures (bring other formats in with "
                          "`brdf import` first)");
  CheckOutputPath(options.out, file, ".csv", options.force);
  // The capture rule of every command (brdf/sources/capture.h), for a copy: damage and
  // inconsistent structure are refused as convert refuses them; an unfinished capture is
  // exported with its incomplete slices marked; a cut end chunk or bytes after it are warnings.
  std::vector<std::string> warnings;
  const Measurement m = sources::LoadCaptureForCopy(file, &warnings);
  CheckFinite(m, file);
  const std::string text = FormatCsv(m);
  // What is written must read back: a value outside the CSV's validated ranges (θout > 90°,
  // say) is refused now rather than leaving a file `brdf import` rejects.
  try {
    ParseCsv(text, options.out);
  } catch (const FormatError& e) {
    // The CSV was never written: the refusal names the capture's slice and sample.
    throw FormatError(file, SampleOfCsvLine(m, text, e.position()), e.expected(), e.got(),
                      "the .bpc itself is intact; a CSV point cloud cannot hold this value");
  }
  WriteFileAtomically(options.out, text);
  // Warnings after the work: a refusal stays the one line on stderr.
  for (const std::string& w : warnings) std::fprintf(stderr, "%s\n", w.c_str());
  std::printf("%s -> %s: %zu slices, %zu samples\n", file.c_str(), options.out.c_str(),
              m.slices.size(), m.SampleCount());
  return 0;
}

}  // namespace brdf::cli
