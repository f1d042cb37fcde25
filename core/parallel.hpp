#pragma once
// core/parallel.hpp -- the one worker pool of the library: independent items handed out
// dynamically to threads (items differ in cost by 100x: a static split would leave threads
// idle). Every long loop over runs, conditions or campaigns goes through it.
//
// Takes: the number of items, the threads (0: all cores), the work per item, and an optional
//        callback run under a lock after each item (results in order of completion, progress).
// Gives: nothing; an exception thrown by an item is caught and rethrown after all threads
//        have joined (the first one), unless the item handles its own failures. The caller's
//        cancel flag (core/cancel.hpp) is current in every worker and checked before each item.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "core/cancel.hpp"

namespace vrelab::core {

// The threads to use: `requested` when positive, else every core the machine reports.
inline int thread_count(int requested) {
  return requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Runs work(i) for i in [0, n) on thread_count(threads) threads (the caller's among them),
// then after_each(i) under one lock. The item's index, not the thread, decides its result:
// any per-item randomness must be seeded from i.
inline void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& work,
                         const std::function<void(std::size_t)>& after_each = {}) {
  std::atomic<std::size_t> next{0};
  std::mutex lock;
  std::exception_ptr failure;
  const std::atomic<bool>* cancel = current_cancel_flag();
  auto worker = [&] {
    CancelScope scope(cancel);
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        throw_if_cancelled();
        work(i);
        if (after_each) {
          std::lock_guard<std::mutex> g(lock);
          after_each(i);
        }
      } catch (...) {
        std::lock_guard<std::mutex> g(lock);
        if (!failure) failure = std::current_exception();
        next = n;  // stop handing out work
      }
    }
  };
  const int t = std::min<int>(thread_count(threads), static_cast<int>(std::max<std::size_t>(n, 1)));
  std::vector<std::thread> pool;
  for (int k = 1; k < t; ++k) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace vrelab::core
