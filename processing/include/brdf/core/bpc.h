// The native capture file, .bpc (brdf point cloud). The byte layout is documented in
// docs/formats/bpc.md; this header is the API.
//
// A capture appends one chunk per θin slice and flushes it to disk as soon as the slice is
// complete, so every prefix of the file that ends on a chunk boundary is a valid file. A file
// cut anywhere (power loss, unplugged instrument, killed process) still opens: the complete
// slices read back bit-exact and the damaged tail is reported with its byte offset.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "brdf/core/measurement.h"

namespace brdf {

// Something wrong found while reading a .bpc that did not prevent reading what precedes it.
struct BpcProblem {
  std::uint64_t offset = 0;  // byte offset of the damaged chunk or the cut
  int slice_index = -1;      // index of the slice the damage belongs to, -1 if unknown
  std::string message;       // full sentence naming file, offset, expected and found
};

struct BpcReadResult {
  Measurement measurement;           // every intact slice, in file order
  std::vector<BpcProblem> problems;  // empty for an intact, finished file
  bool finished = false;             // the end chunk (capture end metadata) is present
  std::uint64_t valid_bytes = 0;     // length of the longest intact prefix; a resume truncates here
};

// Reads a .bpc, tolerating a damaged tail. Throws FormatError if not even the header is
// readable (wrong magic, unsupported version, corrupt header), IoError if the file cannot be
// opened.
BpcReadResult ReadBpc(const std::string& path);

// Reads a .bpc and throws FormatError on any problem (the first one's message).
Measurement LoadBpc(const std::string& path);

// Writes a complete measurement to `path` via a temporary file in the same folder renamed
// into place only when complete (conversions, rewrites).
void WriteBpc(const std::string& path, const Measurement& measurement);

// Appends a capture slice by slice. Each AppendSlice writes one chunk and flushes it to disk
// (fflush + fsync) before returning, so a crash after it returns never loses that slice.
class BpcAppender {
 public:
  // Creates `path` (truncating any existing file) and writes the header chunk.
  static BpcAppender Create(const std::string& path, const Metadata& metadata);
  // Opens an interrupted capture to continue it: truncates the file to its valid prefix and
  // returns the appender positioned there. `existing` receives what the file already holds.
  static BpcAppender Resume(const std::string& path, BpcReadResult* existing);

  BpcAppender(BpcAppender&& other) noexcept;
  BpcAppender& operator=(BpcAppender&& other) noexcept;
  BpcAppender(const BpcAppender&) = delete;
  BpcAppender& operator=(const BpcAppender&) = delete;
  ~BpcAppender();

  void AppendSlice(const Slice& slice);
  // Writes the end chunk (capture end time and any final metadata) and closes the file.
  void Finish(const Metadata& final_metadata);

  const std::string& path() const { return path_; }

 private:
  BpcAppender(std::string path, std::FILE* file);
  std::string path_;
  std::FILE* file_ = nullptr;
};

}  // namespace brdf
