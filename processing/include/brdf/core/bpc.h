// The native capture file, .bpc (brdf point cloud). The byte layout is documented in
// docs/formats/bpc.md; this header is the API.
//
// A capture appends one chunk per θin slice and flushes it to disk as soon as the slice is
// complete, so every prefix of the file that ends on a chunk boundary is a valid file. A file
// cut anywhere (power loss, unplugged instrument, killed process) still opens: the complete
// slices read back bit-exact and the damaged tail is reported with its byte offset. Every chunk
// carries two CRC-32s (one over its fixed header, one over its payload), so a flipped byte is
// found and attributed to the slice it belongs to; slices after a damaged one are still read.
//
// Values are stored losslessly: every float of Sample is written as its float32 bit pattern
// (NaN payloads, -0.0 and denormals included), θin/φin of a Slice as float64.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "brdf/core/measurement.h"

namespace brdf {

// The 8 bytes every .bpc file starts with (docs/formats/bpc.md): 0x89 "BPC" CR LF 0x1A LF, so a
// transfer that mangles line ends or stops at the DOS end-of-file byte shows in the first bytes.
inline constexpr std::array<std::uint8_t, 8> kBpcMagic = {0x89, 'B',  'P',  'C',
                                                          '\r', '\n', 0x1a, '\n'};
// The format version this code writes and the newest it reads (docs/formats/bpc.md, versioning).
inline constexpr std::uint16_t kBpcVersionMajor = 1;
inline constexpr std::uint16_t kBpcVersionMinor = 0;
// Files larger than this are refused before anything is allocated (a full reference capture
// is about 5 MB).
inline constexpr std::uint64_t kBpcMaxFileBytes = 1ull << 32;

enum class BpcProblemKind {
  kTruncated,     // the file ends inside a chunk: an interrupted write (the usual crash case)
  kCorrupt,       // a chunk's bytes do not match its CRC-32 or its fields are inconsistent
  kTrailingData,  // bytes after the end chunk
};

// Something wrong found while reading a .bpc that did not prevent reading the rest.
struct BpcProblem {
  BpcProblemKind kind = BpcProblemKind::kCorrupt;
  std::uint64_t offset = 0;   // byte offset where the damaged region starts (a chunk start)
  std::uint64_t size = 0;     // bytes in the damaged region; offset + size is the cut for a
                              // truncated tail (the file size)
  int slice_index = -1;       // index of the slice the damage belongs to, -1 if not a slice or
                              // not known (a cut inside a chunk header)
  std::string expected, got;  // what the format requires there and what the file holds
  std::string message;        // full sentence naming file, offset, slice, expected and found
};

struct BpcReadResult {
  Measurement measurement;           // every intact slice, in file order; the end chunk's
                                     // metadata if finished, else the header's
  Metadata header_metadata;          // the header chunk's metadata (what the capture started
                                     // with; a resume compares its settings with these)
  std::vector<BpcProblem> problems;  // empty for an intact file (finished or not)
  bool finished = false;             // the end chunk (capture end metadata) is present and intact
  std::uint64_t valid_bytes = 0;     // length of the longest intact prefix (ends on a chunk
                                     // boundary); a resume truncates here
  std::vector<int> slice_indices;    // slice index of each returned slice (gaps mark damaged ones)
  std::vector<std::uint64_t> slice_offsets;  // byte offset of each returned slice's chunk
  // What the end chunk says the file holds (-1 when not finished or not recorded), and where
  // the end chunk starts. Not checked by the reader: brdf::sources compares them with the
  // slices (a writer that lied).
  std::int64_t end_slice_count = -1, end_sample_count = -1;
  std::uint64_t end_offset = 0;
  bool intact_data_after_damage = false;  // an intact chunk follows a damaged one, so
                                          // truncating to valid_bytes would discard it
};

// Reads a .bpc, tolerating damage after the header. An intact file is streamed (the file is
// never held in memory whole); at the first sign of damage the whole file is read (at most
// kBpcMaxFileBytes) and parsed by the tolerant reader of docs/formats/bpc.md, "Reading". Throws
// FormatError if not even the header is readable (wrong magic, unsupported version, corrupt header
// chunk), IoError if the file cannot be opened.
BpcReadResult ReadBpc(const std::string& path);

// ReadBpc over bytes already in memory (tests, fuzzing, streams). `file` names the source in
// messages.
BpcReadResult ParseBpc(const std::uint8_t* data, std::size_t size, const std::string& file);

// Reads a .bpc and throws FormatError on any problem (the first one's message).
Measurement LoadBpc(const std::string& path);

// Writes a complete measurement (header, every slice, end chunk with measurement.metadata) to
// `path` via a temporary file in the same folder renamed into place only when complete
// (conversions, rewrites). Throws IoError.
void WriteBpc(const std::string& path, const Measurement& measurement);

// Serialises a complete measurement into the bytes WriteBpc writes (for tests and tools that
// stream elsewhere).
std::string EncodeBpc(const Measurement& measurement);

// Appends a capture slice by slice. Each call writes whole chunks and flushes them to disk
// (fflush + fsync) before returning, so a crash after it returns never loses that slice and a
// crash during it leaves a file whose damaged tail the reader reports.
class BpcAppender {
 public:
  // Creates `path` (truncating any existing file) and writes the header chunk with `metadata`
  // (capture_end is normally still empty). Throws IoError.
  static BpcAppender Create(const std::string& path, const Metadata& metadata);
  // Opens an interrupted capture to continue it: truncates the file to its valid prefix and
  // returns the appender positioned there. `existing` (may be null) receives what the file
  // already holds. Throws InvalidArgument if the capture is already finished, FormatError if
  // intact slices follow damage (truncating would lose them), IoError.
  static BpcAppender Resume(const std::string& path, BpcReadResult* existing);

  BpcAppender(BpcAppender&& other) noexcept;
  BpcAppender& operator=(BpcAppender&& other) noexcept;
  BpcAppender(const BpcAppender&) = delete;
  BpcAppender& operator=(const BpcAppender&) = delete;
  // Closes the file without an end chunk if Finish was not called: the file stays a valid,
  // unfinished capture.
  ~BpcAppender();

  // Writes one slice chunk (index = number of slices already in the file). Throws IoError,
  // or Error if the appender is finished. After a failed write (disk full) the file is cut back
  // to its last complete chunk, so it stays valid and the call may be retried.
  void AppendSlice(const Slice& slice);
  // Writes the end chunk (capture end time and any final metadata) and closes the file.
  void Finish(const Metadata& final_metadata);

  const std::string& path() const { return path_; }
  // Number of slices in the file so far (including those present before a Resume).
  int slice_count() const { return slice_count_; }
  bool is_open() const { return file_ != nullptr; }

 private:
  BpcAppender(std::string path, std::FILE* file, int slice_count);
  void WriteDurably(const std::string& bytes);
  void Close();
  std::string path_;
  std::FILE* file_ = nullptr;
  int slice_count_ = 0;
  std::uint64_t sample_count_ = 0;
  std::uint64_t size_ = 0;  // bytes durably written: the file ends on this chunk boundary
};

}  // namespace brdf
