// `brdf`: the command-line face of brdf-toolchain. This is the only translation unit that
// sees CLI11; each subcommand parses into an options struct and calls its Run* function.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/measurement.h"
#include "cli_support.h"
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

// A whole number of at least `min`, as typed: "0", "-1", "2.5", "abc" and "" are refused with
// the value quoted (CLI::PositiveNumber printed its range as two 309-digit numbers).
// Help texts of options that convert and atlas share, written once so they cannot drift.
constexpr const char* kExrCompressionHelp =
    "EXR compression: none or zip (zip: float EXRs of measured data about 20 % smaller, writing "
    "takes about twice as long)";
constexpr const char* kExrTypeHelp = "EXR pixel type: float, or half (faster to write, smaller)";

CLI::Validator WholeNumberAtLeast(long long min) {
  return CLI::Validator(
      [min](std::string& text) -> std::string {
        const std::string expected = "expected a whole number >= " + std::to_string(min);
        try {
          std::size_t used = 0;
          const long long v = std::stoll(text, &used);
          if (used == text.size() && v >= min) return {};
        } catch (const std::exception&) {
        }
        return expected + ", got '" + text + "'";
      },
      "INT>=" + std::to_string(min));
}

// A whole number in [lo, hi] as typed: "0", "2.5", "abc" and "" are refused with the value and
// the range quoted in plain numbers (CLI::Range printed "Value 0 not in range 1 to 8192", and
// for a double range "%f" figures).
CLI::Validator WholeNumberIn(long long lo, long long hi) {
  const std::string range = std::to_string(lo) + " to " + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        try {
          std::size_t used = 0;
          const long long v = std::stoll(text, &used);
          if (used == text.size() && v >= lo && v <= hi) return {};
        } catch (const std::exception&) {
        }
        return "expected a whole number from " + range + ", got '" + text + "'";
      },
      "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

// A finite number as typed, within [lo, hi] (or (lo, hi) when `open`), with its unit: "nan",
// "inf", "abc" and values outside are refused with the value quoted.
CLI::Validator NumberWithin(double lo, double hi, bool open, const std::string& unit) {
  char bounds[80];
  std::snprintf(bounds, sizeof bounds, open ? "(%g, %g)" : "[%g, %g]", lo, hi);
  const std::string range = bounds + (unit.empty() ? std::string() : " " + unit);
  return CLI::Validator(
      [lo, hi, open, range](std::string& text) -> std::string {
        try {
          std::size_t used = 0;
          const double v = std::stod(text, &used);
          const bool inside = open ? (v > lo && v < hi) : (v >= lo && v <= hi);
          if (used == text.size() && std::isfinite(v) && inside) return {};
        } catch (const std::exception&) {
        }
        return "expected a number in " + range + ", got '" + text + "'";
      },
      range);
}

// A finite number as typed ("nan" and "inf" refused), with its unit.
CLI::Validator FiniteNumber(const std::string& unit) {
  return CLI::Validator(
      [unit](std::string& text) -> std::string {
        try {
          std::size_t used = 0;
          const double v = std::stod(text, &used);
          if (used == text.size() && std::isfinite(v)) return {};
        } catch (const std::exception&) {
        }
        return "expected a finite number" + (unit.empty() ? std::string() : " of " + unit) +
               ", got '" + text + "'";
      },
      "");  // the help keeps the option's type and default ("--noise FLOAT=1")
}

// --engine: a list of engine names; an empty value (`--engine ''`, which wrote nothing) is
// refused like an unknown name (the names themselves are checked by engines::ParseEngines).
CLI::Validator EngineList() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (!text.empty()) return {};
        return "expected unity, unreal, godot, web or all (comma separated), got ''";
      },
      "LIST");
}

// A number in (lo, hi] as typed, with its unit: "abc", "0" and "95" are refused with the value
// quoted (CLI::Range said "Value abc not in range 0.001000 to 90.000000").
CLI::Validator NumberAboveUpTo(double lo, double hi, const std::string& unit) {
  char bounds[64];
  std::snprintf(bounds, sizeof bounds, "(%g, %g]", lo, hi);
  const std::string range = bounds + (" " + unit);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        try {
          std::size_t used = 0;
          const double v = std::stod(text, &used);
          if (used == text.size() && v > lo && v <= hi) return {};
        } catch (const std::exception&) {
        }
        return "expected a number in " + range + ", got '" + text + "'";
      },
      "NUMBER in " + range);
}

