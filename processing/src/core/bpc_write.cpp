// Writing `.bpc` files: a whole capture at once, and the appender that makes every slice
// durable as it arrives (brdf/core/bpc.h).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <utility>

#include "bpc_chunks.h"
#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"

namespace brdf {

using detail::EncodeChunk;
using detail::EncodePreambleAndHeader;
using detail::EncodeSliceChunk;
using detail::EndJson;
using detail::kNoSlice;
using detail::kTagEnd;
using detail::MetadataToJson;

namespace {

std::string ErrnoText() { return std::strerror(errno); }

int SyncFile(std::FILE* f) {
  if (std::fflush(f) != 0) return -1;
  return ::fsync(::fileno(f));
}

void SyncParentDir(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string dir = p.has_parent_path() ? p.parent_path().string() : std::string(".");
  const int fd = ::open(dir.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

std::string EncodeBpc(const Measurement& measurement) {
  std::string out = EncodePreambleAndHeader(measurement.metadata);
  std::uint64_t samples = 0;
  for (std::size_t i = 0; i < measurement.slices.size(); ++i) {
    out += EncodeSliceChunk(measurement.slices[i], static_cast<int>(i));
    samples += measurement.slices[i].samples.size();
  }
  out += EncodeChunk(
      kTagEnd, kNoSlice,
      EndJson(measurement.metadata, static_cast<int>(measurement.slices.size()), samples));
  return out;
}

void WriteBpc(const std::string& path, const Measurement& measurement) {
  WriteFileAtomically(path, EncodeBpc(measurement));
}

BpcAppender::BpcAppender(std::string path, std::FILE* file, int slice_count)
    : path_(std::move(path)), file_(file), slice_count_(slice_count) {}

BpcAppender::BpcAppender(BpcAppender&& other) noexcept
    : path_(std::move(other.path_)),
      file_(std::exchange(other.file_, nullptr)),
      slice_count_(other.slice_count_),
      sample_count_(other.sample_count_),
      size_(other.size_) {}

BpcAppender& BpcAppender::operator=(BpcAppender&& other) noexcept {
  if (this != &other) {
    Close();
    path_ = std::move(other.path_);
    file_ = std::exchange(other.file_, nullptr);
    slice_count_ = other.slice_count_;
    sample_count_ = other.sample_count_;
    size_ = other.size_;
  }
  return *this;
}

BpcAppender::~BpcAppender() { Close(); }

void BpcAppender::Close() {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
}

BpcAppender BpcAppender::Create(const std::string& path, const Metadata& metadata) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw IoError(path + ": cannot create capture file: " + ErrnoText());
  BpcAppender appender(path, f, 0);
  appender.WriteDurably(EncodePreambleAndHeader(metadata));
  SyncParentDir(path);  // the new directory entry must survive a crash too
  return appender;
}

BpcAppender BpcAppender::Resume(const std::string& path, BpcReadResult* existing) {
  BpcReadResult r = ReadBpc(path);
  if (r.finished)
    throw InvalidArgument(path +
                          ": the capture is already finished (it has its end chunk); "
                          "nothing to resume");
  if (r.intact_data_after_damage)
    throw FormatError(path, BytePosition(r.valid_bytes),
                      "damage only at the tail of an interrupted capture",
                      "intact chunks after a damaged one", "resuming would truncate them",
                      Remedy{RemedyKind::kRepairCapture, path});
  if (::truncate(path.c_str(), static_cast<off_t>(r.valid_bytes)) != 0)
    throw IoError(path + ": cannot truncate to " + std::to_string(r.valid_bytes) +
                  " bytes: " + ErrnoText());
  std::FILE* f = std::fopen(path.c_str(), "r+b");
  if (f == nullptr) throw IoError(path + ": cannot open for appending: " + ErrnoText());
  if (std::fseek(f, 0, SEEK_END) != 0) {
    std::fclose(f);
    throw IoError(path + ": cannot seek to the end: " + ErrnoText());
  }
  int next_index = 0;
  for (int index : r.slice_indices) next_index = std::max(next_index, index + 1);
  BpcAppender appender(path, f, next_index);
  appender.sample_count_ = r.measurement.SampleCount();
  appender.size_ = r.valid_bytes;
  if (SyncFile(f) != 0) throw IoError(path + ": cannot sync after truncation: " + ErrnoText());
  if (existing != nullptr) *existing = std::move(r);
  return appender;
}

void BpcAppender::WriteDurably(const std::string& bytes) {
  if (file_ == nullptr) throw Error(path_ + ": capture file already finished or closed");
  // Raw writes on the descriptor (no stdio buffer that could hold half a chunk after a failure).
  const int fd = ::fileno(file_);
  std::size_t done = 0;
  bool ok = true;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ok = false;
      break;
    }
    done += static_cast<std::size_t>(n);
  }
  ok = ok && ::fsync(fd) == 0;
  if (!ok) {
    const std::string why = ErrnoText();
    // Cut the partial chunk off again (disk full, quota, file size limit), so the file stays a
    // valid prefix and a retry appends cleanly after the last complete chunk.
    const bool restored = ::ftruncate(fd, static_cast<off_t>(size_)) == 0 &&
                          ::lseek(fd, static_cast<off_t>(size_), SEEK_SET) >= 0;
    throw IoError(path_ + ": write failed: " + why +
                  (restored ? " (the file is left at its last complete chunk)" : ""));
  }
  size_ += bytes.size();
}

void BpcAppender::AppendSlice(const Slice& slice) {
  WriteDurably(EncodeSliceChunk(slice, slice_count_));
  ++slice_count_;
  sample_count_ += slice.samples.size();
}

void BpcAppender::Finish(const Metadata& final_metadata) {
  WriteDurably(
      EncodeChunk(kTagEnd, kNoSlice, EndJson(final_metadata, slice_count_, sample_count_)));
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw IoError(path_ + ": close failed: " + ErrnoText());
}

std::string MetadataToJsonText(const Metadata& metadata) { return MetadataToJson(metadata).dump(); }

}  // namespace brdf
