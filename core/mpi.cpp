// core/mpi.cpp -- core::dispatch across MPI ranks (core/mpi.hpp; docs/mpi.md).
//
// Protocol, one dispatch: every rank sends rank 0 its threads (MPI_Gather). Each thread of a
// worker rank then loops: under the rank's lock, send rank 0 a request (carrying its last
// result, or its failure) and receive the reply, an item index or "stop"; compute the item
// outside the lock (waiting with MPI_Test and short sleeps). One request per rank is outstanding at a time, so a reply always belongs
// to the thread that waits for it (MPI_THREAD_SERIALIZED is enough). Rank 0's main thread
// coordinates: it polls for requests (MPI_Iprobe, sleeping 20-250 us when idle: a blocking receive
// spins a core in Open MPI, a core rank 0's own compute threads need), calls on_result
// under the lock, and replies with the next item; rank 0's threads take items from the same
// queue. The dispatch ends when every remote thread has been told to stop; after a failure
// no more items are handed out and the failure is rethrown on rank 0.
#include "core/mpi.hpp"

#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace vrelab::core {
namespace {

constexpr int kTagRequest = 7101, kTagReply = 7102;
enum Status : std::int32_t { kHello = 0, kResult = 1, kFailure = 2 };
constexpr std::int64_t kStop = -1;

std::string message(std::int64_t item, Status status, const std::string& payload) {
  std::string m(12 + payload.size(), '\0');
  std::memcpy(m.data(), &item, 8);
  const std::int32_t s = status;
  std::memcpy(m.data() + 8, &s, 4);
  std::memcpy(m.data() + 12, payload.data(), payload.size());
  return m;
}

void check(int rc, const char* call) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + call + " failed");
}