// One line for every command-line error, like every other error of the tool: CLI11's message
// (for "--jobs: ..." it already names the option) and where help is.
std::string OneLineParseError(const CLI::App& app, const CLI::Error& e) {
  std::string command = "brdf", where = "brdf: ";
  for (const CLI::App* sub : app.get_subcommands()) {
    command += " " + sub->get_name();
    where += sub->get_name() + ": ";
  }
  std::string what = e.what();
  if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
    // CLI11 lists the extras last-first ("1 --bogus"); say them in the order they were typed.
    std::string typed;
    for (const std::string& a : app.remaining(true)) typed += (typed.empty() ? "" : " ") + a;
    if (!typed.empty()) what = "unexpected argument(s) '" + typed + "'";
  }
  const std::size_t override_at = what.find(" was given a disallowed flag override");
  if (override_at != std::string::npos)
    what = "--" + what.substr(0, override_at) + " is a switch and takes no value";
  for (char& c : what)
    if (c == '\n') c = ' ';
  return where + what + " (see '" + command + " --help')";
}

// CLI11 takes the token after an option as its value even when it is another option, so
// "--env --out a.png" would set the map to "--out" and then report --out missing. Said instead
// as the user's mistake: the option typed without its value. Empty when there is none.
std::string OptionWithoutValue(CLI::App& app, int argc, char** argv) {
  if (argc < 2) return {};
  CLI::App* sub = nullptr;
  for (CLI::App* candidate : app.get_subcommands({}))
    if (candidate->get_name() == argv[1]) sub = candidate;
  if (sub == nullptr) return {};
  auto option_named = [&](const std::string& token) -> const CLI::Option* {
    if (token.size() < 3 || token.compare(0, 2, "--") != 0) return nullptr;
    return sub->get_option_no_throw(token.substr(0, token.find('=')));
  };
  for (int i = 2; i + 1 < argc; ++i) {
    const std::string token = argv[i], next = argv[i + 1];
    if (token == "--") break;  // the rest are values
    const CLI::Option* option = option_named(token);
    if (option == nullptr || token.find('=') != std::string::npos ||
        option->get_items_expected_min() == 0)
      continue;
    if (option_named(next) != nullptr || next == "--help")
      return "brdf: " + sub->get_name() + ": " + token +
             " needs a value, but the next argument is the option '" + next + "' (see 'brdf " +
             sub->get_name() + " --help')";
  }
  return {};
}

// Said wherever a source argument is described: how a name and a file of that name are told apart
// (brdf/sources/material_library.h).
constexpr const char* kLibraryNames =
    " ('brdf materials' lists them; a file of the same name wins)";

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"brdf: measured reflectance to engine-ready lookup textures"};
  app.set_version_flag("--version", std::string("brdf-toolchain ") + brdf::SoftwareVersion());
  app.require_subcommand(1);
  // A switch takes no value: "--robust=3" is refused instead of being read as "on".
  app.option_defaults()->disable_flag_override();
  // Errors reported through app.exit() (none today: main prints them) look the same.
  app.failure_message(
      [](const CLI::App* a, const CLI::Error& e) { return OneLineParseError(*a, e) + "\n"; });
  int exit_code = 0;

  // brdf eval
  brdf::cli::EvalOptions eval;
  std::string eval_in, eval_out;
  auto* eval_cmd = app.add_subcommand(
      "eval",
      "Print f_r (1/sr, linear RGB) of a material, capture or exported LUT for a pair of "
      "directions (or many, with --pairs)");
  eval_cmd
      ->add_option(
          "file", eval.file,
          "Material file (.json), capture (.bpc), exported LUT (.ktx2, .dds, compact "
          ".brdfc), LUT sidecar (.json), or measured data: RGL .bsdf, MERL .binary, or a table "
          "interpolated like a capture (Zemax or LightTools .bsdf, CSV point cloud, "
          "goniometer table; detected by content), or a library material name" +
              std::string(kLibraryNames))
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
                   "Captures: grazing extrapolation P,L (docs/design.md §6); default: the "
                   "per-material JSON beside the file, else 1,0.5")
      ->capture_default_str();
  eval_cmd
      ->add_option("--beyond", eval.beyond,
                   "Captures: what fills the directions not measured, as 'brdf convert "
                   "--beyond' (clamp, hold, model, auto)")
      ->capture_default_str()
      ->check(CLI::IsMember({"clamp", "hold", "model", "auto"}));
  eval_cmd
      ->add_option("--beyond-subdivide", eval.beyond_subdivide,
                   "Captures: as 'brdf convert --beyond-subdivide'")
      ->capture_default_str()
      ->check(WholeNumberIn(1, 20));
  eval_cmd->footer(
      "Captures are interpolated as 'brdf convert' resamples them; exported LUTs are sampled "
      "as a GPU samples the 3D texture (centre-exact coordinates, trilinear, clamp-to-edge). "
      "A light beyond the measured θin range with the view nearer to it is answered with light "
      "and view exchanged (reciprocity, docs/design.md §5).\n");
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
#ifdef BRDF_HAVE_DEVICE_EMULATION
  const char* const kTransportHelp =
      "How --device sim is connected: loopback (in-process), usb or hid (the simulated firmware "
      "behind real libusb or hidapi through umockdev; run under umockdev-wrapper)";
