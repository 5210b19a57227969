// WorkerPool (common/worker_pool.hpp): every task runs exactly once per
// call, on any number of threads, call after call; an exception comes back
// to the caller after the other tasks have finished. Also run under TSan
// (scripts/sanitize).
#include "tofguard/common/worker_pool.hpp"

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace tofguard {
namespace {

TEST(WorkerPool, RunsEveryTaskExactlyOncePerCall) {
  for (int threads : {1, 2, 4}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.num_threads(), threads);
    for (int num_tasks : {0, 1, 2, 3, 7, 64}) {
      // Many calls: a worker that woke late for one call must not run a
      // task of the next twice or leave one out.
      for (int call = 0; call < 200; ++call) {
        std::vector<int> runs(static_cast<size_t>(num_tasks), 0);
        pool.run(num_tasks, [&](int i) { runs[static_cast<size_t>(i)] += 1; });
        for (int i = 0; i < num_tasks; ++i)
          ASSERT_EQ(runs[static_cast<size_t>(i)], 1)
              << threads << " threads, task " << i << " of " << num_tasks;
      }
    }
  }
}

TEST(WorkerPool, SharesTheTasksAmongItsThreads) {
  WorkerPool pool(2);
  std::set<std::thread::id> seen;
  // Tasks that wait for each other can only finish on two threads at once.
  for (int attempt = 0; attempt < 50 && seen.size() < 2; ++attempt) {
    std::atomic<int> arrived{0};
    std::vector<std::thread::id> ran_on(2);
    pool.run(2, [&](int i) {
      ran_on[static_cast<size_t>(i)] = std::this_thread::get_id();
      arrived.fetch_add(1);
      // The first task to arrive waits a little for the other one (a
      // bounded spin: the worker may be slow to wake, then the caller runs
      // both, one after the other).
      for (int spin = 0; spin < 1000000 && arrived.load() < 2; ++spin) std::this_thread::yield();
    });
    seen.insert(ran_on.begin(), ran_on.end());
  }
  EXPECT_EQ(seen.size(), 2u);
}

// A worker keeps off the CPU its caller called from (worker_pool.hpp: on a
// VM the scheduler put a woken worker on the caller's core, and the two
// took turns on it). Checked on the worker's own CPU affinity, which is
// what keeps it off, after the caller has been pinned to one CPU.
TEST(WorkerPool, AWorkerKeepsOffTheCallersCpu) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ASSERT_EQ(sched_getaffinity(0, sizeof(allowed), &allowed), 0);
  if (CPU_COUNT(&allowed) < 2) GTEST_SKIP() << "this process may run on one CPU only: nothing to keep off";
  int caller_cpu = 0;
  while (!CPU_ISSET(caller_cpu, &allowed)) ++caller_cpu;
  // The pool reads the process's CPUs when it is made, before the caller
  // is pinned.
  WorkerPool pool(2);
  cpu_set_t pinned;
  CPU_ZERO(&pinned);
  CPU_SET(caller_cpu, &pinned);
  ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(pinned), &pinned), 0);
  int worker_tasks = 0;
  int worker_tasks_allowed_on_caller_cpu = 0;
  int worker_tasks_on_caller_cpu = 0;
  for (int attempt = 0; attempt < 50 && worker_tasks < 5; ++attempt) {
    pool.expect_call_within(std::chrono::milliseconds(10));
    std::atomic<int> arrived{0};
    const std::thread::id caller = std::this_thread::get_id();
    std::vector<int> on_worker(2, 0), allowed_on_caller_cpu(2, 0), on_caller_cpu(2, 0);
    pool.run(2, [&](int i) {
      const auto k = static_cast<size_t>(i);
      arrived.fetch_add(1);
      on_worker[k] = std::this_thread::get_id() != caller ? 1 : 0;
      cpu_set_t mine;
      CPU_ZERO(&mine);
      if (pthread_getaffinity_np(pthread_self(), sizeof(mine), &mine) == 0)
        allowed_on_caller_cpu[k] = CPU_ISSET(caller_cpu, &mine) ? 1 : 0;
      on_caller_cpu[k] = sched_getcpu() == caller_cpu ? 1 : 0;
      // As SharesTheTasksAmongItsThreads: the first task waits a little
      // for the other, so that both threads take one.
      for (int spin = 0; spin < 1000000 && arrived.load() < 2; ++spin) std::this_thread::yield();
    });
    for (size_t k = 0; k < 2; ++k) {
      if (!on_worker[k]) continue;  // the caller's own task
      ++worker_tasks;
      worker_tasks_allowed_on_caller_cpu += allowed_on_caller_cpu[k];
      worker_tasks_on_caller_cpu += on_caller_cpu[k];
    }
  }
  ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(allowed), &allowed), 0);
  ASSERT_GT(worker_tasks, 0) << "no task ran on the worker in 50 calls";
  EXPECT_EQ(worker_tasks_allowed_on_caller_cpu, 0) << "of " << worker_tasks << " worker tasks";
  EXPECT_EQ(worker_tasks_on_caller_cpu, 0) << "of " << worker_tasks << " worker tasks";
}

