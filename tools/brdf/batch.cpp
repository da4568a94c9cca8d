#include "batch.h"

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <filesystem>
#include <new>
#include <set>
#include <thread>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/parallel.h"
#include "brdf/sources/material_library.h"
#include "cli_support.h"

namespace brdf::cli {

namespace fs = std::filesystem;

namespace {

bool IsInputKind(FileKind kind, const InputKinds& kinds) {
  if (kind == FileKind::kCapture || kind == FileKind::kMaterial) return true;
  return kinds.exported_luts && (sources::IsTexture(kind) || kind == FileKind::kSidecar);
}

std::string Accepted(const InputKinds& kinds) {
  return kinds.exported_luts
             ? "a capture (.bpc), a material .json or an exported LUT (.ktx2, .dds, sidecar .json)"
             : "a capture (.bpc) or a material .json";
}

}  // namespace

std::string Identity(const fs::path& p) {
  std::error_code ec;
  const fs::path c = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal().string() : c.string();
}

DiscoveredInputs DiscoverInputs(const std::vector<std::string>& arguments,
                                const InputKinds& kinds) {
  DiscoveredInputs out;
  std::set<std::string> seen;
  const auto add = [&](const std::string& path, FileKind kind) {
    if (!seen.insert(Identity(path)).second) return;
    out.inputs.push_back(BatchInput{path, sources::OutputNameOf(path), kind});
  };
  for (const std::string& given : arguments) {
    // A library material name stands for its file (brdf/sources/material_library.h).
    std::string arg;
    try {
      arg = sources::ResolveSource(given);
    } catch (const Error& e) {
      out.failures.push_back({given, ReasonWithoutPath(given, e.what())});
      continue;
    }
    std::error_code ec;
    const fs::file_status st = fs::status(arg, ec);
    if (fs::is_directory(st)) {
      std::vector<fs::path> files;
      for (fs::directory_iterator it(arg, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec)) files.push_back(it->path());
      if (ec) {
        out.failures.push_back({arg, "cannot list the folder: " + ec.message()});
        continue;
      }
      std::sort(files.begin(), files.end());
      for (const fs::path& f : files) {
        const std::string path = f.string();
        FileKind kind = FileKind::kUnknown;
        try {
          kind = sources::DetectFileKind(path);
        } catch (const Error& e) {
          // A JSON file that does not parse might be a broken material: a failure, not a skip.
          out.failures.push_back({path, ReasonWithoutPath(path, e.what())});
          continue;
        }
        if (IsInputKind(kind, kinds))
          add(path, kind);
        else
          out.skipped.push_back(path + " (" + sources::FileKindName(kind) + ")");
      }
    } else if (fs::is_regular_file(st)) {
      try {
        const FileKind kind = sources::DetectFileKind(arg);
        if (IsInputKind(kind, kinds))
          add(arg, kind);
        else
          out.failures.push_back({arg, "not an input: expected " + Accepted(kinds) + ", got a " +
                                           sources::FileKindName(kind)});
      } catch (const Error& e) {
        out.failures.push_back({arg, ReasonWithoutPath(arg, e.what())});
      }
    } else if (fs::exists(st)) {
      // A FIFO, device or socket: say what it is (brdf::CheckRegularFile), never open it.
      try {
        CheckRegularFile(arg);
      } catch (const Error& e) {
        out.failures.push_back({arg, ReasonWithoutPath(arg, e.what())});
      }
    } else {
      out.failures.push_back({arg, ec && ec != std::errc::no_such_file_or_directory
                                       ? "cannot access: " + ec.message()
                                       : std::string("no such file or folder")});
    }
  }
  return out;
}

int DefaultJobs() { return ResolveJobs(0); }

std::vector<JobResult> RunJobs(std::size_t count, int jobs,
                               const std::function<void(std::size_t, JobResult&)>& job,
                               const std::function<void(std::size_t, const JobResult&)>& done) {
  if (jobs < 1) throw InvalidArgument("--jobs: expected at least 1, got " + std::to_string(jobs));
  std::vector<JobResult> results(count);
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < count;) {
      JobResult& r = results[i];
      try {
        job(i, r);
      } catch (const std::bad_alloc&) {
        r.ok = false;
        r.error = "out of memory";
      } catch (const std::exception& e) {
        r.ok = false;
        r.error = ErrorLine(e);
      } catch (...) {
        r.ok = false;
        r.error = "unknown error";
      }
      if (done) done(i, r);
    }
  };
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(jobs), count);
  if (threads <= 1) {
    worker();
    return results;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads);
  for (std::size_t t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  return results;
}

OutputGuard::OutputGuard(std::vector<std::string> paths) : paths_(std::move(paths)) {
  for (const std::string& p : paths_) before_.push_back(Of(p));
}

OutputGuard::Identity OutputGuard::Of(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  return {true, static_cast<unsigned long long>(st.st_dev),
          static_cast<unsigned long long>(st.st_ino)};
}

void OutputGuard::RemoveNew() const {
  for (std::size_t i = 0; i < paths_.size(); ++i) {
    const Identity now = Of(paths_[i]);
    if (now.exists && !(now == before_[i])) {
      std::error_code ec;
      fs::remove(paths_[i], ec);
    }
  }
}

exporter::ExrOptions ParseExrOptions(const std::string& type, const std::string& compression) {
  exporter::ExrOptions options;
  if (type == "float")
    options.type = exporter::ExrPixelType::kFloat;
  else if (type == "half")
    options.type = exporter::ExrPixelType::kHalf;
  else
    throw InvalidArgument("--exr-type: expected 'float' or 'half', got '" + type + "'");
  if (compression == "zip")
    options.compression = exporter::ExrCompression::kZip;
  else if (compression == "none")
    options.compression = exporter::ExrCompression::kNone;
  else
    throw InvalidArgument("--exr-compression: expected 'zip' or 'none', got '" + compression + "'");
  return options;
}

std::string ReasonWithoutPath(const std::string& path, const std::string& message) {
  if (message.size() > path.size() + 2 && message.compare(0, path.size(), path) == 0 &&
      message.compare(path.size(), 2, ": ") == 0)
    return message.substr(path.size() + 2);
  return message;
}

std::string BatchSummary(const std::string& verb, std::size_t succeeded, std::size_t total,
                         const std::vector<BatchFailure>& failures) {
  std::string s = verb + " " + std::to_string(succeeded) + " of " + std::to_string(total);
  if (!failures.empty()) {
    s += "; failed: ";
    for (std::size_t i = 0; i < failures.size(); ++i)
      s += (i ? ", " : "") + failures[i].path + " (" + failures[i].reason + ")";
  }
  return s;
}

}  // namespace brdf::cli
