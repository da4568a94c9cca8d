#include "brdf/core/file_util.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <regex>
#include <set>

#include "brdf/core/error.h"

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

namespace brdf {

namespace fs = std::filesystem;

namespace {

std::string ErrnoText() { return std::strerror(errno); }

void SyncPath(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

std::string ExistsMessage(const std::vector<std::string>& paths) {
  std::string m = paths.front() + ": already exists";
  if (paths.size() > 1)
    m += " (and " + std::to_string(paths.size() - 1) + " more output" +
         (paths.size() == 2 ? "" : "s") + " of this run)";
  return m;
}

// "a folder", "a FIFO (named pipe)", ... for what `st` describes if it is not a regular file.
std::string KindOf(const struct stat& st) {
  if (S_ISDIR(st.st_mode)) return "a folder";
  if (S_ISFIFO(st.st_mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return "a device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "a special file";
}

// KindOf for a path that exists and is not a regular file; "" otherwise.
std::string NonRegularKind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return {};
  return KindOf(st);
}

constexpr const char* kTempPrefix = ".brdf-";
constexpr const char* kTempSuffix = ".tmp";

// The writer's process id if `name` is a temporary file name of AtomicOutputPath (this version:
// ".brdf-<pid>-<n>.tmp"; older ones: ".<final name>.tmp-<pid>-<n>"), else 0.
long TemporaryOwner(const std::string& name) {
  static const std::regex current(R"(^\.brdf-([0-9]{1,9})-[0-9]{1,20}\.tmp$)");
  static const std::regex legacy(R"(^\..+\.tmp-([0-9]{1,9})-[0-9]{1,20}$)");
  std::smatch m;
  if (std::regex_match(name, m, current) || std::regex_match(name, m, legacy))
    return std::stol(m[1].str());
  return 0;
}

bool ProcessRuns(long pid) { return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM; }

}  // namespace

std::vector<std::string> RemoveStaleTemporaries(const std::string& dir) {
  std::vector<std::string> removed;
  std::error_code ec;
  for (fs::directory_iterator it(dir.empty() ? "." : dir, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const long pid = TemporaryOwner(name);
    if (pid <= 0 || pid == ::getpid() || ProcessRuns(pid)) continue;
    std::error_code type_ec;
    if (!it->is_regular_file(type_ec)) continue;
    if (::unlink(it->path().c_str()) == 0) removed.push_back(it->path().string());
  }
  return removed;
}

void CheckOutputName(const std::string& path, bool folders_created) {
  if (path.empty()) throw IoError("an output file name is empty");
  if (path.size() > kMaxPathBytes)
    throw IoError(path.substr(0, 60) + "...: the output's path is " + std::to_string(path.size()) +
                  " bytes long; a path may have at most " + std::to_string(kMaxPathBytes) +
                  " bytes (PATH_MAX)");
  const fs::path p(path);
  const std::string name = p.filename().string();
  if (name.size() > kMaxNameBytes)
    throw IoError(path + ": the file name is " + std::to_string(name.size()) +
                  " bytes long; a file name may have at most " + std::to_string(kMaxNameBytes) +
                  " bytes (NAME_MAX)");
  for (const fs::path& part : p)
    if (part.string().size() > kMaxNameBytes)
      throw IoError(path + ": the folder name " + part.string().substr(0, 40) + "... is " +
                    std::to_string(part.string().size()) + " bytes long; a name may have at most " +
                    std::to_string(kMaxNameBytes) + " bytes (NAME_MAX)");
  std::string folder = p.has_parent_path() ? p.parent_path().string() : std::string(".");
  struct stat st {};
  // Folders the command creates itself: the nearest one that exists must take them.
  while (folders_created && ::stat(folder.c_str(), &st) != 0 && errno == ENOENT) {
    const fs::path up = fs::path(folder).parent_path();
    folder = up.empty() ? std::string(".") : up.string();
  }
  if (::stat(folder.c_str(), &st) != 0)
    throw IoError(path + ": cannot write into the folder " + folder + ": " + ErrnoText());
  if (!S_ISDIR(st.st_mode)) throw IoError(path + ": " + folder + " is not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw IoError(path + ": cannot write into the folder " + folder + ": " + ErrnoText());
}

OutputExistsError::OutputExistsError(std::vector<std::string> paths)
    : IoError(ExistsMessage(paths), Remedy{RemedyKind::kForceOverwrite,
                                           paths.size() == 1 ? paths.front() : std::string()}),
      paths_(std::move(paths)) {}

std::vector<std::string> CheckWritableOutputs(const std::vector<std::string>& paths, bool overwrite,
                                              bool folders_created) {
  std::vector<std::string> existing;
  for (const std::string& p : paths) {
    CheckOutputName(p, folders_created);
    if (const std::string kind = NonRegularKind(p); !kind.empty())
      throw IoError(p + ": exists and is " + kind + ", not a file; choose another output name");
    std::error_code ec;
    if (fs::exists(p, ec)) existing.push_back(p);
  }
  if (!existing.empty() && !overwrite) throw OutputExistsError(std::move(existing));
  std::vector<std::string> removed;
  std::set<std::string> folders;
  for (const std::string& p : paths) {
    const fs::path parent = fs::path(p).parent_path();
    if (!folders.insert(parent.empty() ? "." : parent.string()).second) continue;
    for (std::string& r : RemoveStaleTemporaries(parent.string())) removed.push_back(std::move(r));
  }
  return removed;
}

AtomicOutputPath::AtomicOutputPath(std::string final_path) : final_path_(std::move(final_path)) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(final_path_);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  temp_path_ = (dir / (std::string(kTempPrefix) + std::to_string(::getpid()) + "-" +
                       std::to_string(counter++) + kTempSuffix))
                   .string();
}

AtomicOutputPath::~AtomicOutputPath() {
  if (!committed_) ::unlink(temp_path_.c_str());
}

void AtomicOutputPath::Commit() {
  SyncPath(temp_path_);
  if (std::rename(temp_path_.c_str(), final_path_.c_str()) != 0)
    throw IoError(final_path_ + ": cannot rename temporary file " + temp_path_ +
                  " into place: " + ErrnoText());
  committed_ = true;
  const fs::path p(final_path_);
  SyncPath(p.has_parent_path() ? p.parent_path().string() : std::string("."));
}

void WriteFileAtomically(const std::string& path, std::string_view bytes) {
  AtomicOutputPath out(path);
  std::FILE* f = std::fopen(out.temp_path().c_str(), "wb");
  if (f == nullptr) throw IoError(path + ": cannot create file: " + ErrnoText());
  const std::size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
  const bool ok = written == bytes.size() && std::fflush(f) == 0;
  const std::string why = ok ? std::string() : ErrnoText();
  std::fclose(f);
  if (!ok) throw IoError(path + ": write failed: " + why);
  out.Commit();
}

int OpenRegularFile(const std::string& path, std::uint64_t* size_bytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw IoError(path + ": cannot open: " + ErrnoText());
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const std::string why = ErrnoText();
    ::close(fd);
    throw IoError(path + ": cannot read its size: " + why);
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    throw IoError(path + ": is " + KindOf(st) + ", not a file");
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  *size_bytes = static_cast<std::uint64_t>(st.st_size);
  return fd;
}

void CheckRegularFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) throw IoError(path + ": no such file");
    throw IoError(path + ": cannot access: " + ErrnoText());
  }
  if (!S_ISREG(st.st_mode)) throw IoError(path + ": is " + KindOf(st) + ", not a file");
}

namespace {

// Reads exactly n bytes (fewer only at end of file); returns the count read. Throws IoError.
std::size_t ReadUpTo(int fd, std::uint8_t* out, std::size_t n, const std::string& path) {
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got = ::read(fd, out + done, n - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw IoError(path + ": read failed: " + ErrnoText());
    if (got == 0) break;
    done += static_cast<std::size_t>(got);
  }
  return done;
}

struct FdCloser {
  int fd;
  ~FdCloser() { ::close(fd); }
};

void CheckSize(const std::string& path, std::uint64_t size, std::uint64_t max_bytes) {
  if (size > max_bytes)
    throw FormatError(path, "file size", "at most " + std::to_string(max_bytes) + " bytes",
                      std::to_string(size) + " bytes");
}

}  // namespace

std::vector<std::uint8_t> ReadFileBytes(const std::string& path, std::uint64_t max_bytes) {
  std::uint64_t size = 0;
  const FdCloser fd{OpenRegularFile(path, &size)};
  CheckSize(path, size, max_bytes);
  std::vector<std::uint8_t> data(static_cast<std::size_t>(size));
  if (ReadUpTo(fd.fd, data.data(), data.size(), path) != data.size())
    throw IoError(path + ": read failed: the file became shorter while it was read");
  return data;
}

std::string ReadFileText(const std::string& path, std::uint64_t max_bytes) {
  const auto bytes = ReadFileBytes(path, max_bytes);
  return std::string(bytes.begin(), bytes.end());
}

std::string ReadFileHead(const std::string& path, std::size_t max_bytes) {
  std::uint64_t size = 0;
  const FdCloser fd{OpenRegularFile(path, &size)};
  std::string head(static_cast<std::size_t>(std::min<std::uint64_t>(size, max_bytes)), '\0');
  head.resize(ReadUpTo(fd.fd, reinterpret_cast<std::uint8_t*>(head.data()), head.size(), path));
  return head;
}

MappedFile::MappedFile(const std::string& path, std::uint64_t max_bytes) {
  std::uint64_t size = 0;
  const FdCloser fd{OpenRegularFile(path, &size)};
  CheckSize(path, size, max_bytes);
  if (size == 0) return;
  void* p = ::mmap(nullptr, static_cast<std::size_t>(size), PROT_READ, MAP_PRIVATE, fd.fd, 0);
  if (p == MAP_FAILED) throw IoError(path + ": cannot map the file: " + ErrnoText());
  data_ = static_cast<const std::uint8_t*>(p);
  size_ = static_cast<std::size_t>(size);
}

MappedFile::~MappedFile() {
  if (data_ != nullptr) ::munmap(const_cast<std::uint8_t*>(data_), size_);
}

void ByteReader::Need(std::size_t n, std::string_view what) const {
  if (n > size_ - pos_)
    throw FormatError(file_, BytePosition(offset()),
                      std::to_string(n) + " more bytes for " + std::string(what),
                      "end of data after " + std::to_string(size_ - pos_) + " bytes");
}

void ByteReader::Seek(std::size_t pos) {
  if (pos > size_)
    throw FormatError(file_, BytePosition(base_ + pos), "an offset inside the data",
                      "offset past the end (" + std::to_string(base_ + size_) + " bytes)");
  pos_ = pos;
}

void ByteReader::Skip(std::size_t n) {
  Need(n, "skipped bytes");
  pos_ += n;
}

const std::uint8_t* ByteReader::Bytes(std::size_t n, std::string_view what) {
  Need(n, what);
  const std::uint8_t* p = data_ + pos_;
  pos_ += n;
  return p;
}

std::uint8_t ByteReader::U8(std::string_view what) { return *Bytes(1, what); }

std::uint16_t ByteReader::U16(std::string_view what) {
  const std::uint8_t* p = Bytes(2, what);
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

std::uint32_t ByteReader::U32(std::string_view what) {
  const std::uint8_t* p = Bytes(4, what);
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

std::uint64_t ByteReader::U64(std::string_view what) {
  const std::uint64_t lo = U32(what);
  const std::uint64_t hi = U32(what);
  return lo | (hi << 32);
}

std::int32_t ByteReader::I32(std::string_view what) { return static_cast<std::int32_t>(U32(what)); }

float ByteReader::F32(std::string_view what) {
  const std::uint32_t bits = U32(what);
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

double ByteReader::F64(std::string_view what) {
  const std::uint64_t bits = U64(what);
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

std::string ByteReader::String(std::size_t n, std::string_view what) {
  const std::uint8_t* p = Bytes(n, what);
  return std::string(reinterpret_cast<const char*>(p), n);
}

void ByteReader::Fail(std::string_view expected, std::string_view got) const {
  throw FormatError(file_, BytePosition(offset()), std::string(expected), std::string(got));
}

void AppendU16(std::string& out, std::uint16_t v) {
  out.push_back(static_cast<char>(v & 0xff));
  out.push_back(static_cast<char>(v >> 8));
}

void AppendU32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void AppendU64(std::string& out, std::uint64_t v) {
  AppendU32(out, static_cast<std::uint32_t>(v));
  AppendU32(out, static_cast<std::uint32_t>(v >> 32));
}

void AppendF32(std::string& out, float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  AppendU32(out, bits);
}

namespace {

// Slicing-by-8 tables: a capture of 110 k samples is ~5 MB and every byte of it is checked on
// read, so the CRC dominates reading a .bpc (by-8 is about twice as fast as by-4 here).
struct Crc32Tables {
  std::array<std::array<std::uint32_t, 256>, 8> t{};
  Crc32Tables() {
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[0][i] = c;
    }
    for (std::uint32_t i = 0; i < 256; ++i)
      for (int s = 1; s < 8; ++s) t[s][i] = (t[s - 1][i] >> 8) ^ t[0][t[s - 1][i] & 0xff];
  }
};

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#define BRDF_CRC32_CLMUL 1

// Carry-less multiplication folds 64 bytes at a time (V. Gopal et al., "Fast CRC Computation
// for Generic Polynomials Using PCLMULQDQ Instruction", Intel, 2009, for the reflected
// polynomial): about 2.3× the tables' speed, which every instrument frame and every .bpc read
// pays twice over (CRC on both ends). Constants: x^(4·128±32) and x^(128±32) mod P for the
// folds, x^64 mod P, and P with its Barrett quotient μ = ⌊x^64 / P⌋, all bit-reflected.
__attribute__((target("pclmul,sse4.1"))) inline __m128i FoldClmul(__m128i x, __m128i k,
                                                                  __m128i data) {
  return _mm_xor_si128(
      _mm_xor_si128(_mm_clmulepi64_si128(x, k, 0x00), _mm_clmulepi64_si128(x, k, 0x11)), data);
}

// `state` is the inverted running CRC; size ≥ 64 and a multiple of 16. Returns the new state.
__attribute__((target("pclmul,sse4.1"))) std::uint32_t Crc32Clmul(const std::uint8_t* p,
                                                                  std::size_t size,
                                                                  std::uint32_t state) {
  const __m128i k1k2 = _mm_set_epi64x(0x01c6e41596, 0x0154442bd4);
  const __m128i k3k4 = _mm_set_epi64x(0x00ccaa009e, 0x01751997d0);
  const __m128i k5 = _mm_set_epi64x(0, 0x0163cd6124);
  const __m128i poly_mu = _mm_set_epi64x(0x01f7011641, 0x01db710641);
  const auto load = [](const std::uint8_t* q) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
  };
  __m128i x1 = _mm_xor_si128(load(p), _mm_cvtsi32_si128(static_cast<int>(state)));
  __m128i x2 = load(p + 16), x3 = load(p + 32), x4 = load(p + 48);
  p += 64;
  size -= 64;
  for (; size >= 64; p += 64, size -= 64) {
    x1 = FoldClmul(x1, k1k2, load(p));
    x2 = FoldClmul(x2, k1k2, load(p + 16));
    x3 = FoldClmul(x3, k1k2, load(p + 32));
    x4 = FoldClmul(x4, k1k2, load(p + 48));
  }
  x1 = FoldClmul(FoldClmul(FoldClmul(x1, k3k4, x2), k3k4, x3), k3k4, x4);
  for (; size >= 16; p += 16, size -= 16) x1 = FoldClmul(x1, k3k4, load(p));
  // 128 → 64 bits, then the Barrett reduction to 32.
  const __m128i low32 = _mm_setr_epi32(~0, 0, ~0, 0);
  __m128i t = _mm_clmulepi64_si128(x1, k3k4, 0x10);
  x1 = _mm_xor_si128(_mm_srli_si128(x1, 8), t);
  t = _mm_srli_si128(x1, 4);
  x1 = _mm_xor_si128(_mm_clmulepi64_si128(_mm_and_si128(x1, low32), k5, 0x00), t);
  t = _mm_clmulepi64_si128(_mm_and_si128(x1, low32), poly_mu, 0x10);
  t = _mm_clmulepi64_si128(_mm_and_si128(t, low32), poly_mu, 0x00);
  return static_cast<std::uint32_t>(_mm_extract_epi32(_mm_xor_si128(x1, t), 1));
}

bool HaveClmul() {
  static const bool have = __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("sse4.1");
  return have;
}
#endif

}  // namespace

std::uint32_t Crc32(const void* data, std::size_t size, std::uint32_t crc) {
  static const Crc32Tables tables;
  const auto& t = tables.t;
  const auto* p = static_cast<const std::uint8_t*>(data);
  const auto le32 = [](const std::uint8_t* q) {
    return static_cast<std::uint32_t>(q[0]) | (static_cast<std::uint32_t>(q[1]) << 8) |
           (static_cast<std::uint32_t>(q[2]) << 16) | (static_cast<std::uint32_t>(q[3]) << 24);
  };
  crc = ~crc;
#ifdef BRDF_CRC32_CLMUL
  if (size >= 64 && HaveClmul()) {
    const std::size_t folded = size & ~std::size_t{15};
    crc = Crc32Clmul(p, folded, crc);
    p += folded;
    size -= folded;
  }
#endif
  while (size >= 8) {
    const std::uint32_t lo = crc ^ le32(p);
    const std::uint32_t hi = le32(p + 4);
    crc = t[7][lo & 0xff] ^ t[6][(lo >> 8) & 0xff] ^ t[5][(lo >> 16) & 0xff] ^ t[4][lo >> 24] ^
          t[3][hi & 0xff] ^ t[2][(hi >> 8) & 0xff] ^ t[1][(hi >> 16) & 0xff] ^ t[0][hi >> 24];
    p += 8;
    size -= 8;
  }
  while (size-- > 0) crc = t[0][(crc ^ *p++) & 0xff] ^ (crc >> 8);
  return ~crc;
}

}  // namespace brdf
