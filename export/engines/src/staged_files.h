// Private: the per-material files of one hand-off, made durable together.
//
// Each file is written under a temporary sibling name (brdf::AtomicOutputPath, so a killed run's
// leftovers are recognised and removed by the next run) and its writeback is started at once;
// Commit() then fsyncs every temporary, renames each over its final name and fsyncs every folder
// that received one, once. The rule of brdf/core/file_util.h holds for every file: a final name
// appears only by a rename, after the file's data was synced, so no partial file is ever visible
// under a final name. What grouping saves: the folder fsyncs (one per folder instead of one per
// file) and the waits (the writebacks of all files overlap instead of running one after the other).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "brdf/core/file_util.h"

namespace brdf::engines::detail {

class StagedFiles {
 public:
  // Appends bytes to one staged file through a 64 KiB buffer (no copy of the whole file).
  class Writer {
   public:
    void Append(const void* data, std::size_t size);
    void Append(std::string_view bytes) { Append(bytes.data(), bytes.size()); }
    // A buffer of `size` (at most kChunkBytes) bytes to fill in place; Keep(n) keeps its first n.
    char* Reserve(std::size_t size);
    void Keep(std::size_t size) { used_ += size; }
    static constexpr std::size_t kChunkBytes = 64 * 1024;

   private:
    friend class StagedFiles;
    Writer(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
    void Flush();
    int fd_;
    std::string path_;  // the final path, for messages
    std::unique_ptr<char[]> buffer_ = std::make_unique<char[]>(kChunkBytes);
    std::size_t used_ = 0;
  };

  StagedFiles() = default;
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  ~StagedFiles();  // closes and removes temporaries that were not committed

  // Writes `path` (under its temporary name) with what `fill(Writer&)` appends. Throws IoError.
  template <class Fill>
  void WriteWith(const std::string& path, Fill&& fill) {
    Writer w = Open(path);
    fill(w);
    Close(w);
  }
  void Write(const std::string& path, std::string_view bytes) {
    WriteWith(path, [&](Writer& w) { w.Append(bytes); });
  }
  // Stages `path` as a hard link to `source` (an output that is already durable: no bytes to
  // write or sync). Returns false when linking is impossible (no source, another file system).
  bool Link(const std::string& source, const std::string& path);

  // fsync, rename into place, one fsync per folder. Throws IoError naming the file.
  void Commit();

  // The temporary name of the file staged last (to link further names to it before Commit).
  const std::string& temp_path_of_last() const { return entries_.back().temp->temp_path(); }

  // The final paths, in the order staged.
  std::vector<std::string> paths() const;

 private:
  struct Entry {
    std::unique_ptr<AtomicOutputPath> temp;
    int fd = -1;  // open until Commit (for its fsync); -1 for a link
  };
  Writer Open(const std::string& path);
  void Close(Writer& w);
  std::vector<Entry> entries_;
};

}  // namespace brdf::engines::detail
