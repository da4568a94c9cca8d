// Reading `.bpc` files: the tolerant parser that reports every damaged chunk and recovers the
// rest, and the streaming fast path for intact files (brdf/core/bpc.h).
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
#include "brdf/core/text_format.h"

namespace brdf {

using detail::ChunkHeader;
using detail::DecodeChunkHeader;
using detail::DecodeEndPayload;
using detail::DecodeRecords;
using detail::DecodeSliceHeader;
using detail::DecodeSlicePayload;
using detail::HeaderCrcOk;
using detail::Json;
using detail::kChunkHeaderSize;
using detail::kPreambleSize;
using detail::kSliceHeaderSize;
using detail::kTagEnd;
using detail::kTagHead;
using detail::kTagSlice;
using detail::LoadU32;
using detail::LoadU64;
using detail::MetadataFromJson;
using detail::ParseJsonPayload;
using detail::TagIs;
using detail::TagText;

namespace {

class BpcParser {
 public:
  BpcParser(std::string file, const std::uint8_t* data, std::size_t size)
      : file_(std::move(file)), data_(data), size_(size) {}

  BpcReadResult Parse() {
    std::size_t pos = ParseHeader();
    result_.valid_bytes = pos;
    bool prefix_intact = true;
    int expected_slice = 0;  // ordinal of the next slice chunk, damaged ones included
    while (pos < size_) {
      const std::size_t remaining = size_ - pos;
      if (remaining < kChunkHeaderSize) {
        AddProblem(BpcProblemKind::kTruncated, pos, remaining, -1, "a 24-byte chunk header",
                   "end of file after " + std::to_string(remaining) + " bytes (file cut at byte " +
                       std::to_string(size_) + ")");
        break;
      }
      const std::uint8_t* p = data_ + pos;
      const ChunkHeader h = DecodeChunkHeader(p);
      if (!HeaderCrcOk(p)) {
        // The header cannot be trusted, so neither can its length: look for the next intact
        // chunk header. A single flipped byte leaves either the tag or the index intact, which
        // is enough to attribute the damage to a slice.
        const int slice =
            (TagIs(p, kTagSlice) || h.slice_index == static_cast<std::uint32_t>(expected_slice))
                ? expected_slice
                : -1;
        const std::size_t next = FindNextChunk(pos + 1);
        const std::uint64_t region = next - pos;
        AddProblem(BpcProblemKind::kCorrupt, pos, region, slice,
                   "chunk header CRC-32 " + Hex32Text(h.header_crc),
                   Hex32Text(Crc32(p, 20)) + " (tag " + TagText(p) + "); " +
                       std::to_string(region) + " bytes skipped" +
                       (next == size_ ? " to the end of the file" : ""));
        if (slice >= 0) ++expected_slice;
        prefix_intact = false;
        pos = next;
        continue;
      }
      const bool is_slice = TagIs(p, kTagSlice);
      const int stored_slice =
          is_slice && h.slice_index <= static_cast<std::uint32_t>(std::numeric_limits<int>::max())
              ? static_cast<int>(h.slice_index)
              : -1;
      if (h.payload_size > remaining - kChunkHeaderSize) {
        AddProblem(BpcProblemKind::kTruncated, pos, remaining, stored_slice,
                   std::to_string(h.payload_size) + " payload bytes for chunk " + TagText(p),
                   std::to_string(remaining - kChunkHeaderSize) + " (file cut at byte " +
                       std::to_string(size_) + ")");
        break;
      }
      const std::uint8_t* payload = p + kChunkHeaderSize;
      const std::size_t n = static_cast<std::size_t>(h.payload_size);
      const std::size_t end = pos + kChunkHeaderSize + n;
      const std::uint32_t crc = Crc32(payload, n);
      if (crc != h.payload_crc) {
        AddProblem(BpcProblemKind::kCorrupt, pos, end - pos, stored_slice,
                   "payload CRC-32 " + Hex32Text(h.payload_crc) + " of chunk " + TagText(p),
                   Hex32Text(crc));
        if (stored_slice >= 0) expected_slice = stored_slice + 1;
        prefix_intact = false;
        pos = end;
        continue;
      }
      bool intact = true;
      if (is_slice) {
        Slice slice;
        const std::string why = stored_slice < 0
                                    ? std::string("slice index ") + std::to_string(h.slice_index)
                                    : DecodeSlicePayload(payload, n, &slice);
        if (why.empty()) {
          result_.measurement.slices.push_back(std::move(slice));
          result_.slice_indices.push_back(stored_slice);
          result_.slice_offsets.push_back(pos);
          expected_slice = stored_slice + 1;
        } else {
          AddProblem(BpcProblemKind::kCorrupt, pos, end - pos, stored_slice,
                     "a consistent slice chunk", why);
          intact = false;
          if (stored_slice >= 0) expected_slice = stored_slice + 1;
        }
      } else if (TagIs(p, kTagEnd)) {
        // A CRC-valid end chunk with unusable JSON was written wrong, not damaged in transit;
        // it is reported like damage so the slices before it stay readable.
        try {
          end_metadata_ = DecodeEndPayload(payload, n, file_, pos + kChunkHeaderSize, &result_);
          result_.finished = true;
        } catch (const FormatError& e) {
          AddProblem(BpcProblemKind::kCorrupt, pos, end - pos, -1, e.expected(), e.got());
          intact = false;
        }
      }
      // Any other tag is a chunk type from a newer minor version: skipped (bpc.md, versioning).
      if (intact && !prefix_intact) result_.intact_data_after_damage = true;
      if (!intact) prefix_intact = false;
      pos = end;
      if (prefix_intact) result_.valid_bytes = pos;
      if (result_.finished) {
        if (pos < size_)
          AddProblem(BpcProblemKind::kTrailingData, pos, size_ - pos, -1,
                     "end of file after the end chunk",
                     std::to_string(size_ - pos) + " more bytes");
        break;
      }
    }
    result_.header_metadata = result_.measurement.metadata;
    if (result_.finished) result_.measurement.metadata = end_metadata_;
    return std::move(result_);
  }

