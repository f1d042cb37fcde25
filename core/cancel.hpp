#pragma once
// core/cancel.hpp -- stopping a long library call from outside it (Ctrl-C in the Python
// module): the caller owns a flag and makes it current for the thread that runs the call
// (CancelScope). core::parallel_for hands it on to its workers and checks it before each item;
// the ODE solver checks it at every output time. A set flag ends the call with core::Cancelled
// at the next check, before anything the call writes at its end. The CLI never sets one.
#include <atomic>

namespace vrelab::core {

// Deliberately not a std::exception: the places that record a run's failure and go on
// (catch (const std::exception&)) let a cancellation through to the caller.
struct Cancelled {};

// The flag current for this thread (nullptr: the call cannot be cancelled).
inline const std::atomic<bool>*& current_cancel_flag() {
  thread_local const std::atomic<bool>* flag = nullptr;
  return flag;
}

// Makes `flag` current for this thread while the scope lives.
class CancelScope {
 public:
  explicit CancelScope(const std::atomic<bool>* flag) : saved_(current_cancel_flag()) { current_cancel_flag() = flag; }
  ~CancelScope() { current_cancel_flag() = saved_; }
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  const std::atomic<bool>* saved_;
};

inline void throw_if_cancelled() {
  const std::atomic<bool>* flag = current_cancel_flag();
  if (flag && flag->load(std::memory_order_relaxed)) throw Cancelled();
}

}  // namespace vrelab::core
