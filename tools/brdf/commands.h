// The `brdf` subcommands. main.cpp parses the command line with CLI11 into these option
// structs; each Run* function lives in its own translation unit, writes results to stdout,
// progress to stderr, and returns the process exit code. Errors thrown as brdf::Error are
// turned into one line on stderr by main.cpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

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
  std::string formats = kAllLutFormats;
  std::string exr_type = "float";  // EXR pixel type: "float" or "half"
  // EXR compression: "none" or "zip". None by default: ZIP shrinks a float composite of
  // measured (noisy) data by only ~20 % and costs more than everything else of a conversion
  // (docs/benchmarks.md).
  std::string exr_compression = "none";
  int jobs = DefaultJobs();
  bool quiet = false;  // no progress bar
};
int RunConvert(const ConvertOptions& options);

struct AtlasOptions {
  std::vector<std::string> inputs;  // files and folders
  std::string out;                  // prefix: writes PREFIX.ktx2, .dds, .exr, .json
  std::string extrapolate;
  std::string exr_type = "float";
  std::string exr_compression = "zip";
  int jobs = DefaultJobs();
  bool quiet = false;
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
  std::string device = "sim";
  std::string material;  // library name or file
  std::string sample;    // sample name recorded in the metadata
  std::string out;       // .bpc path
  std::vector<double> theta_in_deg = {0, 20, 40, 60};
  double theta_out_max_deg = 75;
  double theta_out_step_deg = 1;
  double phi_out_step_deg = 1;
  double noise = 1.0;  // 0 = noise-free and unsaturated; 1 = the reference instrument's noise
  std::uint64_t seed = 1;
  std::string operator_notes;
  bool resume = false;
  bool force = false;  // overwrite an existing file instead of refusing
  bool quiet = false;
  std::string exposure = "auto";  // "auto" (per θout row), "auto-slice", or fixed milliseconds
  // Faults the simulated instrument injects, for testing the recovery path:
  // "disconnect:N", "stall:N", "corrupt:N" (N counts the instrument's frames), comma separated.
  std::string sim_fault;
};
int RunCapture(const CaptureOptions& options);

// `brdf preview`: an environment-lit render of any source (brdf/processing/preview.h), to a
// linear EXR or a tone-mapped PNG; with `compare`, both renders and their signed difference.
struct PreviewCommandOptions {
  std::string file;
  std::string compare;           // second source; empty: none
  std::string env = "studio";    // studio, sky, furnace, axes, or an .exr/.hdr file
  bool env_given = false;        // --env on the command line (with --light: map lighting too)
  double env_rotation_deg = 0;
  std::string mesh = "sphere";   // sphere, plane, or a .ply/.obj file
  int size = 512;                // pixels a side
  int spp = 64;                  // passes per pixel (ignored with rms > 0)
  double rms = 0;                // target relative RMS error, e.g. 0.01; 0: use spp
  std::string light;             // "THETA,PHI" in degrees (world frame); empty: none
  std::string view = "90,0";     // camera position THETA,PHI seen from the object
  double fov_deg = 0;            // > 0: perspective camera with this vertical field of view
  double exposure_ev = 0;
  std::string tone_map = "clamp";     // clamp or reinhard (PNG only)
  std::string estimator = "mis";      // mis, env, brdf, quadrature
  std::string extrapolate;            // captures: "P,L"
  std::string out;                    // .exr or .png
  int jobs = DefaultJobs();
  std::uint64_t seed = 1;
  bool no_background = false;  // black instead of the map where the object is not
  bool quiet = false;
};
int RunPreview(const PreviewCommandOptions& options);

}  // namespace brdf::cli
