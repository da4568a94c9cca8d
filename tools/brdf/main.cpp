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
      "eval",
      "Print f_r (1/sr, linear RGB) of a material, capture or exported LUT for a pair of "
      "directions (or many, with --pairs)");
  eval_cmd
      ->add_option("file", eval.file,
                   "Material file (.json), capture (.bpc), exported LUT (.ktx2, .dds), LUT "
                   "sidecar (.json), or measured data: RGL .bsdf, MERL .binary, or a table "
                   "interpolated like a capture (Zemax or LightTools .bsdf, CSV point cloud, "
                   "goniometer table; detected by content)")
      ->required();
  auto* eval_in_opt = eval_cmd->add_option("--in", eval_in, "Light direction THETA,PHI in degrees")
                          ->check(AnglePairValidator());
  auto* eval_out_opt =
      eval_cmd->add_option("--out", eval_out, "View direction THETA,PHI in degrees")
          ->check(AnglePairValidator());
  auto* eval_pairs_opt = eval_cmd->add_option(
      "--pairs", eval.pairs,
      "Instead of --in/--out: a file ('-' for stdin) of lines 'THETA_IN PHI_IN THETA_OUT "
      "PHI_OUT' in degrees; prints one line per pair");
  eval_in_opt->needs(eval_out_opt)->excludes(eval_pairs_opt);
  eval_out_opt->needs(eval_in_opt)->excludes(eval_pairs_opt);
  eval_cmd
      ->add_option("--extrapolate", eval.extrapolate,
                   "Captures: grazing extrapolation P,L (DESIGN §6); default: the "
                   "per-material JSON beside the file, else 1,0.5")
      ->capture_default_str();
  eval_cmd->footer(
      "Captures are interpolated as 'brdf convert' resamples them; exported LUTs are sampled "
      "as a GPU samples the 3D texture (centre-exact coordinates, trilinear, clamp-to-edge).\n");
  eval_cmd->callback([&] {
    if (eval_in.empty() && eval.pairs.empty())
      throw CLI::RequiredError("--in and --out (or --pairs)");
    if (!eval_in.empty()) {
      ParseAnglePair(eval_in, &eval.theta_in_deg, &eval.phi_in_deg);
      ParseAnglePair(eval_out, &eval.theta_out_deg, &eval.phi_out_deg);
    }
    exit_code = brdf::cli::RunEval(eval);
  });

  // brdf capture
  brdf::cli::CaptureOptions capture;
  auto* capture_cmd = app.add_subcommand(
      "capture",
      "Capture a sample slice by slice with a scatterometer into a .bpc file (each completed "
      "slice is saved at once; --resume continues an interrupted capture)");
  capture_cmd
      ->add_option("--device", capture.device, "Instrument: sim (the simulated scatterometer)")
      ->capture_default_str();
  capture_cmd
      ->add_option("--material", capture.material,
                   "Virtual sample: a library name ('brdf materials') or a material .json")
      ->required();
  capture_cmd->add_option("--sample", capture.sample, "Sample name recorded in the file")
      ->required();
  capture_cmd->add_option("--out", capture.out, "Output .bpc file")->required();
  capture_cmd
      ->add_option("--theta-in", capture.theta_in_deg,
                   "Incidence angles in degrees, comma separated, in capture order")
      ->delimiter(',')
      ->capture_default_str();
  capture_cmd
      ->add_option("--theta-out-max", capture.theta_out_max_deg,
                   "Largest detector polar angle, degrees (sim)")
      ->capture_default_str();
  capture_cmd
      ->add_option("--theta-out-step", capture.theta_out_step_deg,
                   "Detector polar step, degrees (sim)")
      ->capture_default_str();
  capture_cmd
      ->add_option("--phi-out-step", capture.phi_out_step_deg,
                   "Detector azimuth step, degrees (sim)")
      ->capture_default_str();
  capture_cmd
      ->add_option("--noise", capture.noise,
                   "Detector noise level: 1 = reference instrument, 0 = ideal detector "
                   "(noise-free, unsaturated signal)")
      ->capture_default_str();
  capture_cmd->add_option("--seed", capture.seed, "Seed of the simulated detector noise")
      ->capture_default_str();
  capture_cmd
      ->add_option("--exposure", capture.exposure,
                   "Exposure: auto (ranged per θout row), auto-slice, or a fixed time in ms")
      ->capture_default_str();
  capture_cmd->add_option("--operator-notes", capture.operator_notes,
                          "Free text recorded in the file's metadata");
  auto* resume_flag = capture_cmd->add_flag(
      "--resume", capture.resume,
      "Continue an interrupted capture in --out: keep its complete slices, measure the rest");
  auto* force_flag =
      capture_cmd->add_flag("--force", capture.force, "Overwrite --out if it already exists");
  resume_flag->excludes(force_flag);
  capture_cmd->add_flag("--quiet", capture.quiet, "No progress on stderr");
  capture_cmd
      ->add_option("--sim-fault", capture.sim_fault,
                   "Testing: make the simulated instrument fail: disconnect:N, stall:N or "
                   "corrupt:N (N = instrument frames sent), comma separated")
      ->group("Testing");
  capture_cmd->callback([&] { exit_code = brdf::cli::RunCapture(capture); });

  // brdf info
  brdf::cli::InfoOptions info;
  auto* info_cmd = app.add_subcommand(
      "info",
      "Describe a file: a .bpc capture (slices, samples, ranges, statistics, flags, "
      "metadata, damage), a material .json (model and parameters), an exported LUT or atlas "
      "(.ktx2, .dds) or its sidecar / manifest .json (dimensions, θin, payload, checksum, "
      "extrapolation, value ranges), or a third-party measurement (Zemax or LightTools .bsdf "
      "with the integrated TIS per incidence, CSV point cloud, goniometer table, RGL .bsdf, "
      "MERL .binary)");
  info_cmd
      ->add_option("file", info.file,
                   "File to describe (.bpc, .json, .ktx2, .dds, .bsdf, .csv, .binary)")
      ->required();
  info_cmd->add_flag("--json", info.json, "Print JSON instead of text");
  info_cmd->callback([&] { exit_code = brdf::cli::RunInfo(info); });

  // brdf convert
  brdf::cli::ConvertOptions convert;
  auto* convert_cmd = app.add_subcommand(
      "convert",
      "Turn captures (.bpc) and material files (.json) into engine-ready LUTs: "
      "DIR/<name>.ktx2, .dds (RGB9E5 3D textures), .exr (float composite), .png (tone-mapped "
      "contact image) and .json (sidecar)");
  convert_cmd
      ->add_option("inputs", convert.inputs,
                   "Capture files, material files, or folders of them (not recursive)")
      ->required();
  convert_cmd->add_option("--out", convert.out, "Output folder (created if missing)")->required();
  convert_cmd
      ->add_option("--extrapolate", convert.extrapolate,
                   "Grazing extrapolation P,L (DESIGN §6) for inputs without their own; "
                   "default 1,0.5 (clamping)")
      ->capture_default_str();
  convert_cmd->add_option("--formats", convert.formats, "Comma-separated outputs to write")
      ->capture_default_str();
  convert_cmd
      ->add_option("--exr-type", convert.exr_type,
                   "EXR pixel type: float, or half (faster to write, smaller)")
      ->capture_default_str()
      ->check(CLI::IsMember({"float", "half"}));
  convert_cmd
      ->add_option("--exr-compression", convert.exr_compression,
                   "EXR compression: none, or zip (float EXRs of measured data: about 20 % "
                   "smaller, and a conversion takes twice as long)")
      ->capture_default_str()
      ->check(CLI::IsMember({"zip", "none"}));
  convert_cmd
      ->add_option("--jobs", convert.jobs,
                   "Inputs converted in parallel (default: hardware threads)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  convert_cmd->add_flag("--quiet", convert.quiet, "No progress bar");
  convert_cmd->footer(
      "Material files are first captured noise-free on the reference geometry (theta_in 0, 20, "
      "40, 60; theta_out 0-75; phi_out 0-359; 1 degree steps), then resampled like a capture.\n"
      "Extrapolation, most specific first: <name>.extrapolate.json beside the input, the "
      "material file's own \"extrapolate\" member, --extrapolate, then 1,0.5.\n"
      "Damaged captures: a capture missing slices is not a complete LUT. A corrupt chunk, a "
      "file cut inside a slice, or a slice the instrument did not finish fails that input "
      "(with the byte offset and how to resume or recapture). A capture whose only damage is "
      "a missing or cut end chunk is converted with a warning if every planned theta_in "
      "slice is intact (the plan is the capture's metadata extra \"theta_in_deg\", else 0, "
      "20, 40, 60).\n"
      "A failing input is reported and skipped; the others are converted. Every file is "
      "written atomically; a failed input leaves none of its outputs. Exit code 0 if all "
      "inputs converted, 1 if any failed.\n");
  convert_cmd->callback([&] { exit_code = brdf::cli::RunConvert(convert); });

  // brdf atlas
  brdf::cli::AtlasOptions atlas;
  auto* atlas_cmd = app.add_subcommand(
      "atlas",
      "Pack many materials into one atlas texture (DESIGN §5): PREFIX.ktx2, .dds, .exr and "
      "PREFIX.json (manifest naming every material's cell)");
  atlas_cmd
      ->add_option("inputs", atlas.inputs,
                   "Captures, material files, exported LUTs (.ktx2, .dds, sidecar .json), "
                   "or folders of captures and material files")
      ->required();
  atlas_cmd->add_option("--out", atlas.out, "Output prefix (PREFIX.ktx2, ...)")->required();
  atlas_cmd
      ->add_option("--extrapolate", atlas.extrapolate,
                   "Grazing extrapolation P,L for inputs without their own; default 1,0.5")
      ->capture_default_str();
  atlas_cmd->add_option("--exr-type", atlas.exr_type, "EXR pixel type: float or half")
      ->capture_default_str()
      ->check(CLI::IsMember({"float", "half"}));
  atlas_cmd->add_option("--exr-compression", atlas.exr_compression, "EXR compression: zip or none")
      ->capture_default_str()
      ->check(CLI::IsMember({"zip", "none"}));
  atlas_cmd->add_option("--jobs", atlas.jobs, "Inputs resampled in parallel")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  atlas_cmd->add_flag("--quiet", atlas.quiet, "No progress bar");
  atlas_cmd->footer(
      "Materials are placed in input order (folders sorted by file name). All must share one "
      "theta_in list; materials with different sets are refused by name. Nothing is written "
      "if any input fails.\n");
  atlas_cmd->callback([&] { exit_code = brdf::cli::RunAtlas(atlas); });

  // brdf materials
  brdf::cli::MaterialsOptions materials;
  auto* materials_cmd =
      app.add_subcommand("materials", "List the virtual sample library of the simulator");
  materials_cmd->add_flag("--json", materials.json, "Print JSON instead of a table");
  materials_cmd->callback([&] { exit_code = brdf::cli::RunMaterials(materials); });

  // brdf import
  brdf::cli::ImportOptions import;
  auto* import_cmd = app.add_subcommand(
      "import",
      "Bring a third-party measurement into the toolchain as a .bpc capture: Zemax or "
      "LightTools (MiniDiff) BSDF text, CSV point cloud, spectral goniometer table; RGL .bsdf "
      "and MERL .binary BRDFs become a noise-free virtual capture at the reference geometry");
  import_cmd->add_option("file", import.file, "Measurement file to read")->required();
  import_cmd->add_option("--out", import.out, "Output .bpc file (written atomically)")->required();
  import_cmd
      ->add_option("--format", import.format, "Input format; auto detects it from the content")
      ->check(CLI::IsMember({"auto", "rgl", "zemax", "lighttools", "merl", "csv", "gonio"},
                            CLI::ignore_case))
      ->capture_default_str();
  import_cmd->add_option("--sample", import.sample,
                         "Sample name recorded in the file (default: the input's path)");
  import_cmd->add_flag("--allow-btdf", import.allow_btdf,
                       "Accept transmission (BTDF) tables, stored mirrored into the reflection "
                       "hemisphere");
  import_cmd->add_flag("--force", import.force, "Overwrite --out if it already exists");
  import_cmd->callback([&] { exit_code = brdf::cli::RunImport(import); });

  // brdf export-csv
  brdf::cli::ExportCsvOptions export_csv;
  auto* export_csv_cmd = app.add_subcommand(
      "export-csv",
      "Write a .bpc capture as a CSV point cloud "
      "(theta_in,phi_in,theta_out,phi_out,r,g,b[,sigma_r,sigma_g,sigma_b],flags; degrees, "
      "f_r in 1/sr); values round-trip bit-exactly through 'brdf import'");
  export_csv_cmd->add_option("file", export_csv.file, "Capture to export (.bpc)")->required();
  export_csv_cmd->add_option("--out", export_csv.out, "Output .csv file (written atomically)")
      ->required();
  export_csv_cmd->add_flag("--force", export_csv.force, "Overwrite --out if it already exists");
  export_csv_cmd->callback([&] { exit_code = brdf::cli::RunExportCsv(export_csv); });

  // brdf preview
  brdf::cli::PreviewCommandOptions preview;
  auto* preview_cmd = app.add_subcommand(
      "preview",
      "Render a material, capture, LUT or measured file on a sphere, plane or mesh lit by an "
      "environment map, to a linear .exr or a tone-mapped .png (docs/preview.md)");
  preview_cmd->add_option("source", preview.file, "Anything 'brdf eval' reads")->required();
  preview_cmd->add_option("--compare", preview.compare,
                          "A second source: both renders side by side with their signed "
                          "difference, and the RMS difference printed");
  auto* preview_env = preview_cmd
      ->add_option("--env", preview.env,
                   "Environment: studio, sky, furnace, axes (orientation check) or an "
                   "equirectangular .exr/.hdr file")
      ->capture_default_str();
  preview_cmd->add_option("--env-rotate", preview.env_rotation_deg,
                          "Turn the map about the up axis, degrees")
      ->capture_default_str();
  preview_cmd->add_option("--mesh", preview.mesh, "Object: sphere, plane, or a .ply/.obj file")
      ->capture_default_str();
  preview_cmd->add_option("--size", preview.size, "Image width and height in pixels")
      ->capture_default_str()
      ->check(CLI::Range(1, 8192));
  auto* preview_spp = preview_cmd
      ->add_option("--spp", preview.spp, "Samples (passes) per pixel")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  preview_cmd
      ->add_option("--rms", preview.rms,
                   "Instead of --spp: render until the estimated relative RMS error is below "
                   "this (e.g. 0.01)")
      ->check(CLI::Range(1e-6, 1.0))
      ->excludes(preview_spp);
  preview_cmd
      ->add_option("--light", preview.light,
                   "A directional light from THETA,PHI (degrees, world frame, z up); without "
                   "--env the map then does not light the object")
      ->check(AnglePairValidator());
  preview_cmd->add_option("--view", preview.view, "Camera position THETA,PHI seen from the object")
      ->capture_default_str()
      ->check(AnglePairValidator());
  preview_cmd->add_option("--fov", preview.fov_deg,
                          "Perspective camera with this vertical field of view, degrees "
                          "(default: orthographic)");
  preview_cmd->add_option("--exposure", preview.exposure_ev, "PNG exposure in stops")
      ->capture_default_str();
  preview_cmd->add_option("--tone-map", preview.tone_map, "PNG tone curve after exposure")
      ->capture_default_str()
      ->check(CLI::IsMember({"clamp", "reinhard"}));
  preview_cmd->add_option("--estimator", preview.estimator,
                          "mis (default), env, brdf, or quadrature (sphere and plane only)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mis", "env", "brdf", "quadrature"}));
  preview_cmd->add_option("--extrapolate", preview.extrapolate,
                          "Captures: grazing extrapolation P,L (docs/design.md §6)");
  preview_cmd->add_option("--jobs", preview.jobs, "Worker threads")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  preview_cmd->add_option("--seed", preview.seed, "Random seed")->capture_default_str();
  preview_cmd->add_option("--out", preview.out, "Output image (.exr or .png)")->required();
  preview_cmd->add_flag("--no-background", preview.no_background,
                        "Black where the object is not, instead of the map");
  preview_cmd->add_flag("--quiet", preview.quiet, "No progress on stderr");
  preview_cmd->footer(
      "World frame: z up; the map's top row is the zenith, its left edge azimuth 0 (+x), "
      "azimuth growing to the right. The default camera looks from +x, so the map's centre is "
      "behind the object. EXR: linear radiance; PNG: exposure, then the tone curve, then sRGB.\n");
  preview_cmd->callback([&] {
    preview.env_given = preview_env->count() > 0;
    exit_code = brdf::cli::RunPreview(preview);
  });

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