 private:
  [[noreturn]] void FailHeader(std::uint64_t offset, const std::string& expected,
                               const std::string& got) const {
    throw FormatError(file_, BytePosition(offset), expected, got,
                      "the file header is unreadable, so nothing in the file can be trusted");
  }

  std::size_t ParseHeader() {
    if (size_ < kBpcMagic.size() || std::memcmp(data_, kBpcMagic.data(), kBpcMagic.size()) != 0) {
      std::string got;
      for (std::size_t i = 0; i < std::min<std::size_t>(size_, kBpcMagic.size()); ++i) {
        char buf[4];
        std::snprintf(buf, sizeof buf, "%02x", data_[i]);
        got += (i ? " " : "") + std::string(buf);
      }
      FailHeader(0, "the .bpc magic 89 42 50 43 0d 0a 1a 0a",
                 size_ == 0 ? std::string("an empty file") : got);
    }
    if (size_ < kPreambleSize)
      FailHeader(8, "a 2+2-byte format version", "end of file at byte " + std::to_string(size_));
    const unsigned major = data_[8] | (data_[9] << 8);
    const unsigned minor = data_[10] | (data_[11] << 8);
    if (major != kBpcVersionMajor)
      FailHeader(8, "format version " + std::to_string(kBpcVersionMajor) + ".x",
                 "version " + std::to_string(major) + "." + std::to_string(minor));
    std::size_t pos = kPreambleSize;
    if (size_ - pos < kChunkHeaderSize)
      FailHeader(pos, "the 24-byte header chunk header",
                 "end of file at byte " + std::to_string(size_));
    const std::uint8_t* p = data_ + pos;
    if (!TagIs(p, kTagHead)) FailHeader(pos, "chunk tag 'HEAD'", TagText(p));
    if (!HeaderCrcOk(p))
      FailHeader(pos + 20, "header chunk header CRC-32 " + Hex32Text(LoadU32(p + 20)),
                 Hex32Text(Crc32(p, 20)));
    const ChunkHeader h = DecodeChunkHeader(p);
    if (h.payload_size > size_ - pos - kChunkHeaderSize)
      FailHeader(pos + 8, std::to_string(h.payload_size) + " bytes of header JSON",
                 std::to_string(size_ - pos - kChunkHeaderSize) + " bytes before the end of file");
    const std::size_t n = static_cast<std::size_t>(h.payload_size);
    const std::uint8_t* payload = p + kChunkHeaderSize;
    if (const std::uint32_t crc = Crc32(payload, n); crc != h.payload_crc)
      FailHeader(pos + kChunkHeaderSize, "header JSON CRC-32 " + Hex32Text(h.payload_crc),
                 Hex32Text(crc));
    const Json j = ParseJsonPayload(payload, n, file_, pos + kChunkHeaderSize, "header");
    // The preamble's version is outside any CRC; the JSON repeats it, so a damaged version
    // field is caught rather than silently accepted.
    const Json want_version = {major, minor};
    if (const auto v = j.find("version"); v == j.end() || *v != want_version)
      FailHeader(8, "the format version of the header JSON",
                 "preamble version " + std::to_string(major) + "." + std::to_string(minor) +
                     " but header JSON 'version' " + (v == j.end() ? "missing" : v->dump()));
    const auto md = j.find("metadata");
    if (md == j.end())
      throw FormatError(file_, BytePosition(pos + kChunkHeaderSize) + " (header JSON)",
                        "a 'metadata' member", "none");
    result_.measurement.metadata = MetadataFromJson(*md, file_, pos + kChunkHeaderSize, "header");
    return pos + kChunkHeaderSize + n;
  }

