// Batch plumbing of `brdf convert` and `brdf atlas`: turning command-line arguments (files and
// folders) into a list of inputs, and running one job per input on a fixed number of worker
// threads with failures collected instead of stopping the batch.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "brdf/exporter/exr.h"
#include "brdf/sources/detect.h"
#include "commands.h"

namespace brdf::cli {

using sources::FileKind;

struct BatchInput {
  std::string path;  // as given, or folder/name for a file found in a folder
  std::string name;  // output name (the file stem)
  FileKind kind = FileKind::kUnknown;
};

struct BatchFailure {
  std::string path;
  std::string reason;  // the error message without the leading "<path>: "
};

struct DiscoveredInputs {
  std::vector<BatchInput> inputs;
  std::vector<BatchFailure> failures;  // arguments that cannot be inputs (missing, wrong type)
  std::vector<std::string> skipped;    // files in folders that are not inputs, with the reason
};

// Which kinds an argument may be.
struct InputKinds {
  bool exported_luts = false;  // also accept .ktx2, .dds and sidecars (brdf atlas)
};

// Expands the arguments in order; an argument that names nothing on disk may name a library
// material (sources::ResolveSource; a file of that name wins). A file argument must be a capture
// (.bpc) or a material file (or, with `kinds.exported_luts`, an exported LUT); anything else, or a
// missing path, becomes a failure naming it. A folder contributes its captures and material files
// (not recursively; sorted by file name); sidecars, atlas manifests, "<name>.extrapolate.json"
// files and other files in it are skipped (listed in `skipped`), and a .json that does not parse
// there is a failure. A path given twice is taken once.
DiscoveredInputs DiscoverInputs(const std::vector<std::string>& arguments,
                                const InputKinds& kinds = {});

// The outcome of one job.
struct JobResult {
  bool ok = true;
  std::string error;                  // full message when !ok
  std::vector<std::string> warnings;  // full sentences, printed by the caller
};

// Runs job(i, result) for every i in [0, count) on min(jobs, count) worker threads; each
// worker takes the next index when it finishes one, so at most `jobs` inputs are in memory at
// once. An exception thrown by a job (brdf::Error, std::bad_alloc, anything) marks that job
// failed with its message and the batch goes on. `done(i, result)` is called on the worker
// thread right after job i (for progress reporting; it must be thread-safe). Returns the
// results in index order. Throws InvalidArgument for jobs < 1.
std::vector<JobResult> RunJobs(std::size_t count, int jobs,
                               const std::function<void(std::size_t, JobResult&)>& job,
                               const std::function<void(std::size_t, const JobResult&)>& done);

// Guards a set of output paths during a write that may fail halfway: remembers which file
// (device, inode) each path held before, so RemoveNew() deletes exactly the files renamed into
// place since, leaving no partial set of outputs (older files that were not replaced stay).
class OutputGuard {
 public:
  explicit OutputGuard(std::vector<std::string> paths);
  void RemoveNew() const;

 private:
  struct Identity {
    bool exists = false;
    unsigned long long device = 0, inode = 0;
    friend bool operator==(const Identity&, const Identity&) = default;
  };
  static Identity Of(const std::string& path);
  std::vector<std::string> paths_;
  std::vector<Identity> before_;
};

// --exr-type ("float" or "half") and --exr-compression ("zip" or "none") as the exporter's EXR
// options; throws InvalidArgument naming a bad value.
exporter::ExrOptions ParseExrOptions(const std::string& type, const std::string& compression);

// Identity of a path for de-duplication and collision checks: the canonical path when it
// exists, else the lexically normal one.
std::string Identity(const std::filesystem::path& p);

// "<path>: <reason>" → reason, for the summary (messages of this toolchain start with the path).
std::string ReasonWithoutPath(const std::string& path, const std::string& message);

// "converted 214 of 216; failed: a.bpc (reason), b.bpc (reason)", or "converted 3 of 3".
std::string BatchSummary(const std::string& verb, std::size_t succeeded, std::size_t total,
                         const std::vector<BatchFailure>& failures);

}  // namespace brdf::cli