class MpiDistributor final : public Distributor, public MpiJob {
 public:
  MpiDistributor(int rank, int ranks, bool serialized) : rank_(rank), ranks_(ranks), serialized_(serialized) {}
  ~MpiDistributor() override {
    if (current_distributor() == this) current_distributor() = nullptr;
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
  int ranks() const override { return ranks_; }
  int rank() const override { return rank_; }
  void abort(int code) override { MPI_Abort(MPI_COMM_WORLD, code); }

  void run(const std::vector<std::size_t>& items, int threads, const ItemWork& work,
           const ItemResult& on_result) override {
    // Worker ranks without MPI_THREAD_SERIALIZED use one thread (only it calls MPI).
    int t = threads_per_process(threads);
    if (!serialized_ && rank_ != 0) t = 1;
    // Rank 0 computes beside coordinating, unless VRELAB_MPI_ROOT_THREADS says how many of its
    // threads compute (0: it only coordinates; docs/mpi.md, beyond a few hundred ranks).
    if (const char* v = std::getenv("VRELAB_MPI_ROOT_THREADS"); v && rank_ == 0) t = std::max(0, std::atoi(v));
    std::vector<int> counts(static_cast<std::size_t>(ranks_), 0);
    check(MPI_Gather(&t, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Gather");
    if (rank_ == 0) {
      long remote = 0;
      for (int r = 1; r < ranks_; ++r) remote += counts[static_cast<std::size_t>(r)];
      coordinate(items, t, remote, work, on_result);
    } else {
      compute(t, work);
    }
  }

 private:
  // A worker rank: `t` threads asking rank 0 for items until told to stop.
  void compute(int t, const ItemWork& work) {
    std::mutex mpi;
    auto thread = [&] {
      std::int64_t item = kStop;
      Status status = kHello;
      std::string payload;
      for (;;) {
        std::int64_t next = kStop;
        {
          std::lock_guard<std::mutex> g(mpi);
          const std::string m = message(item, status, payload);
          check(MPI_Send(m.data(), static_cast<int>(m.size()), MPI_BYTE, 0, kTagRequest, MPI_COMM_WORLD), "MPI_Send");
          // Waits without spinning (a blocking receive would take a core from the threads
          // computing on an oversubscribed node).
          MPI_Request reply;
          check(MPI_Irecv(&next, 8, MPI_BYTE, 0, kTagReply, MPI_COMM_WORLD, &reply), "MPI_Irecv");
          for (int done = 0, wait_us = 0;;) {
            check(MPI_Test(&reply, &done, MPI_STATUS_IGNORE), "MPI_Test");
            if (done) break;
            wait_us = wait_us == 0 ? 10 : std::min(wait_us * 2, 250);
            std::this_thread::sleep_for(std::chrono::microseconds(wait_us));
          }
        }
        if (next == kStop) return;
        item = next;
        try {
          payload = work(static_cast<std::size_t>(next));
          status = kResult;
        } catch (const std::exception& e) {
          payload = e.what(), status = kFailure;
        } catch (...) {
          payload = "an exception that is not a std::exception", status = kFailure;
        }
      }
    };
    std::vector<std::thread> pool;
    for (int k = 1; k < t; ++k) pool.emplace_back(thread);
    thread();
    for (auto& th : pool) th.join();
  }

  // Rank 0: hands out `items` to its own `t` threads and to `remote` threads of the others.
  void coordinate(const std::vector<std::size_t>& items, int t, long remote, const ItemWork& work,
                  const ItemResult& on_result) {
    std::mutex lock;  // the queue, on_result, the failure
    std::size_t next = 0;
    bool failed = false;
    std::string failure;
    auto take = [&](std::int64_t* item) {  // under `lock`
      if (failed || next >= items.size()) return false;
      *item = static_cast<std::int64_t>(items[next++]);
      return true;
    };
    auto fail = [&](const std::string& what) {  // under `lock`
      if (!failed) failure = what;
      failed = true;
    };
    // Rank 0's own threads.
    std::vector<std::thread> pool;
    for (int k = 0; k < t; ++k)
      pool.emplace_back([&] {
        for (;;) {
          std::int64_t item = 0;
          {
            std::lock_guard<std::mutex> g(lock);
            if (!take(&item)) return;
          }
          try {
            const std::string r = work(static_cast<std::size_t>(item));
            std::lock_guard<std::mutex> g(lock);
            on_result(static_cast<std::size_t>(item), r);
          } catch (const std::exception& e) {
            std::lock_guard<std::mutex> g(lock);
            fail("rank 0, item " + std::to_string(item) + ": " + e.what());
          } catch (...) {
            std::lock_guard<std::mutex> g(lock);
            fail("rank 0, item " + std::to_string(item) + ": an exception that is not a std::exception");
          }
        }
      });
    // The coordinator: this thread.
    using Clock = std::chrono::steady_clock;
    double busy_s = 0;
    long messages = 0, remote_results = 0, stopped = 0;
    int idle_us = 0;
    std::string buffer;
    std::exception_ptr coordinator_failure;
    try {
      while (stopped < remote) {
        int flag = 0;
        MPI_Status st;
        check(MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &flag, &st), "MPI_Iprobe");
        if (!flag) {
          idle_us = idle_us == 0 ? 20 : std::min(idle_us * 2, 250);
          std::this_thread::sleep_for(std::chrono::microseconds(idle_us));
          continue;
        }
        idle_us = 0;
        const auto t0 = Clock::now();
        int size = 0;
        check(MPI_Get_count(&st, MPI_BYTE, &size), "MPI_Get_count");
        buffer.resize(static_cast<std::size_t>(size));
        check(MPI_Recv(buffer.data(), size, MPI_BYTE, st.MPI_SOURCE, kTagRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
              "MPI_Recv");
        std::int64_t item = 0;
        std::int32_t status = 0;
        std::memcpy(&item, buffer.data(), 8);
        std::memcpy(&status, buffer.data() + 8, 4);
        std::int64_t reply = kStop;
        {
          std::lock_guard<std::mutex> g(lock);
          if (status == kResult) {
            ++remote_results;
            try {
              on_result(static_cast<std::size_t>(item), buffer.substr(12));
            } catch (const std::exception& e) {
              fail("rank 0, writing item " + std::to_string(item) + ": " + e.what());
            }
          } else if (status == kFailure) {
            fail("rank " + std::to_string(st.MPI_SOURCE) + ", item " + std::to_string(item) + ": " + buffer.substr(12));
          }
          if (!take(&reply)) reply = kStop;
        }
        check(MPI_Send(&reply, 8, MPI_BYTE, st.MPI_SOURCE, kTagReply, MPI_COMM_WORLD), "MPI_Send");
        if (reply == kStop) ++stopped;
        ++messages;
        busy_s += std::chrono::duration<double>(Clock::now() - t0).count();
      }
    } catch (...) {
      coordinator_failure = std::current_exception();
      std::lock_guard<std::mutex> g(lock);
      failed = true;
    }
    for (auto& th : pool) th.join();
    if (coordinator_failure) std::rethrow_exception(coordinator_failure);
    if (std::getenv("VRELAB_MPI_STATS"))
      std::fprintf(stderr,
                   "vrelab: mpi: %zu items on %d ranks (%ld remote results); rank 0 coordinating: %ld messages, "
                   "%.6f s busy, %.0f messages/s\n",
                   items.size(), ranks_, remote_results, messages, busy_s, busy_s > 0 ? messages / busy_s : 0.0);
    if (failed) throw std::runtime_error(failure);
  }

  int rank_, ranks_;
  bool serialized_;
};

}  // namespace

bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

std::unique_ptr<MpiJob> start_mpi(int* argc, char*** argv) {
  if (!launched_by_mpirun()) return nullptr;
  int provided = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
    throw std::runtime_error("MPI_Init_thread failed");
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  auto job = std::make_unique<MpiDistributor>(rank, ranks, provided >= MPI_THREAD_SERIALIZED);
  current_distributor() = job.get();
  return job;
}

}  // namespace vrelab::core