  // First offset >= from holding a slice or end chunk header whose header CRC matches; the
  // file size if there is none.
  std::size_t FindNextChunk(std::size_t from) const {
    for (std::size_t q = from; q + kChunkHeaderSize <= size_; ++q) {
      const std::uint8_t* p = data_ + q;
      if ((TagIs(p, kTagSlice) || TagIs(p, kTagEnd)) && HeaderCrcOk(p)) return q;
    }
    return size_;
  }

  void AddProblem(BpcProblemKind kind, std::uint64_t offset, std::uint64_t size, int slice,
                  std::string expected, std::string got) {
    BpcProblem problem;
    problem.kind = kind;
    problem.offset = offset;
    problem.size = size;
    problem.slice_index = slice;
    std::string position = BytePosition(offset);
    if (slice >= 0) position += " (slice " + std::to_string(slice) + ")";
    std::string hint;
    if (kind == BpcProblemKind::kTruncated) hint = "damaged tail of an interrupted capture";
    problem.message = FormatError(file_, position, expected, got, hint).what();
    problem.expected = std::move(expected);
    problem.got = std::move(got);
    result_.problems.push_back(std::move(problem));
  }

  std::string file_;
  const std::uint8_t* data_;
  std::size_t size_;
  BpcReadResult result_;
  Metadata end_metadata_;
};

// Reads exactly n bytes; false on a short read or an error.
bool ReadExact(int fd, void* dst, std::size_t n) {
  auto* p = static_cast<std::uint8_t*>(dst);
  while (n > 0) {
    const ssize_t got = ::read(fd, p, n);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    p += got;
    n -= static_cast<std::size_t>(got);
  }
  return true;
}

// The common case, an intact file, streamed through a small buffer: the whole file is never
// held in memory, which halves the memory a read touches (page faults dominate a 5 MB read).
// Returns nothing at the first sign of damage (or a file changing under us); the caller then
// reads the whole file with the tolerant parser, which alone decides what is reported.
std::optional<BpcReadResult> ReadIntactStreaming(int fd, std::uint64_t size,
                                                 const std::string& path) {
  if (size < kPreambleSize + kChunkHeaderSize) return std::nullopt;
  std::vector<std::uint8_t> head(kPreambleSize + kChunkHeaderSize);
  if (!ReadExact(fd, head.data(), head.size())) return std::nullopt;
  const std::uint64_t head_json = LoadU64(head.data() + kPreambleSize + 8);
  if (head_json > size - head.size()) return std::nullopt;
  head.resize(head.size() + static_cast<std::size_t>(head_json));
  if (!ReadExact(fd, head.data() + kPreambleSize + kChunkHeaderSize,
                 static_cast<std::size_t>(head_json)))
    return std::nullopt;
  BpcReadResult result;
  try {
    result = ParseBpc(head.data(), head.size(), path);
  } catch (const FormatError&) {
    return std::nullopt;
  }
  if (!result.problems.empty()) return std::nullopt;

  constexpr std::size_t kBlockBytes = 64 * 1024;
  std::vector<std::uint8_t> block(kBlockBytes);
  std::uint64_t pos = head.size();
  while (pos < size) {
    std::uint8_t h[kChunkHeaderSize];
    if (size - pos < kChunkHeaderSize || !ReadExact(fd, h, sizeof h) || !HeaderCrcOk(h))
      return std::nullopt;
    const ChunkHeader ch = DecodeChunkHeader(h);
    const std::uint64_t n = ch.payload_size;
    if (n > size - pos - kChunkHeaderSize) return std::nullopt;
    std::uint32_t crc = 0;
    if (TagIs(h, kTagSlice)) {
      std::uint8_t sh[kSliceHeaderSize];
      Slice slice;
      std::uint32_t record_size = 0;
      if (ch.slice_index > static_cast<std::uint32_t>(std::numeric_limits<int>::max()) ||
          n < kSliceHeaderSize || !ReadExact(fd, sh, sizeof sh) ||
          !DecodeSliceHeader(sh, n, &slice, &record_size).empty())
        return std::nullopt;
      crc = Crc32(sh, sizeof sh);
      const std::size_t per_block = std::max<std::size_t>(1, kBlockBytes / record_size);
      if (block.size() < per_block * record_size) block.resize(per_block * record_size);
      for (std::size_t done = 0; done < slice.samples.size();) {
        const std::size_t count = std::min(per_block, slice.samples.size() - done);
        const std::size_t bytes = count * record_size;
        if (!ReadExact(fd, block.data(), bytes)) return std::nullopt;
        crc = Crc32(block.data(), bytes, crc);
        DecodeRecords(block.data(), count, record_size, slice.has_sigma,
                      slice.samples.data() + done);
        done += count;
      }
      if (crc != ch.payload_crc) return std::nullopt;
      result.measurement.slices.push_back(std::move(slice));
      result.slice_indices.push_back(static_cast<int>(ch.slice_index));
      result.slice_offsets.push_back(pos);
    } else if (TagIs(h, kTagEnd)) {
      std::vector<std::uint8_t> payload(static_cast<std::size_t>(n));
      if (!ReadExact(fd, payload.data(), payload.size()) ||
          Crc32(payload.data(), payload.size()) != ch.payload_crc ||
          pos + kChunkHeaderSize + n != size)
        return std::nullopt;
      try {
        result.header_metadata = result.measurement.metadata;
        result.measurement.metadata =
            DecodeEndPayload(payload.data(), payload.size(), path, pos + kChunkHeaderSize, &result);
      } catch (const FormatError&) {
        return std::nullopt;
      }
      result.finished = true;
    } else {
      for (std::uint64_t left = n; left > 0;) {
        const std::size_t bytes =
            static_cast<std::size_t>(std::min<std::uint64_t>(left, block.size()));
        if (!ReadExact(fd, block.data(), bytes)) return std::nullopt;
        crc = Crc32(block.data(), bytes, crc);
        left -= bytes;
      }
      if (crc != ch.payload_crc) return std::nullopt;
    }
    pos += kChunkHeaderSize + n;
    result.valid_bytes = pos;
  }
  if (!result.finished) result.header_metadata = result.measurement.metadata;
  return result;
}

}  // namespace

BpcReadResult ReadBpc(const std::string& path) {
  // Never blocks on a FIFO or device; refuses anything but a regular file.
  std::uint64_t size = 0;
  const int fd = OpenRegularFile(path, &size);
  std::optional<BpcReadResult> fast;
  if (size <= kBpcMaxFileBytes) fast = ReadIntactStreaming(fd, size, path);
  ::close(fd);
  if (fast) return std::move(*fast);
  // Damaged or unusual: the parser needs random access. Mapped, not read, so a huge file
  // (e.g. a small capture followed by gigabytes of holes) costs only the pages looked at.
  const MappedFile mapped(path, kBpcMaxFileBytes);
  return ParseBpc(mapped.data(), mapped.size(), path);
}

BpcReadResult ParseBpc(const std::uint8_t* data, std::size_t size, const std::string& file) {
  return BpcParser(file, data, size).Parse();
}

Measurement LoadBpc(const std::string& path) {
  BpcReadResult r = ReadBpc(path);
  if (!r.problems.empty()) {
    const BpcProblem& p = r.problems.front();
    std::string position = BytePosition(p.offset);
    if (p.slice_index >= 0) position += " (slice " + std::to_string(p.slice_index) + ")";
    throw FormatError(path, position, p.expected, p.got);
  }
  return std::move(r.measurement);
}

}  // namespace brdf
