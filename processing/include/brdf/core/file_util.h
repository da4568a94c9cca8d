// File helpers shared by every reader and writer.
//
// Files written whole (conversions, exports, rewrites) go to a temporary name in the same
// folder and are renamed over the final name only when complete, so a crash or a full disk
// never leaves a half-written file under the final name. Reads are bounded: a file larger
// than the caller's limit is refused before anything is allocated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/error.h"

namespace brdf {

// The one overwrite rule of every command that writes a file (capture, import, export-csv,
// convert, atlas, fit, preview): an output that already exists is replaced only when the user
// said so (the tools' --force); an existing path that is not a regular file (a folder, a FIFO,
// a device) is never replaced. Call it for every output before any work is done.
//
// Thrown when an output exists and overwriting was not allowed, with Remedy kForceOverwrite (its
// file: the one existing output, empty when several exist) that each tool renders in its words.
class OutputExistsError : public IoError {
 public:
  explicit OutputExistsError(std::vector<std::string> paths);
  // Every existing output (at least one), in the order checked.
  const std::vector<std::string>& paths() const { return paths_; }

 private:
  std::vector<std::string> paths_;
};

// The limits of an output's name on Linux: NAME_MAX bytes per file name, PATH_MAX bytes for
// the whole path.
inline constexpr std::size_t kMaxNameBytes = 255, kMaxPathBytes = 4095;

// Throws IoError naming `path` when it cannot be created: a file or folder name longer than
// kMaxNameBytes or a path longer than kMaxPathBytes, a folder that does not exist, is not a
// folder, or cannot be written into (errno's reason). `folders_created`: the command creates
// the missing folders itself (convert's and atlas's engine folders), so the nearest existing
// one is checked instead. Checks no file, only its place.
void CheckOutputName(const std::string& path, bool folders_created = false);

// Checks `paths` (all the outputs of one command): CheckOutputName for each, then throws
// OutputExistsError listing those that exist when !overwrite, and IoError "<path>: exists and
// is a folder (or FIFO, device, ...), not a file" for an existing non-regular path whatever
// `overwrite` says. Symbolic links are
// followed (a link to a regular file counts as that file). Then removes the temporary files
// that killed runs left in the outputs' folders (RemoveStaleTemporaries) and returns their
// paths, for the caller to report.
std::vector<std::string> CheckWritableOutputs(const std::vector<std::string>& paths, bool overwrite,
                                              bool folders_created = false);
inline std::vector<std::string> CheckWritableOutput(const std::string& path, bool overwrite) {
  return CheckWritableOutputs({path}, overwrite);
}

// Removes from `dir` the temporary files of AtomicOutputPath whose writing process no longer
// runs (a run that was killed or lost power before renaming them into place), also those of
// older versions of the toolchain (".<name>.tmp-<pid>-<n>"). Files of live processes, including
// this one, are left alone. Returns the removed paths; errors are ignored (a file that cannot
// be removed is simply not listed).
std::vector<std::string> RemoveStaleTemporaries(const std::string& dir);

// A temporary sibling of `final_path`, "dir/.brdf-<pid>-<n>.tmp": short whatever the final
// name's length (a legal 255-byte file name must not fail for want of room), and naming the
// writing process so the next run into the folder can remove it if the writer was killed
// (RemoveStaleTemporaries). Removed by the destructor unless Commit() renamed it into place.
class AtomicOutputPath {
 public:
  explicit AtomicOutputPath(std::string final_path);
  AtomicOutputPath(const AtomicOutputPath&) = delete;
  AtomicOutputPath& operator=(const AtomicOutputPath&) = delete;
  ~AtomicOutputPath();

  const std::string& temp_path() const { return temp_path_; }
  const std::string& final_path() const { return final_path_; }
  // fsyncs the temporary file and renames it to the final path. Throws IoError.
  void Commit();

 private:
  std::string final_path_, temp_path_;
  bool committed_ = false;
};

// Writes `bytes` to `path` atomically (temporary sibling, fsync, rename). Throws IoError.
void WriteFileAtomically(const std::string& path, std::string_view bytes);

// Every read of a named file goes through OpenRegularFile: the path is opened without blocking
// (O_NONBLOCK, so a FIFO with no writer or a device cannot hang the caller) and refused with
// IoError "<path>: is a FIFO (named pipe), not a file" (or a folder, a device, a socket) unless
// it is a regular file. Returns a descriptor in blocking mode; `size_bytes` receives the size.
// The caller closes it.
int OpenRegularFile(const std::string& path, std::uint64_t* size_bytes);

// Checks, without opening (stat(2) never blocks), that `path` names a regular file: throws
// IoError "<path>: no such file" or "<path>: is a FIFO (named pipe), not a file" (a folder, a
// device, a socket). For front ends that classify a path before reading it.
void CheckRegularFile(const std::string& path);

// Reads a whole file; throws IoError if it cannot be read or is not a regular file, and
// FormatError if it is larger than `max_bytes` (checked before allocating).
std::vector<std::uint8_t> ReadFileBytes(const std::string& path, std::uint64_t max_bytes);
std::string ReadFileText(const std::string& path, std::uint64_t max_bytes);

// At most the first `max_bytes` of a file (fewer if it is shorter), for content detection.
std::string ReadFileHead(const std::string& path, std::size_t max_bytes);

// A regular file mapped read-only into memory. Pages are read from disk only when touched, so
// a parser that stops at the first bad chunk of a huge (or sparse) file costs memory for what
// it looked at, not for the file's size. Throws like ReadFileBytes (size cap included).
class MappedFile {
 public:
  MappedFile(const std::string& path, std::uint64_t max_bytes);
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();
  const std::uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

// Little-endian cursor over a byte buffer that knows the file name and its position, so every
// read past the end or unexpected value becomes a FormatError naming both.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size, std::string file,
             std::uint64_t base_offset = 0)
      : data_(data), size_(size), file_(std::move(file)), base_(base_offset) {}

  std::uint64_t offset() const { return base_ + pos_; }  // absolute file offset
  std::size_t remaining() const { return size_ - pos_; }
  const std::string& file() const { return file_; }
  void Seek(std::size_t pos);  // relative to the buffer start; throws past the end
  void Skip(std::size_t n);

  std::uint8_t U8(std::string_view what);
  std::uint16_t U16(std::string_view what);
  std::uint32_t U32(std::string_view what);
  std::uint64_t U64(std::string_view what);
  std::int32_t I32(std::string_view what);
  float F32(std::string_view what);
  double F64(std::string_view what);
  // Pointer to the next n bytes, advancing past them.
  const std::uint8_t* Bytes(std::size_t n, std::string_view what);
  std::string String(std::size_t n, std::string_view what);

  // Throws FormatError "<file>: byte <offset>: expected <expected>, got <got>".
  [[noreturn]] void Fail(std::string_view expected, std::string_view got) const;

 private:
  void Need(std::size_t n, std::string_view what) const;
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string file_;
  std::uint64_t base_;
};

// Little-endian appenders for writers.
void AppendU16(std::string& out, std::uint16_t v);
void AppendU32(std::string& out, std::uint32_t v);
void AppendU64(std::string& out, std::uint64_t v);
void AppendF32(std::string& out, float v);

// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib's crc32). `crc` continues a
// running checksum; start with 0.
std::uint32_t Crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace brdf
