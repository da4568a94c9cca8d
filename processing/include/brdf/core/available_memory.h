// How much memory this process can still take before the machine, its cgroup or its
// address-space limit says no: for refusing, in one line and before any work, a request that
// would not fit (a preview of 8192² pixels on a small machine), instead of being killed by the
// kernel's out-of-memory killer or failing half-way.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace brdf {

struct AvailableMemory {
  std::uint64_t bytes = 0;
  std::string limited_by;  // what set it: MemAvailable, the cgroup, the address-space limit
};

// The smallest of: MemAvailable of /proc/meminfo; the cgroup (v2 memory.max − memory.current,
// or v1 memory.limit_in_bytes − memory.usage_in_bytes) of this process; RLIMIT_AS minus the
// address space already mapped. Empty when none of them can be read (not Linux).
std::optional<AvailableMemory> QueryAvailableMemory();

// "3.2 GB", "640 MB": a byte count for a message.
std::string MemoryText(std::uint64_t bytes);

}  // namespace brdf
