// The `brdf` subcommands. main.cpp parses the command line with CLI11 into these option
// structs; each Run* function lives in its own translation unit, writes results to stdout,
// progress to stderr, and returns the process exit code. Errors thrown as brdf::Error are
// turned into one line on stderr by main.cpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "brdf/core/virtual_capture.h"

namespace brdf::cli {

struct InfoOptions {
  std::string file;
  bool json = false;
};
int RunInfo(const InfoOptions& options);

struct EvalOptions {
  std::string file;
  double theta_in_deg = 0, phi_in_deg = 0;
  double theta_out_deg = 0, phi_out_deg = 0;
  std::string extrapolate;  // "P,L" for captures; empty: per-material JSON, else 1,0.5
  // Captures: blind-spot fill, as `brdf convert --beyond` (processing::kDefaultBeyondMethod).
  std::string beyond = "auto";
  int beyond_subdivide = 2;  // captures: as `brdf convert --beyond-subdivide`
  // Many directions at once instead of --in/--out: a file ("-" = stdin) of lines
  // "THETA_IN PHI_IN THETA_OUT PHI_OUT" (degrees, blanks or commas between); one output line
  // each. Empty lines and lines starting with '#' are skipped.
  std::string pairs;
};
int RunEval(const EvalOptions& options);

// std::thread::hardware_concurrency(), at least 1: the default of --jobs.
int DefaultJobs();

// The export formats `brdf convert` writes unless told otherwise.
inline constexpr const char* kAllLutFormats = "ktx2,dds,exr,png,json";

struct ConvertOptions {
  std::vector<std::string> inputs;  // files and folders
  std::string out;                  // output folder (created if missing)
  std::string extrapolate;          // "P,L"; empty: per-material JSON, else 1,0.5
  // Blind-spot fill (brdf/processing/beyond.h): "clamp", "hold", "model" or "auto"; the default
  // is processing::kDefaultBeyondMethod.
  std::string beyond = "auto";
  int beyond_subdivide = 2;  // the filled LUT's θin step is the measured one divided by this
  std::string formats = kAllLutFormats;
  std::string exr_type = "float";  // EXR pixel type: "float" or "half"
  // EXR compression: "none" or "zip". None by default: ZIP shrinks a float composite of
  // measured (noisy) data by only ~20 % and costs more than everything else of a conversion
  // (docs/benchmarks.md).
  std::string exr_compression = "none";
  // Texel format of the KTX2 and DDS: "none" (RGB9E5) or "bc6h" (exporter/lut_compression.h),
  // or "compact" (a .brdfc in their place, exporter/compact_lut.h).
  std::string compress = "none";
  // --max-error E (a fraction; 0: not given): the smallest of compact, BC6H and RGB9E5 meeting
  // it on the measured range, per input (exporter::LutExportOptions::max_error).
  double max_error = 0;
  int jobs = DefaultJobs();
  bool quiet = false;  // no progress bar
  bool force = false;  // overwrite existing outputs (brdf::CheckWritableOutputs)
  // Engine hand-off folders OUT/<engine>/: "unity,unreal,godot,web" (any subset) or "all";
  // empty: none (brdf/engines/engine_export.h).
  std::string engines;
  // Folder of `brdf fit` results (NAME.MODEL.json) for the engine manifests' fallback material.
  std::string engine_fits;
};
int RunConvert(const ConvertOptions& options);

struct AtlasOptions {
  std::vector<std::string> inputs;  // files and folders
  std::string out;                  // prefix: writes PREFIX.ktx2, .dds, .exr, .json
  std::string extrapolate;
  std::string exr_type = "float";
  std::string exr_compression = "none";  // as convert's: one default for every EXR written
  std::string compress = "none";         // as convert's
  // --max-error E (a fraction; 0: not given): BC6H for the whole atlas when every material's
  // cell meets E with it, else RGB9E5 (exporter::ChooseAtlasCompression); overrides --compress.
  double max_error = 0;
  int jobs = DefaultJobs();
  bool quiet = false;
  bool force = false;   // overwrite existing PREFIX.* files
  std::string engines;  // as ConvertOptions::engines; folders beside the prefix
};
int RunAtlas(const AtlasOptions& options);

struct MaterialsOptions {
  bool json = false;
};
int RunMaterials(const MaterialsOptions& options);

// `brdf import`: a third-party measurement file (Zemax or LightTools BSDF, CSV point cloud,
// goniometer table; RGL and MERL once their virtual capture is wired) as a .bpc capture.
struct ImportOptions {
  std::string file;
  std::string out;              // .bpc path, written atomically
  std::string format = "auto";  // auto, rgl, zemax, lighttools, merl, csv, gonio
  std::string sample;           // sample name for the metadata; empty: the reader's (file name)
  bool allow_btdf = false;      // accept transmission tables, mirrored (brdf/core/zemax.h)
  bool force = false;           // overwrite an existing --out
};
int RunImport(const ImportOptions& options);

// `brdf export-csv`: a .bpc capture as a CSV point cloud (brdf/core/csv.h).
struct ExportCsvOptions {
  std::string file;  // .bpc
  std::string out;   // .csv path, written atomically
  bool force = false;
};
int RunExportCsv(const ExportCsvOptions& options);

struct CaptureOptions {
  // "sim", "usb[:VID:PID[:SERIAL]]" or "hid[:VID:PID[:SERIAL]]" (brdf/device/usb_models.h).
  std::string device = "sim";
  // How --device sim is connected: "loopback" (in-process), "usb" or "hid" (the simulated
  // firmware behind real libusb / hidapi through umockdev; run under umockdev-wrapper; only in
  // a build with the emulation, BRDF_BUILD_DEVICE_EMULATION).
  std::string transport = "loopback";
  double sim_pace_ms = 0;  // testing: real time per θout row of the simulated firmware
  std::string material;    // library name or file
  std::string sample;      // sample name recorded in the metadata
  std::string out;         // .bpc path
  // The planned θin (every instrument) and the detector steps (--device sim only); default:
  // the reference geometry (brdf/core/virtual_capture.h).
  CaptureGeometry geometry = ReferenceGeometry();
  double noise = 1.0;  // 0 = noise-free and unsaturated; 1 = the reference instrument's noise
  std::uint64_t seed = 1;
  std::string operator_notes;
  bool resume = false;
  bool force = false;  // overwrite an existing file instead of refusing
  // On --resume: measure new dark and white references instead of reusing the file's.
  bool calibrate = false;
  bool quiet = false;
  std::string exposure = "auto";  // "auto" (per θout row), "auto-slice", or fixed milliseconds
  // Faults the simulated instrument injects, for testing the recovery path: NAME:N items,
  // comma separated, every one applied (brdf/device/simulator.h ParseFaultPlan).
  std::string sim_fault;
};
int RunCapture(const CaptureOptions& options);

// `brdf repair DAMAGED.bpc --out FIXED.bpc`: every intact slice of a damaged or unfinished
// capture written to a new, unfinished capture that `brdf capture --resume` completes
// (brdf::sources::RepairCapture).
struct RepairOptions {
  std::string file;    // the damaged .bpc
  std::string out;     // the new .bpc, written atomically
  bool force = false;  // overwrite an existing --out
};
int RunRepair(const RepairOptions& options);
// `brdf fit`: analytic materials fitted to captures, material files or measured BRDFs
// (brdf/fit/fit.h). One input and one model: --out is the material file to write;
// otherwise --out is a folder receiving <input>.<model>.json for every input and model.
struct FitCommandOptions {
  std::vector<std::string> inputs;  // files and folders
  std::string model = "ggx";        // a model name or "all"
  std::string out;
  std::string loss = "ngan";  // ngan, log, cbrt
  bool robust = false;
  double max_theta_out_deg = 0;  // 0: everything measured
  int starts = 2;
  int jobs = 1;
  bool force = false;  // overwrite existing outputs
  bool quiet = false;  // no progress on stderr
};
int RunFit(const FitCommandOptions& options);
// `brdf devices`: instruments found over USB and HID.
struct DevicesOptions {
  bool json = false;
};
int RunDevices(const DevicesOptions& options);
// `brdf preview`: an environment-lit render of any source (brdf/preview/preview.h), to a
// linear EXR or a tone-mapped PNG; with `compare`, both renders and their signed difference.
struct PreviewCommandOptions {
  std::string file;
  std::string compare;         // second source; empty: none
  std::string ibl = "true";    // true: the integral; engine: the split sum of the IBL pack
  std::string env = "studio";  // studio, sky, furnace, axes, or an .exr/.hdr file
  bool env_given = false;      // --env on the command line (with --light: map lighting too)
  double env_rotation_deg = 0;
  std::string mesh = "sphere";  // sphere, plane, or a .ply/.obj file
  int size = 512;               // pixels a side
  int spp = 64;                 // passes per pixel (ignored with rms > 0)
  double rms = 0;               // target relative RMS error, e.g. 0.01; 0: use spp
  std::string light;            // "THETA,PHI" in degrees (world frame); empty: none
  std::string view;             // camera position THETA,PHI; empty: preview::DefaultCamera
  double fov_deg = 0;           // > 0: perspective camera with this vertical field of view
  double exposure_ev = 0;
  std::string tone_map = "clamp";  // clamp or reinhard (PNG only)
  std::string estimator = "auto";  // auto, hierarchical, mis, env, brdf, quadrature
  bool spp_given = false;          // --spp on the command line (auto then means mis)
  int subdivisions = 2;            // quadrature: each map pixel split n × n
  int sample_pixels = 0;           // > 0: render only this many object pixels (references)
  std::string extrapolate;         // captures: "P,L"
  std::string out;                 // .exr or .png
  bool force = false;              // overwrite an existing --out
  int jobs = DefaultJobs();
  std::uint64_t seed = 1;
  bool no_background = false;  // black instead of the map where the object is not
  bool quiet = false;
};
int RunPreview(const PreviewCommandOptions& options);

}  // namespace brdf::cli
