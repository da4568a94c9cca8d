// `brdf eval FILE --in T,P --out T,P`: f_r of any evaluable file for one pair of directions.
// The file is opened by brdf::sources::OpenBrdf (brdf/sources/open.h): material files are
// evaluated analytically, captures and tables resampled into the float LUT `brdf convert` would
// build and sampled exactly as a GPU samples the exported texture, so a capture, its LUT and
// the exported texture agree by construction.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/error.h"
#include "brdf/core/eval_pairs.h"
#include "brdf/core/file_util.h"
#include "brdf/sources/open.h"
#include "cli_support.h"
#include "commands.h"

namespace brdf::cli {

namespace {

void CheckPolar(double theta_deg, const char* which) {
  if (!(theta_deg >= 0.0 && theta_deg <= 90.0))
    throw InvalidArgument(std::string("--") + which +
                          ": polar angle must be in [0, 90] degrees, got " + NumberText(theta_deg));
}

struct Pair {
  double theta_in_deg, phi_in_deg, theta_out_deg, phi_out_deg;
};

// Reads the --pairs list (at most 64 MiB).
std::vector<Pair> ReadPairs(const std::string& path) {
  std::string text;
  if (path == "-") {
    std::ostringstream all;
    all << std::cin.rdbuf();
    text = all.str();
  } else {
    text = ReadFileText(path, 64u << 20);
  }
  const std::string name = path == "-" ? "<stdin>" : path;
  std::vector<Pair> pairs;
  std::istringstream lines(text);
  std::string line;
  for (std::uint64_t n = 1; std::getline(lines, line); ++n) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::string spaced = line;
    for (char& c : spaced)
      if (c == ',') c = ' ';
    std::istringstream in(spaced);
    Pair p{};
    std::string rest;
    if (!(in >> p.theta_in_deg >> p.phi_in_deg >> p.theta_out_deg >> p.phi_out_deg) || (in >> rest))
      throw FormatError(name, LinePosition(n),
                        "four angles in degrees: THETA_IN PHI_IN THETA_OUT PHI_OUT",
                        "'" + line + "'");
    if (!(p.theta_in_deg >= 0 && p.theta_in_deg <= 90 && p.theta_out_deg >= 0 &&
          p.theta_out_deg <= 90 && std::isfinite(p.phi_in_deg) && std::isfinite(p.phi_out_deg)))
      throw FormatError(name, LinePosition(n), "polar angles in [0, 90] and finite azimuths",
                        "'" + line + "'");
    pairs.push_back(p);
  }
  return pairs;
}

}  // namespace

int RunEval(const EvalOptions& options) {
  std::vector<Pair> pairs;
  if (!options.pairs.empty()) {
    pairs = ReadPairs(options.pairs);
  } else {
    CheckPolar(options.theta_in_deg, "in");
    CheckPolar(options.theta_out_deg, "out");
    pairs.push_back(
        {options.theta_in_deg, options.phi_in_deg, options.theta_out_deg, options.phi_out_deg});
  }
  std::optional<processing::ExtrapolationParams> extrapolate;
  if (!options.extrapolate.empty()) extrapolate = ParseExtrapolationOption(options.extrapolate);
  sources::OpenOptions open_options;
  open_options.extrapolation = extrapolate;
  open_options.resample.beyond.method = processing::ParseBeyondMethod(options.beyond);
  open_options.resample.beyond.subdivisions = options.beyond_subdivide;
  const sources::OpenedSource source = sources::OpenBrdf(options.file, open_options);
  for (const std::string& w : source.warnings) std::fprintf(stderr, "%s\n", w.c_str());
  std::set<double> warned_theta_in;  // one warning per θin beyond the measured range
  for (const Pair& p : pairs)
    if (const auto w = source.BeyondMeasuredWarning(p.theta_in_deg, p.theta_out_deg, options.file))
      if (warned_theta_in.insert(p.theta_in_deg).second) std::fprintf(stderr, "%s\n", w->c_str());
  // The evaluation path of the Python module's eval_deg too (brdf/core/eval_pairs.h).
  std::vector<double> angles[4], rgb(3 * pairs.size());
  for (const Pair& p : pairs) {
    angles[0].push_back(p.theta_in_deg);
    angles[1].push_back(p.phi_in_deg);
    angles[2].push_back(p.theta_out_deg);
    angles[3].push_back(p.phi_out_deg);
  }
  EvalAnglePairsDeg(*source.brdf, pairs.size(), angles[0].data(), angles[1].data(),
                    angles[2].data(), angles[3].data(), rgb.data());
  for (std::size_t i = 0; i < pairs.size(); ++i)
    std::printf("%.9g %.9g %.9g\n", rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
  return 0;
}

}  // namespace brdf::cli
