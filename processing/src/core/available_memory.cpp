// The memory this process may still take (available_memory.h), from /proc and the cgroup files.
#include "brdf/core/available_memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace brdf {
namespace {

// The first unsigned number of a file ("max" and unreadable files give nothing).
std::optional<std::uint64_t> ReadNumber(const std::string& path) {
  std::ifstream in(path);
  std::uint64_t v = 0;
  if (in >> v) return v;
  return std::nullopt;
}

// This process's cgroup path: the "0::/path" line (v2) or the memory controller's line (v1).
std::optional<std::string> CgroupPath(bool* v2) {
  std::ifstream in("/proc/self/cgroup");
  std::string line, v1_path;
  std::optional<std::string> v2_path;
  while (std::getline(in, line)) {
    const auto first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::string path = line.substr(second + 1);
    if (line.compare(0, first, "0") == 0 && controllers.empty()) v2_path = path;
    std::istringstream list(controllers);
    for (std::string c; std::getline(list, c, ',');)
      if (c == "memory") v1_path = path;
  }
  if (!v1_path.empty()) {
    *v2 = false;
    return v1_path;
  }
  *v2 = true;
  return v2_path;
}

}  // namespace

std::optional<AvailableMemory> QueryAvailableMemory() {
  std::optional<AvailableMemory> best;
  auto consider = [&](std::uint64_t bytes, const char* what) {
    if (!best || bytes < best->bytes) best = AvailableMemory{bytes, what};
  };
  {
    std::ifstream in("/proc/meminfo");
    std::string key;
    std::uint64_t kib = 0;
    std::string unit;
    while (in >> key >> kib) {
      std::getline(in, unit);
      if (key == "MemAvailable:") {
        consider(kib * 1024, "MemAvailable");
        break;
      }
    }
  }
  bool v2 = true;
  if (const auto path = CgroupPath(&v2)) {
    const std::string base = (v2 ? "/sys/fs/cgroup" : "/sys/fs/cgroup/memory") + *path;
    const auto limit = ReadNumber(base + (v2 ? "/memory.max" : "/memory.limit_in_bytes"));
    const auto usage = ReadNumber(base + (v2 ? "/memory.current" : "/memory.usage_in_bytes"));
    // v1 reports "no limit" as a number near 2^63.
    if (limit && usage && *limit < (std::uint64_t{1} << 60))
      consider(*limit > *usage ? *limit - *usage : 0, "the cgroup's memory limit");
  }
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    std::uint64_t mapped = 0;
    if (std::ifstream statm("/proc/self/statm"); statm >> mapped)
      mapped *= static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
    const std::uint64_t limit = as.rlim_cur;
    consider(limit > mapped ? limit - mapped : 0, "the address-space limit (ulimit -v)");
  }
  return best;
}

std::string MemoryText(std::uint64_t bytes) {
  char buf[32];
  if (bytes >= (std::uint64_t{1} << 30))
    std::snprintf(buf, sizeof buf, "%.1f GB", bytes / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.0f MB", bytes / 1e6);
  return buf;
}

}  // namespace brdf