TEST(WorkerPool, ATaskExceptionReachesTheCallerAfterTheOtherTasks) {
  WorkerPool pool(3);
  std::vector<int> runs(16, 0);
  EXPECT_THROW(pool.run(16,
                        [&](int i) {
                          runs[static_cast<size_t>(i)] = 1;
                          if (i == 5) throw std::runtime_error("task 5");
                        }),
               std::runtime_error);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(runs[static_cast<size_t>(i)], 1) << i;
  // The pool still works.
  std::vector<int> again(4, 0);
  pool.run(4, [&](int i) { again[static_cast<size_t>(i)] = 1; });
  EXPECT_EQ(again, std::vector<int>(4, 1));
}

TEST(SideTask, RunsOnceBesideARunOrAfterIt) {
  WorkerPool pool(2);
  for (int call = 0; call < 100; ++call) {
    // Beside a run: task 0 runs it, the owner's run_once after the call
    // does nothing.
    int side_runs = 0;
    std::vector<int> runs(8, 0);
    SideTask side([&] { ++side_runs; });
    pool.run(9, [&](int i) {
      if (i == 0) {
        side.run_once();
      } else {
        runs[static_cast<size_t>(i - 1)] += 1;
      }
    });
    EXPECT_TRUE(side.done());
    side.run_once();
    ASSERT_EQ(side_runs, 1);
    for (int r : runs) ASSERT_EQ(r, 1);
  }
  // No run took it: the owner's run_once runs it, once.
  int side_runs = 0;
  SideTask side([&] { ++side_runs; });
  EXPECT_FALSE(side.done());
  side.run_once();
  side.run_once();
  EXPECT_EQ(side_runs, 1);
}

// Workers that sleep at once (linger 0), poll between the calls of a burst
// (the default), or poll for longer than the test runs: every task still
// runs once per call, also when the caller asks them to be awake for a
// call (expect_call_within) before some calls and a worker wakes into a
// call that has already ended.
TEST(WorkerPool, RunsEveryTaskOnceWhetherItsWorkersSleepOrPoll) {
  using std::chrono::microseconds;
  for (const microseconds linger : {microseconds(0), WorkerPool::kDefaultLinger, microseconds(200000)}) {
    WorkerPool pool(3, linger);
    for (int call = 0; call < 300; ++call) {
      if (call % 3 == 0) pool.expect_call_within(microseconds(call % 2 == 0 ? 1000 : 200000));
      const int num_tasks = 1 + call % 11;
      std::vector<int> runs(static_cast<size_t>(num_tasks), 0);
      pool.run(num_tasks, [&](int i) { runs[static_cast<size_t>(i)] += 1; });
      for (int i = 0; i < num_tasks; ++i)
        ASSERT_EQ(runs[static_cast<size_t>(i)], 1)
            << "linger " << linger.count() << " us, call " << call << ", task " << i << " of " << num_tasks;
    }
  }
}

// A pool whose workers were asked to poll for a minute stops when it is
// destroyed, not after the minute (the test would hang until ctest's
// timeout).
TEST(WorkerPool, AnAwakePoolStopsWithoutWaitingOutItsPoll) {
  auto pool = std::make_unique<WorkerPool>(2, std::chrono::seconds(60));
  pool->expect_call_within(std::chrono::seconds(60));
  int ran = 0;
  pool->run(1, [&](int) { ++ran; });
  pool.reset();
  EXPECT_EQ(ran, 1);
}

TEST(WorkerPool, RefusesNoThreads) { EXPECT_DEATH(WorkerPool(0), "num_threads"); }

TEST(WorkerPool, RefusesANegativeLinger) {
  EXPECT_DEATH(WorkerPool(2, std::chrono::microseconds(-1)), "linger");
}

}  // namespace
}  // namespace tofguard
