#include "tofguard/common/worker_pool.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "tofguard/common/demand.hpp"

namespace tofguard {

namespace {

// The CPUs the calling thread may run on; none when they cannot be read.
std::vector<int> allowed_cpus() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof(allowed), &allowed) != 0) return cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) cpus.push_back(cpu);
  }
  return cpus;
}

}  // namespace

int allowed_cpu_count() { return std::max(static_cast<int>(allowed_cpus().size()), 1); }

WorkerPool::WorkerPool(int num_threads, std::chrono::microseconds linger) : linger_(linger) {
  TOFGUARD_DEMAND(num_threads >= 1,
                  "WorkerPool: num_threads must be >= 1, got " + std::to_string(num_threads));
  TOFGUARD_DEMAND(linger.count() >= 0, "WorkerPool: linger must be >= 0 us, got " +
                                           std::to_string(static_cast<long long>(linger.count())));
  if (num_threads > 1) {
    std::vector<int> cpus = allowed_cpus();
    if (cpus.size() > 1) allowed_cpus_ = std::move(cpus);
  }
  workers_.reserve(static_cast<size_t>(num_threads - 1));
  for (int i = 1; i < num_threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    stopping_flag_.store(true);
  }
  start_.notify_all();
  for (std::thread& t : workers_) t.join();
}

int64_t WorkerPool::now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void WorkerPool::stay_awake(std::chrono::microseconds for_time) {
  const int64_t until = now_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(for_time).count();
  int64_t seen = awake_until_ns_.load();
  while (seen < until && !awake_until_ns_.compare_exchange_weak(seen, until)) {
  }
}

void WorkerPool::note_caller_cpu() {
  if (!allowed_cpus_.empty()) caller_cpu_.store(sched_getcpu());
}

void WorkerPool::keep_off_caller_cpu(int* excluded) const {
  const int caller = caller_cpu_.load();
  if (allowed_cpus_.empty() || caller < 0 || caller == *excluded) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int cpu : allowed_cpus_) {
    if (cpu != caller) CPU_SET(cpu, &set);
  }
  // A caller outside the allowed CPUs (its affinity changed since) leaves
  // them all: still a valid set. Failing, the worker runs where it is.
  if (CPU_COUNT(&set) == 0 || pthread_setaffinity_np(pthread_self(), sizeof(set), &set) != 0) return;
  *excluded = caller;
}

void WorkerPool::expect_call_within(std::chrono::microseconds within) {
  if (workers_.empty() || within.count() <= 0) return;
  note_caller_cpu();
  {
    // Under the lock: a worker between its wait's test and its sleep would
    // otherwise miss the notification.
    std::lock_guard<std::mutex> lock(mutex_);
    stay_awake(within);
  }
  start_.notify_all();
}

void WorkerPool::poll_for_call(uint64_t seen) const {
  while (open_generation_.load() == seen && !stopping_flag_.load() && now_ns() < awake_until_ns_.load())
    std::this_thread::yield();
}

void WorkerPool::work() {
  for (int i = next_task_.fetch_add(1); i < num_tasks_; i = next_task_.fetch_add(1)) {
    try {
      call_(task_, i);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
    }
  }
}

// A worker joins a call only while it is open: one that wakes after the
// caller has run out of tasks (the other core was busy) goes back to
// waiting without touching the call, and the caller does not wait for it.
// While it should be awake (after a call, or asked to), it waits by
// polling without the lock; else it sleeps on start_.
void WorkerPool::worker_loop() {
  uint64_t seen = 0;
  int excluded_cpu = -1;
  for (;;) {
    // (Off the caller's CPU outside the lock: a move is a system call.)
    keep_off_caller_cpu(&excluded_cpu);
    poll_for_call(seen);
    std::unique_lock<std::mutex> lock(mutex_);
    start_.wait(lock, [&] { return stopping_ || generation_ != seen || now_ns() < awake_until_ns_.load(); });
    if (stopping_) return;
    if (generation_ == seen) continue;  // asked to be awake: poll
    seen = generation_;
    if (!open_) continue;  // a call missed: it has ended
    active_workers_.fetch_add(1);
    lock.unlock();
    keep_off_caller_cpu(&excluded_cpu);
    work();
    lock.lock();
    if (active_workers_.fetch_sub(1) == 1) done_.notify_one();
    stay_awake(linger_);
  }
}

void WorkerPool::run_erased(int num_tasks, Call call, const void* task) {
  if (num_tasks <= 0) return;
  if (workers_.empty() || num_tasks == 1) {
    for (int i = 0; i < num_tasks; ++i) call(task, i);
    return;
  }
  note_caller_cpu();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    call_ = call;
    task_ = task;
    num_tasks_ = num_tasks;
    next_task_.store(0);
    error_ = nullptr;
    open_ = true;
    ++generation_;
    open_generation_.store(generation_);
  }
  start_.notify_all();
  work();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = false;
  }
  // The workers still in the call are finishing their last task: poll for
  // them as long as a worker lingers, then sleep.
  const int64_t poll_until = now_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(linger_).count();
  while (active_workers_.load() > 0 && now_ns() < poll_until) std::this_thread::yield();
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return active_workers_.load() == 0; });
    error = error_;
    error_ = nullptr;
    call_ = nullptr;
    task_ = nullptr;
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace tofguard
