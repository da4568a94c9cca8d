// `brdf repair DAMAGED.bpc --out FIXED.bpc`: salvages a damaged capture. The work is
// brdf::sources::RepairCapture; this file checks the output name and prints what was kept and
// what was dropped.
#include <cstdio>
#include <string>

#include "brdf/core/error.h"
#include "brdf/core/text_format.h"
#include "brdf/sources/capture.h"
#include "brdf/sources/material_library.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {
namespace {

// "0, 20, 40", or "none" for a repair that kept or misses no slice.
std::string DegList(const std::vector<double>& values) {
  return values.empty() ? "none" : ShortNumberListText(values);
}

}  // namespace

int RunRepair(const RepairOptions& options) {
  // A library material name stands for its file (brdf/sources/material_library.h).
  const std::string file = sources::ResolveSource(options.file);
  CheckOutputPath(options.out, file, ".bpc", options.force);
  const sources::RepairReport r = sources::RepairCapture(file, options.out, options.force);
  std::printf("%s -> %s: kept %zu slice%s (theta_in %s deg), %llu bytes\n", r.input.c_str(),
              r.output.c_str(), r.kept_theta_in_deg.size(),
              r.kept_theta_in_deg.size() == 1 ? "" : "s", DegList(r.kept_theta_in_deg).c_str(),
              static_cast<unsigned long long>(r.output_bytes));
  for (const sources::DroppedPart& d : r.dropped) {
    std::string what = d.slice_index >= 0 ? "slice " + std::to_string(d.slice_index) : "data";
    if (d.theta_in_deg) what += " (theta_in " + DegList({*d.theta_in_deg}) + " deg)";
    std::printf("  dropped %s at byte %llu (%llu bytes): %s\n", what.c_str(),
                static_cast<unsigned long long>(d.offset), static_cast<unsigned long long>(d.size),
                d.reason.c_str());
  }
  if (r.missing_theta_in_deg.empty()) {
    std::printf(
        "every planned slice (theta_in %s deg) is intact; %s is an unfinished capture "
        "that 'brdf capture ... --out %s --resume' finishes without measuring\n",
        DegList(r.planned_theta_in_deg).c_str(), r.output.c_str(), r.output.c_str());
  } else {
    std::printf(
        "missing theta_in %s deg of the plan (%s deg): rerun the 'brdf capture' command "
        "that made %s with --out %s --resume to capture them\n",
        DegList(r.missing_theta_in_deg).c_str(), DegList(r.planned_theta_in_deg).c_str(),
        r.input.c_str(), r.output.c_str());
  }
  return 0;
}

}  // namespace brdf::cli
