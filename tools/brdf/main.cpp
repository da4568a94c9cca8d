// `brdf`: the command-line face of brdf-toolchain. This is the only translation unit that
// sees CLI11; each subcommand parses into an options struct and calls its Run* function.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/measurement.h"
#include "commands.h"

namespace {

// Parses "THETA,PHI" (degrees) into two numbers.
std::string ParseAnglePair(const std::string& text, double* theta, double* phi) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) return "expected THETA,PHI in degrees, got '" + text + "'";
  try {
    std::size_t used = 0;
    *theta = std::stod(text.substr(0, comma), &used);
    if (used != comma) throw std::invalid_argument("trailing");
    const std::string rest = text.substr(comma + 1);
    *phi = std::stod(rest, &used);
    if (used != rest.size()) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    return "expected THETA,PHI in degrees, got '" + text + "'";
  }
  return {};
}

CLI::Validator AnglePairValidator() {
  return CLI::Validator(
      [](std::string& text) {
        double a = 0, b = 0;
        return ParseAnglePair(text, &a, &b);
      },
      "THETA,PHI");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"brdf: measured reflectance to engine-ready lookup textures"};
  app.set_version_flag("--version", std::string("brdf-toolchain ") + brdf::SoftwareVersion());
  app.require_subcommand(1);
  int exit_code = 0;

  // brdf eval
  brdf::cli::EvalOptions eval;
  std::string eval_in, eval_out;
  auto* eval_cmd = app.add_subcommand(
      "eval", "Print f_r (1/sr, linear RGB) of a BRDF source for one pair of directions");
  eval_cmd->add_option("file", eval.file, "Material file (.json) or other BRDF source")->required();
  eval_cmd->add_option("--in", eval_in, "Light direction THETA,PHI in degrees")
      ->required()
      ->check(AnglePairValidator());
  eval_cmd->add_option("--out", eval_out, "View direction THETA,PHI in degrees")
      ->required()
      ->check(AnglePairValidator());
  eval_cmd->callback([&] {
    ParseAnglePair(eval_in, &eval.theta_in_deg, &eval.phi_in_deg);
    ParseAnglePair(eval_out, &eval.theta_out_deg, &eval.phi_out_deg);
    exit_code = brdf::cli::RunEval(eval);
  });

  // brdf info
  brdf::cli::InfoOptions info;
  auto* info_cmd = app.add_subcommand(
      "info",
      "Describe a file: a .bpc capture (slices, samples, ranges, statistics, flags, "
      "metadata, damage) or a material .json (model and parameters)");
  info_cmd->add_option("file", info.file, "File to describe (.bpc, .json)")->required();
  info_cmd->add_flag("--json", info.json, "Print JSON instead of text");
  info_cmd->callback([&] { exit_code = brdf::cli::RunInfo(info); });

  // brdf materials
  brdf::cli::MaterialsOptions materials;
  auto* materials_cmd =
      app.add_subcommand("materials", "List the virtual sample library of the simulator");
  materials_cmd->add_flag("--json", materials.json, "Print JSON instead of a table");
  materials_cmd->callback([&] { exit_code = brdf::cli::RunMaterials(materials); });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    // One clear line, then where to look for help.
    std::fprintf(stderr, "brdf: %s\nRun 'brdf --help' or 'brdf <command> --help' for usage.\n",
                 e.what());
    return 2;
  } catch (const brdf::Error& e) {
    std::fprintf(stderr, "brdf: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "brdf: internal error: %s\n", e.what());
    return 3;
  }
  return exit_code;
}
