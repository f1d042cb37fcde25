// core/mpi.cpp -- core::dispatch across MPI ranks (core/mpi.hpp; docs/mpi.md).
//
// Protocol, one dispatch: every rank sends rank 0 its threads (MPI_Gather). Thread k of a
// worker rank asks rank 0 for an item (an "ask" message naming k) and waits for the reply on
// its own tag (kTagReply + k): an item index or "stop". When it starts an item it asks for
// the next one at once, computes, sends the result (or its failure; no reply to that), and
// only then waits for the reply to its ask, which has usually long arrived: the round trip
// is hidden behind the item (one ask in flight per thread). Every MPI call of a rank is made
// under the rank's lock (MPI_THREAD_SERIALIZED is enough); waits poll with MPI_Test and
// short sleeps. Rank 0's main thread coordinates: it polls for messages (MPI_Iprobe,
// sleeping 20-250 us when idle: a blocking receive spins a core in Open MPI, a core rank 0's
// own compute threads need), calls on_result under the lock, and answers asks with the next
// item; rank 0's threads take items from the same queue. The dispatch ends when every remote
// thread has been told to stop and every item handed out has come back; after a failure no
// more items are handed out and the failure is rethrown on rank 0.
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
enum Status : std::int32_t { kAsk = 0, kResult = 1, kFailure = 2 };
constexpr std::int64_t kStop = -1;
constexpr std::size_t kHeader = 16;  // item (8), status (4), the asking thread (4)

std::string message(std::int64_t item, Status status, std::int32_t thread, const std::string& payload) {
  std::string m(kHeader + payload.size(), '\0');
  std::memcpy(m.data(), &item, 8);
  const std::int32_t s = status;
  std::memcpy(m.data() + 8, &s, 4);
  std::memcpy(m.data() + 12, &thread, 4);
  std::memcpy(m.data() + kHeader, payload.data(), payload.size());
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
    std::mutex mpi;  // every MPI call of this rank
    auto thread = [&](std::int32_t k) {
      const int tag = kTagReply + k;
      std::int64_t next = kStop;
      MPI_Request reply = MPI_REQUEST_NULL;
      auto ask = [&] {  // posts the receive of the reply, then the ask
        std::lock_guard<std::mutex> g(mpi);
        check(MPI_Irecv(&next, 8, MPI_BYTE, 0, tag, MPI_COMM_WORLD, &reply), "MPI_Irecv");
        const std::string m = message(kStop, kAsk, k, std::string());
        check(MPI_Send(m.data(), static_cast<int>(m.size()), MPI_BYTE, 0, kTagRequest, MPI_COMM_WORLD), "MPI_Send");
      };
      auto await_reply = [&] {  // without spinning (a blocking receive takes a core from the threads computing)
        for (int done = 0, wait_us = 0;;) {
          {
            std::lock_guard<std::mutex> g(mpi);
            check(MPI_Test(&reply, &done, MPI_STATUS_IGNORE), "MPI_Test");
          }
          if (done) return next;
          wait_us = wait_us == 0 ? 10 : std::min(wait_us * 2, 250);
          std::this_thread::sleep_for(std::chrono::microseconds(wait_us));
        }
      };
      ask();
      for (std::int64_t item = await_reply(); item != kStop;) {
        ask();  // the next one, while this one computes
        std::string payload;
        Status status = kResult;
        try {
          payload = work(static_cast<std::size_t>(item));
        } catch (const std::exception& e) {
          payload = e.what(), status = kFailure;
        } catch (...) {
          payload = "an exception that is not a std::exception", status = kFailure;
        }
        {
          std::lock_guard<std::mutex> g(mpi);
          const std::string m = message(item, status, k, payload);
          check(MPI_Send(m.data(), static_cast<int>(m.size()), MPI_BYTE, 0, kTagRequest, MPI_COMM_WORLD), "MPI_Send");
        }
        item = await_reply();
      }
    };
    std::vector<std::thread> pool;
    for (int k = 1; k < t; ++k) pool.emplace_back(thread, static_cast<std::int32_t>(k));
    thread(0);
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
    long messages = 0, remote_results = 0, stopped = 0, outstanding = 0;
    std::vector<long> per_rank(static_cast<std::size_t>(ranks_), 0);
    int idle_us = 0;
    std::string buffer;
    std::exception_ptr coordinator_failure;
    try {
      while (stopped < remote || outstanding > 0) {
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
        if (static_cast<std::size_t>(size) < kHeader) throw std::runtime_error("MPI: a message too short");
        std::int64_t item = 0;
        std::int32_t status = 0, asker = 0;
        std::memcpy(&item, buffer.data(), 8);
        std::memcpy(&status, buffer.data() + 8, 4);
        std::memcpy(&asker, buffer.data() + 12, 4);
        std::int64_t reply = kStop;
        {
          std::lock_guard<std::mutex> g(lock);
          if (status == kResult) {
            ++remote_results, --outstanding;
            ++per_rank[static_cast<std::size_t>(st.MPI_SOURCE)];
            try {
              on_result(static_cast<std::size_t>(item), buffer.substr(kHeader));
            } catch (const std::exception& e) {
              fail("rank 0, writing item " + std::to_string(item) + ": " + e.what());
            }
          } else if (status == kFailure) {
            --outstanding;
            fail("rank " + std::to_string(st.MPI_SOURCE) + ", item " + std::to_string(item) + ": " + buffer.substr(kHeader));
          } else if (!take(&reply)) {
            reply = kStop;
          }
        }
        if (status == kAsk) {
          check(MPI_Send(&reply, 8, MPI_BYTE, st.MPI_SOURCE, kTagReply + asker, MPI_COMM_WORLD), "MPI_Send");
          if (reply == kStop)
            ++stopped;
          else
            ++outstanding;
        }
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
    if (std::getenv("VRELAB_MPI_STATS")) {
      std::string share;
      for (int r = 1; r < ranks_; ++r) share.append(" ").append(std::to_string(per_rank[static_cast<std::size_t>(r)]));
      std::fprintf(stderr,
                   "vrelab: mpi: %zu items on %d ranks (%ld remote results; ranks 1..: %s); rank 0 coordinating: "
                   "%ld messages, %.6f s busy, %.0f messages/s\n",
                   items.size(), ranks_, remote_results, share.c_str() + (share.empty() ? 0 : 1), messages, busy_s,
                   busy_s > 0 ? messages / busy_s : 0.0);
    }
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
