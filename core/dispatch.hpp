#pragma once
// core/dispatch.hpp -- independent items whose results are text, run on this process's
// threads or, when the program runs under mpirun with more than one rank, on every rank
// (docs/mpi.md). The sweeps, the blind benchmark, the Monte Carlo of identify and the
// diagnosis of many campaigns go through it.
//
// Takes: the item indices in the order to hand them out (the longest first pays), the
//        threads per process (0: all cores without MPI, one per rank under MPI), work(i)
//        returning item i's result serialised as a string, and on_result(i, text).
// Gives: on_result called once per item, on rank 0 only, under one lock, in order of
//        completion; never on the other ranks. An item's result must depend on its index
//        alone (its seed from i), so it is the same whatever the ranks and threads. An
//        exception thrown by work(i) ends the call with it (rethrown on rank 0 naming the
//        rank and the item under MPI) after the items under way have finished; items that
//        can fail on their own should catch and serialise their failure.
//
// The library never starts MPI: the program installs a Distributor (core/mpi.hpp) when it
// was launched by mpirun; without one every call runs on threads (core::parallel_for).
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/parallel.hpp"

namespace vrelab::core {

using ItemWork = std::function<std::string(std::size_t)>;
using ItemResult = std::function<void(std::size_t, const std::string&)>;

// Items handed out across processes. ranks() and rank() are those of the job.
class Distributor {
 public:
  virtual ~Distributor() = default;
  virtual int ranks() const = 0;
  virtual int rank() const = 0;
  // Every rank calls it at the same point; `items` matters on rank 0 only.
  virtual void run(const std::vector<std::size_t>& items, int threads, const ItemWork& work,
                   const ItemResult& on_result) = 0;
};

// The distributor of this program (nullptr: none, threads only).
inline Distributor*& current_distributor() {
  static Distributor* d = nullptr;
  return d;
}

// The processes of this job (1 without MPI) and this one's rank (0 without MPI).
inline int process_count() { return current_distributor() ? current_distributor()->ranks() : 1; }
inline int process_rank() { return current_distributor() ? current_distributor()->rank() : 0; }
// Only rank 0 writes files and prints.
inline bool is_root_process() { return process_rank() == 0; }

// The threads per process a call with `requested` threads uses: as core::thread_count without
// MPI; under MPI with more than one rank, `requested` when positive, else 1 (one rank per core
// is how mpirun places them; every rank taking every core would oversubscribe the node).
inline int threads_per_process(int requested) {
  if (process_count() > 1) return requested > 0 ? requested : 1;
  return thread_count(requested);
}

inline void dispatch(const std::vector<std::size_t>& items, int threads, const ItemWork& work,
                     const ItemResult& on_result) {
  if (Distributor* d = current_distributor(); d && d->ranks() > 1) {
    d->run(items, threads, work, on_result);
    return;
  }
  std::vector<std::string> results(items.size());
  parallel_for(
      items.size(), threads, [&](std::size_t k) { results[k] = work(items[k]); },
      [&](std::size_t k) {
        on_result(items[k], results[k]);
        std::string().swap(results[k]);
      });
}

}  // namespace vrelab::core
