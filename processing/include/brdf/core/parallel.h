// The one work-sharing loop of the libraries: the preview's pixel passes, the map hierarchy,
// the BRDF sampler tables, an RGL file's tabulation and the fit's independent blocks all hand
// out work through it.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace brdf {

// The number of threads a `jobs` setting asks for: itself when positive, else one per core
// (std::thread::hardware_concurrency(), at least 1).
inline int ResolveJobs(int jobs) {
  if (jobs > 0) return jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Runs work(begin, end) over [0, count) in chunks of `chunk` on `jobs` threads (the calling
// thread one of them; never more threads than chunks, at least one), handing out chunks in
// order from one atomic counter. Stops handing out chunks once `cancel` (if given) becomes
// true, or once a chunk throws: the first exception is rethrown on the calling thread after
// every thread has finished. `after_caller_chunk`, when set, runs on the calling thread after
// each chunk it completed (progress reports come from there, so callbacks never run on a
// worker).
template <class F>
void ParallelChunks(std::size_t count, std::size_t chunk, int jobs, const std::atomic<bool>* cancel,
                    F work, const std::function<void()>& after_caller_chunk = {}) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto loop = [&](bool caller) {
    for (std::size_t begin = next.fetch_add(chunk); begin < count; begin = next.fetch_add(chunk)) {
      if (failed.load(std::memory_order_relaxed)) return;
      if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return;
      try {
        work(begin, std::min(count, begin + chunk));
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
        return;
      }
      if (caller && after_caller_chunk) after_caller_chunk();
    }
  };
  const int threads =
      std::max(1, std::min<int>(jobs, static_cast<int>((count + chunk - 1) / chunk)));
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t) workers.emplace_back(loop, false);
  loop(true);
  for (auto& w : workers) w.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace brdf