#else
  const char* const kTransportHelp =
      "How --device sim is connected: loopback (in-process); the emulated usb and hid transports "
      "are not part of this build";
#endif
  auto* capture_cmd = app.add_subcommand(
      "capture",
      "Capture a sample slice by slice with a scatterometer into a .bpc file (each completed "
      "slice is saved at once; --resume continues an interrupted capture)");
  capture_cmd
      ->add_option("--device", capture.device,
                   "Instrument: sim (the simulated scatterometer), usb[:VID:PID[:SERIAL]] "
                   "(vendor bulk interface, libusb) or hid[:VID:PID[:SERIAL]] (HID reports, "
                   "hidapi); IDs in hexadecimal, the first instrument found when omitted")
      ->capture_default_str();
  capture_cmd->add_option("--transport", capture.transport, kTransportHelp)->capture_default_str();
  capture_cmd->add_option("--material", capture.material,
                          "Virtual sample of --device sim (required for it): a library material "
                          "name or any file 'brdf eval' reads" +
                              std::string(kLibraryNames));
  capture_cmd->add_option("--sample", capture.sample, "Sample name recorded in the file")
      ->required();
  capture_cmd->add_option("--out", capture.out, "Output .bpc file")->required();
  capture_cmd
      ->add_option("--theta-in", capture.geometry.theta_in_deg,
                   "Incidence angles in degrees, comma separated, in capture order")
      ->delimiter(',')
      ->capture_default_str();
  capture_cmd
      ->add_option("--theta-out-max", capture.geometry.theta_out_max_deg,
                   "Largest detector polar angle, degrees (sim)")
      ->capture_default_str()
      ->check(FiniteNumber("degrees"));
  capture_cmd
      ->add_option("--theta-out-step", capture.geometry.theta_out_step_deg,
                   "Detector polar step, degrees (sim)")
      ->capture_default_str()
      ->check(FiniteNumber("degrees"));
  capture_cmd
      ->add_option("--phi-out-step", capture.geometry.phi_out_step_deg,
                   "Detector azimuth step, degrees (sim)")
      ->capture_default_str()
      ->check(FiniteNumber("degrees"));
  capture_cmd
      ->add_option("--noise", capture.noise,
                   "Detector noise level: 1 = reference instrument, 0 = ideal detector "
                   "(noise-free, unsaturated signal)")
      ->capture_default_str()
      ->check(FiniteNumber(""));
  capture_cmd->add_option("--seed", capture.seed, "Seed of the simulated detector noise")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& text) {
            // CLI11 would wrap "-1" around to 2^64 − 1; a seed is typed as a whole number.
            const bool digits = !text.empty() && text.size() <= 20 &&
                                text.find_first_not_of("0123456789") == std::string::npos;
            return digits ? std::string() : "expected a whole number ≥ 0, got '" + text + "'";
          },
          ""));
  capture_cmd
      ->add_option("--exposure", capture.exposure,
                   "Exposure: auto (ranged per θout row), auto-slice, or a fixed time in ms")
      ->capture_default_str();
  capture_cmd->add_option("--operator-notes", capture.operator_notes,
                          "Free text recorded in the file's metadata");
  capture_cmd->add_flag(
      "--resume", capture.resume,
      "Continue an interrupted capture in --out: re-identify the instrument, keep the complete "
      "slices, measure the rest (with the file's dark and white references unless --calibrate)");
  capture_cmd->add_flag("--force", capture.force,
                        "Overwrite --out if it already exists; with --resume, accept an "
                        "instrument whose serial number or geometry differs from the file's");
  capture_cmd->add_flag("--calibrate", capture.calibrate,
                        "Measure the dark and white references first also when resuming (a new "
                        "capture always measures them)");
  capture_cmd->add_flag("--quiet", capture.quiet, "No progress on stderr");
  capture_cmd
      ->add_option("--sim-fault", capture.sim_fault,
                   "Testing: faults of the simulated instrument, NAME:N comma separated, all "
                   "applied (N = the instrument's Nth frame): disconnect, stall (stops "
                   "answering), timeout (silent until ABORT), corrupt (bad CRC), duplicate, "
                   "reorder (N and N+1 swapped), lamp, contact, overtemp (firmware error "
                   "codes); halt (the Nth USB/HID IN transfer stalls); hold (silent from frame "
                   "N until the capture is cancelled, announced on stderr)")
      ->group("Testing");
  capture_cmd
      ->add_option("--sim-pace-ms", capture.sim_pace_ms,
                   "Testing: real time the simulated firmware spends per detector row, ms")
      ->check(FiniteNumber("ms"))
      ->group("Testing");
  capture_cmd->callback([&] { exit_code = brdf::cli::RunCapture(capture); });

  // brdf devices
  brdf::cli::DevicesOptions devices;
  auto* devices_cmd = app.add_subcommand(
      "devices",
      "List the scatterometers connected over USB and HID (model, serial, firmware, bus "
      "path, permission problems)");
  devices_cmd->add_flag("--json", devices.json, "Machine-readable output");
  devices_cmd->callback([&] { exit_code = brdf::cli::RunDevices(devices); });

  // brdf info
  brdf::cli::InfoOptions info;
  auto* info_cmd = app.add_subcommand(
      "info",
      "Describe a file: a .bpc capture (slices, samples, ranges, statistics, flags, "
      "metadata, damage), a material .json (model and parameters), an exported LUT or atlas "
      "(.ktx2, .dds, compact .brdfc) or its sidecar / manifest .json (dimensions, θin, payload, "
      "checksum, "
      "extrapolation, value ranges), or a third-party measurement (Zemax or LightTools .bsdf "
      "with the integrated TIS per incidence, CSV point cloud, goniometer table, RGL .bsdf, "
      "MERL .binary). Exit code 1 when a command that reads the file refuses it (\"usable\": "
      "false, reasons under \"refusals\"; a θin list that is not k·Δin is refused by convert "
      "and atlas alone)");
  info_cmd
      ->add_option("file", info.file,
                   "File to describe (.bpc, .json, .ktx2, .dds, .brdfc, .bsdf, .csv, .binary) or a "
                   "library material name" +
                       std::string(kLibraryNames))
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
                   "Capture files, material files, or folders of them (not recursive), or "
                   "library material names" +
                       std::string(kLibraryNames))
      ->required();
  convert_cmd->add_option("--out", convert.out, "Output folder (created if missing)")->required();
  convert_cmd
      ->add_option("--extrapolate", convert.extrapolate,
                   "Grazing extrapolation P,L (docs/design.md §6) for inputs without their own; "
                   "default 1,0.5 (clamping); 'auto' fits GGX to each input and chooses P,L "
                   "that follow its fall-off to 90 deg (recorded in the sidecar)")
      ->capture_default_str();
  convert_cmd
      ->add_option("--beyond", convert.beyond,
                   "What fills the light beyond the last measured slice and the view beyond "
                   "the last measured theta_out (docs/design.md §5): clamp (the nearest slice, "
                   "no extra slice), hold (extra slices up to 80 deg by reciprocity and the "
                   "held measured values), model (extra slices and band from a ggx, ward or "
                   "lafortune material fitted to the capture, as a ratio on the measured "
                   "values; the family that predicts the last slice best from the others) or auto "
                   "(hold or model, "
                   "whichever predicts the capture's last slice better from the others)")
      ->capture_default_str()
      ->check(CLI::IsMember({"clamp", "hold", "model", "auto"}));
  convert_cmd
      ->add_option("--beyond-subdivide", convert.beyond_subdivide,
                   "With hold, model or auto: the filled LUT's theta_in step is the measured "
                   "one divided by this (2: 10 deg slices 0-80 for the reference instrument, "
                   "filtering follows grazing highlights; 1: the measured step)")
      ->capture_default_str()
      ->check(WholeNumberIn(1, 20));
  convert_cmd->add_option("--formats", convert.formats, "Comma-separated outputs to write")
      ->capture_default_str();
  convert_cmd->add_option("--exr-type", convert.exr_type, kExrTypeHelp)
      ->capture_default_str()
      ->check(CLI::IsMember({"float", "half"}));
  convert_cmd->add_option("--exr-compression", convert.exr_compression, kExrCompressionHelp)
      ->capture_default_str()
      ->check(CLI::IsMember({"zip", "none"}));
  convert_cmd
      ->add_option("--compress", convert.compress,
                   "Texel format of the KTX2 and DDS: none (RGB9E5) or bc6h (BC6H_UF16 blocks, "
                   "4x smaller), or compact (NAME.brdfc in their place: an adaptive log grid, "
                   "20-600x smaller, built to a measured-range max error of 2 %, read by the "
                   "engine kit's compact GLSL decoder); the sidecar records the error against "
                   "the float LUT: max, p99 and median over the measured and the filled range. "
                   "With --engine, bc6h writes the engine folders as BC6H too (364x184 slices); "
                   "compact is refused there")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "bc6h", "compact"}));
  convert_cmd
      ->add_option("--max-error", convert.max_error,
                   "Largest relative error allowed on the measured range (a fraction, e.g. "
                   "0.01): per input, the smallest of compact, BC6H and RGB9E5 that meets it is "
                   "written (RGB9E5 with a warning when none does) and reported with its bytes "
                   "and error; overrides --compress. With --engine: BC6H or RGB9E5 only (no "
                   "engine kit samples the compact form), the engine folders in the same form")
      ->check(CLI::Range(1e-6, 0.999999));
  convert_cmd
      ->add_option("--jobs", convert.jobs,
                   "Inputs converted in parallel (default: hardware threads)")
      ->capture_default_str()
      ->check(WholeNumberAtLeast(1));
  convert_cmd->add_flag("--quiet", convert.quiet, "No progress bar");
  convert_cmd->add_flag("--force", convert.force,
                        "Overwrite outputs that already exist in --out (without it nothing is "
                        "converted when any output exists)");
  convert_cmd
      ->add_option(
          "--engine", convert.engines,
          "Also write engine hand-off folders DIR/<engine>/ (importer, shader code, manifest, "
          "texture in the engine's format, IBL pack NAME_ibl.dds): unity, unreal, godot, web "
          "(comma separated) or all")
      ->check(EngineList());
  convert_cmd->add_option("--engine-fits", convert.engine_fits,
                          "With --engine: folder of `brdf fit` results (NAME.MODEL.json); each "
                          "manifest carries NAME's fits, with their errors, as fallback material");
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
      "Pack many materials into one atlas texture (docs/design.md §5): PREFIX.ktx2, .dds, .exr and "
      "PREFIX.json (manifest naming every material's cell)");
  atlas_cmd
      ->add_option("inputs", atlas.inputs,
                   "Captures, material files, exported LUTs (.ktx2, .dds, sidecar .json), "
                   "or folders of captures and material files, or library material names" +
                       std::string(kLibraryNames))
      ->required();
  atlas_cmd->add_option("--out", atlas.out, "Output prefix (PREFIX.ktx2, ...)")->required();
  atlas_cmd
      ->add_option("--extrapolate", atlas.extrapolate,
                   "Grazing extrapolation P,L for inputs without their own; default 1,0.5; "
                   "'auto' fits GGX to each input and chooses P,L that follow its fall-off")
      ->capture_default_str();
  atlas_cmd->add_option("--exr-type", atlas.exr_type, kExrTypeHelp)
      ->capture_default_str()
      ->check(CLI::IsMember({"float", "half"}));
  atlas_cmd->add_option("--exr-compression", atlas.exr_compression, kExrCompressionHelp)
      ->capture_default_str()
      ->check(CLI::IsMember({"zip", "none"}));
  atlas_cmd
      ->add_option("--compress", atlas.compress,
                   "Texel format of the KTX2 and DDS: none (RGB9E5) or bc6h (BC6H_UF16 blocks; "
                   "the manifest records each material's error against its float LUT)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "bc6h"}));
  atlas_cmd
      ->add_option("--max-error", atlas.max_error,
                   "Largest relative error allowed on each material's measured range (a "
                   "fraction, e.g. 0.01): the atlas is one texture, so it is BC6H when every "
                   "material meets the bound with BC6H, else RGB9E5 (a warning for materials "
                   "still above it); prints which, and each material's error, also recorded in "
                   "the manifest; overrides --compress")
      ->check(CLI::Range(1e-6, 0.999999));
  atlas_cmd->add_option("--jobs", atlas.jobs, "Inputs resampled in parallel")
      ->capture_default_str()
      ->check(WholeNumberAtLeast(1));
  atlas_cmd->add_flag("--quiet", atlas.quiet, "No progress bar");
  atlas_cmd->add_flag("--force", atlas.force,
                      "Overwrite PREFIX.ktx2, .dds, .exr, .json if any already exists");
  atlas_cmd
      ->add_option("--engine", atlas.engines,
                   "Also write engine hand-off folders beside the prefix: unity, unreal, "
                   "godot, web (comma separated) or all")
      ->check(EngineList());
  atlas_cmd->footer(
      "Materials are placed in input order (folders sorted by file name). All must share one "
      "theta_in list; materials with different sets are refused by name. Nothing is written "
      "if any input fails.\n");
  atlas_cmd->callback([&] { exit_code = brdf::cli::RunAtlas(atlas); });

  // brdf materials
  brdf::cli::MaterialsOptions materials;
  auto* materials_cmd =
      app.add_subcommand("materials",
                         "List the virtual sample library: the material names every command "
                         "that reads a source accepts, and the simulator's samples");
  materials_cmd->add_flag("--json", materials.json, "Print JSON instead of a table");
  materials_cmd->footer(
      "The library is the folder $BRDF_MATERIALS_DIR when set, else the installed "
      "<prefix>/share/brdf-toolchain/materials (found from the brdf executable's folder), else "
      "the source tree's data-samples/materials. A file of the same name as a library material "
      "wins over it: 'brdf eval gold' reads ./gold if it exists.");
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
      "f_r in 1/sr); values round-trip bit-exactly through 'brdf import'. Samples the other "
      "commands refuse (an incomplete slice, values no surface has) are copied with a warning");
  export_csv_cmd->add_option("file", export_csv.file, "Capture to export (.bpc)")->required();
  export_csv_cmd->add_option("--out", export_csv.out, "Output .csv file (written atomically)")
      ->required();
  export_csv_cmd->add_flag("--force", export_csv.force, "Overwrite --out if it already exists");
  export_csv_cmd->callback([&] { exit_code = brdf::cli::RunExportCsv(export_csv); });

  // brdf repair
  brdf::cli::RepairOptions repair;
  auto* repair_cmd = app.add_subcommand(
      "repair",
      "Write every intact slice of a damaged or unfinished capture to a new .bpc that "
      "'brdf capture --resume' completes, dropping slices whose values every command refuses "
      "(NaN, negative or absurd f_r, no valid sample); names every part it drops (slice, "
      "theta_in, byte offset, reason)");
  repair_cmd->add_option("file", repair.file, "Damaged or unfinished capture (.bpc)")->required();
  repair_cmd->add_option("--out", repair.out, "New capture (.bpc, written atomically)")->required();
  repair_cmd->add_flag("--force", repair.force, "Overwrite --out if it already exists");
  repair_cmd->footer(
      "The new file keeps the original header (sample, settings, planned theta_in list) and "
      "has no end chunk: resume it with the 'brdf capture' command that made the original, "
      "with --out set to the new file and --resume, to capture the missing slices.");
  repair_cmd->callback([&] { exit_code = brdf::cli::RunRepair(repair); });
  // brdf fit
  brdf::cli::FitCommandOptions fit;
  auto* fit_cmd = app.add_subcommand(
      "fit",
      "Fit analytic BRDF models (lafortune, ggx, blinn-phong, ward, lambert) and the engines' "
      "shading models (unreal-defaultlit, unity-hdrp-lit[-specular], unity-urp-lit[-specular]) "
      "to captures, material files or measured BRDFs; writes material files with the fit "
      "report under \"fit\" (\"representable\": false, with a warning, for a fit with fewer "
      "usable samples than twice the parameters per colour channel); transmission (BTDF) "
      "tables are read mirrored into the reflection hemisphere, as eval reads them");
  fit_cmd
      ->add_option("inputs", fit.inputs,
                   "Captures (.bpc), material files (.json), RGL .bsdf or MERL .binary files, "
                   "third-party tables (Zemax, LightTools, CSV, goniometer), exported LUTs "
                   "(.ktx2, .dds, sidecar .json), or folders of captures, material files and "
                   "measured BRDF files (RGL, MERL, Zemax, LightTools; recognised by content), "
                   "or library material names" +
                       std::string(kLibraryNames))
      ->required();
  fit_cmd
      ->add_option("--model", fit.model,
                   "lambert, lafortune, ggx, blinn-phong, ward, unreal-defaultlit, unity-hdrp-lit, "
                   "unity-hdrp-lit-specular, unity-urp-lit, unity-urp-lit-specular, or all")
      ->capture_default_str()
      ->check(CLI::IsMember({"lambert", "lafortune", "ggx", "blinn-phong", "ward",
                             "unreal-defaultlit", "unity-hdrp-lit", "unity-hdrp-lit-specular",
                             "unity-urp-lit", "unity-urp-lit-specular", "all"}));
  fit_cmd
      ->add_option("--out", fit.out,
                   "Output material file (.json) for one input and one model; otherwise a "
                   "folder receiving INPUT.MODEL.json (or FIT.MODEL.json beside a .json name "
                   "with --model all)")
      ->required();
  fit_cmd
      ->add_option("--loss", fit.loss,
                   "ngan (cos-weighted L2 with solid-angle weights), log (ln(1 + f cos)), cbrt "
                   "(cube roots)")
      ->capture_default_str()
      ->check(CLI::IsMember({"ngan", "log", "cbrt"}));
  fit_cmd->add_flag("--robust", fit.robust,
                    "Cauchy loss against outliers, per sample and channel; its scale is 1.4826 "
                    "x the median residual at the start (recorded as fit.robust_scale)");
  fit_cmd
      ->add_option("--max-theta-out", fit.max_theta_out_deg,
                   "Leave out samples beyond this theta_out (degrees); default: all measured")
      ->check(NumberAboveUpTo(0, 90, "degrees"));
  fit_cmd->add_option("--starts", fit.starts, "Sweep candidates refined by Ceres")
      ->capture_default_str()
      ->check(WholeNumberAtLeast(1));
  fit_cmd
      ->add_option(
          "--jobs", fit.jobs,
          "Threads: inputs fitted in parallel, or for a single input its colour channels and "
          "the two fixed halves its samples are summed in (results do not depend on --jobs)")
      ->capture_default_str()
      ->check(WholeNumberAtLeast(1));
  fit_cmd->add_flag("--force", fit.force, "Overwrite existing output files");
  fit_cmd->add_flag("--quiet", fit.quiet, "No progress on stderr");
  fit_cmd->callback([&] { exit_code = brdf::cli::RunFit(fit); });
  // brdf preview
  brdf::cli::PreviewCommandOptions preview;
  auto* preview_cmd = app.add_subcommand(
      "preview",
      "Render a material, capture, LUT or measured file on a sphere, plane or mesh lit by an "
      "environment map, to a linear .exr or a tone-mapped .png (docs/preview.md)");
  preview_cmd->add_option("source", preview.file, "Anything 'brdf eval' reads")->required();
  preview_cmd->add_option("--compare", preview.compare,
                          "A second source: both renders side by side with their signed "
                          "difference, and the RMS difference printed (the second source is "
                          "always lit by the true integral, whatever --ibl says)");
  preview_cmd
      ->add_option("--ibl", preview.ibl,
                   "How the map lights the source: true (default: the rendering integral) or "
                   "engine (what an engine's probes give: the split sum of the material's IBL "
                   "pack, SH irradiance and a GGX-prefiltered map at the pack's equivalent "
                   "roughness; docs/preview.md). 'SOURCE --ibl engine --compare SOURCE' shows "
                   "the engine's error")
      ->capture_default_str()
      ->check(CLI::IsMember({"true", "engine"}));
  auto* preview_env =
      preview_cmd
          ->add_option("--env", preview.env,
                       "Environment: studio, sky, furnace, axes (orientation check) or an "
                       "equirectangular .exr/.hdr file")
          ->capture_default_str();
  preview_cmd
      ->add_option("--env-rotate", preview.env_rotation_deg,
                   "Turn the map about the up axis, degrees")
      ->capture_default_str()
      ->check(FiniteNumber("degrees"));
  preview_cmd->add_option("--mesh", preview.mesh, "Object: sphere, plane, or a .ply/.obj file")
      ->capture_default_str();
  preview_cmd->add_option("--size", preview.size, "Image width and height in pixels")
      ->capture_default_str()
      ->check(WholeNumberIn(1, 8192));
  auto* preview_spp =
      preview_cmd->add_option("--spp", preview.spp, "Monte Carlo passes per pixel (selects mis)")
          ->capture_default_str()
          ->check(WholeNumberIn(1, 1 << 20));
  preview_cmd
      ->add_option("--rms", preview.rms,
                   "Instead of --spp: Monte Carlo until the estimated relative RMS error is below "
                   "this (e.g. 0.01)")
      ->check(NumberWithin(1e-6, 1.0, /*open=*/false, ""))
      ->excludes(preview_spp);
  preview_cmd
      ->add_option("--light", preview.light,
                   "A directional light from THETA,PHI (degrees, world frame, z up); without "
                   "--env the map then does not light the object")
      ->check(AnglePairValidator());
  preview_cmd
      ->add_option("--view", preview.view,
                   "Camera position THETA,PHI seen from the object (default 90,0; 60,0 for the "
                   "plane, which 90,0 sees edge-on)")
      ->check(AnglePairValidator());
  preview_cmd
      ->add_option("--fov", preview.fov_deg,
                   "Perspective camera with this vertical field of view, degrees, in (0, 170) "
                   "(default: orthographic)")
      ->check(NumberWithin(0, 170, /*open=*/true, "degrees"));
  preview_cmd->add_option("--exposure", preview.exposure_ev, "PNG exposure in stops")
      ->capture_default_str()
      ->check(FiniteNumber("stops"));
  preview_cmd->add_option("--tone-map", preview.tone_map, "PNG tone curve after exposure")
      ->capture_default_str()
      ->check(CLI::IsMember({"clamp", "reinhard"}));
  preview_cmd
      ->add_option("--estimator", preview.estimator,
                   "auto (default): the sphere by the deterministic hierarchical quadrature "
                   "(one pass, at 512 px typically within 1 % RMS of the converged image; "
                   "docs/preview.md), planes and meshes by mis; with --spp or --rms, mis. "
                   "Or: hierarchical (sphere, plane), mis (Monte Carlo, map and BRDF samples "
                   "combined), env, brdf, quadrature (brute force over every map pixel, the slow "
                   "reference; sphere, plane)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "hierarchical", "mis", "env", "brdf", "quadrature"}));
  preview_cmd
      ->add_option("--subdivisions", preview.subdivisions,
                   "quadrature: each map pixel split N × N (midpoint rule)")
      ->capture_default_str()
      ->check(WholeNumberIn(1, 16));
  preview_cmd
      ->add_option("--sample-pixels", preview.sample_pixels,
                   "Render only N object pixels spread evenly over the image, the rest black "
                   "(references with the slow estimators)")
      ->check(WholeNumberIn(1, 1 << 26));
  preview_cmd->add_option("--extrapolate", preview.extrapolate,
                          "Captures: grazing extrapolation P,L (docs/design.md §6)");
  preview_cmd->add_option("--jobs", preview.jobs, "Worker threads")
      ->capture_default_str()
      ->check(WholeNumberAtLeast(1));
  preview_cmd->add_option("--seed", preview.seed, "Random seed")->capture_default_str();
  preview_cmd->add_option("--out", preview.out, "Output image (.exr or .png)")->required();
  preview_cmd->add_flag("--no-background", preview.no_background,
                        "Black where the object is not, instead of the map");
  preview_cmd->add_flag("--quiet", preview.quiet, "No progress on stderr");
  preview_cmd->add_flag("--force", preview.force, "Overwrite --out if it already exists");
  preview_cmd->footer(
      "World frame: z up; the map's top row is the zenith, its left edge azimuth 0 (+x), "
      "azimuth growing to the right. The default camera looks from +x, so the map's centre is "
      "behind the object. EXR: linear radiance; PNG: exposure, then the tone curve, then sRGB.\n");
  preview_cmd->callback([&] {
    preview.env_given = preview_env->count() > 0;
    preview.spp_given = preview_spp->count() > 0;
    exit_code = brdf::cli::RunPreview(preview);
  });

  if (const std::string missing = OptionWithoutValue(app, argc, argv); !missing.empty()) {
    std::fprintf(stderr, "%s\n", missing.c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::fprintf(stderr, "%s\n", OneLineParseError(app, e).c_str());
    return 2;
  } catch (const brdf::Error& e) {
    // Every remedy (--force for an existing output included) rendered by cli::RemedyText.
    const std::string command =
        app.get_subcommands().empty() ? std::string() : app.get_subcommands().front()->get_name();
    std::fprintf(stderr, "brdf: error: %s\n", brdf::cli::ErrorLine(e, command).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "brdf: internal error: %s\n", e.what());
    return 3;
  }
  return exit_code;
}
