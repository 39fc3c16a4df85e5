#pragma once
// A minimal parallel loop for independent CPU work items (per template, per hypothesis).
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace vkpose::util {

/// The threads parallelFor runs n items on: `threads` (0: all cores), at most n.
inline unsigned threadsFor(std::size_t n, unsigned threads = 0) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::min<std::size_t>(threads, n));
}

/// Calls fn(i) for i in [0, n) on up to `threads` threads (0: all cores). The first exception
/// thrown by any item is rethrown here after all threads stop. Each item's result goes to its
/// own slot (callers index by i), so the results do not depend on the thread count.
template <class Fn>
void parallelFor(std::size_t n, Fn&& fn, unsigned threads = 0) {
  threads = threadsFor(n, threads);
  if (threads <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < n;) {
      try {
        fn(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace vkpose::util
