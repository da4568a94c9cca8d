#include "staged_files.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "brdf/core/error.h"

namespace brdf::engines::detail {

namespace {

std::string ErrnoText() { return std::strerror(errno); }

std::string FolderOf(const std::string& path) {
  const std::filesystem::path p(path);
  return p.has_parent_path() ? p.parent_path().string() : std::string(".");
}

}  // namespace

void StagedFiles::Writer::Flush() {
  std::size_t done = 0;
  while (done < used_) {
    const ssize_t n = ::write(fd_, buffer_.get() + done, used_ - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(path_ + ": write failed: " + ErrnoText());
    done += static_cast<std::size_t>(n);
  }
  used_ = 0;
}

char* StagedFiles::Writer::Reserve(std::size_t size) {
  if (size > kChunkBytes) throw InvalidArgument("StagedFiles: reserve of more than one chunk");
  if (kChunkBytes - used_ < size) Flush();
  return buffer_.get() + used_;
}

void StagedFiles::Writer::Append(const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const std::size_t n = std::min(size, kChunkBytes);
    std::memcpy(Reserve(n), p, n);
    Keep(n);
    p += n;
    size -= n;
  }
}

StagedFiles::~StagedFiles() {
  for (Entry& e : entries_)
    if (e.fd >= 0) ::close(e.fd);
  // Each AtomicOutputPath removes its temporary name (a no-op once renamed into place).
}

StagedFiles::Writer StagedFiles::Open(const std::string& path) {
  auto temp = std::make_unique<AtomicOutputPath>(path);
  const int fd = ::open(temp->temp_path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw IoError(path + ": cannot create file: " + ErrnoText());
  entries_.push_back({std::move(temp), fd});
  return Writer(fd, path);
}

void StagedFiles::Close(Writer& w) {
  w.Flush();
  // Start writing the data to disk now, so the fsync in Commit waits for less.
  ::sync_file_range(w.fd_, 0, 0, SYNC_FILE_RANGE_WRITE);
}

bool StagedFiles::Link(const std::string& source, const std::string& path) {
  if (source.empty()) return false;
  auto temp = std::make_unique<AtomicOutputPath>(path);
  if (::link(source.c_str(), temp->temp_path().c_str()) != 0) return false;
  entries_.push_back({std::move(temp), -1});
  return true;
}

void StagedFiles::Commit() {
  for (Entry& e : entries_) {
    if (e.fd < 0) continue;
    if (::fsync(e.fd) != 0)
      throw IoError(e.temp->final_path() + ": cannot write to disk: " + ErrnoText());
    ::close(e.fd);
    e.fd = -1;
  }
  std::vector<std::string> folders;
  for (Entry& e : entries_) {
    if (std::rename(e.temp->temp_path().c_str(), e.temp->final_path().c_str()) != 0)
      throw IoError(e.temp->final_path() + ": cannot rename temporary file " + e.temp->temp_path() +
                    " into place: " + ErrnoText());
    const std::string folder = FolderOf(e.temp->final_path());
    if (std::find(folders.begin(), folders.end(), folder) == folders.end())
      folders.push_back(folder);
  }
  for (const std::string& folder : folders) {
    const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) continue;
    ::fsync(fd);
    ::close(fd);
  }
}

std::vector<std::string> StagedFiles::paths() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.temp->final_path());
  return out;
}

}  // namespace brdf::engines::detail
