#include "tofguard/common/worker_pool.hpp"

#include "tofguard/common/demand.hpp"

namespace tofguard {

WorkerPool::WorkerPool(int num_threads) {
  TOFGUARD_DEMAND(num_threads >= 1,
                  "WorkerPool: num_threads must be >= 1, got " + std::to_string(num_threads));
  workers_.reserve(static_cast<size_t>(num_threads - 1));
  for (int i = 1; i < num_threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (std::thread& t : workers_) t.join();
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
// caller has run out of tasks (the other core was busy) goes back to sleep
// without touching the call, and the caller does not wait for it.
void WorkerPool::worker_loop() {
  uint64_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    start_.wait(lock, [&] { return stopping_ || (open_ && generation_ != seen); });
    if (stopping_) return;
    seen = generation_;
    ++active_workers_;
    lock.unlock();
    work();
    lock.lock();
    if (--active_workers_ == 0) done_.notify_one();
  }
}

void WorkerPool::run_erased(int num_tasks, Call call, const void* task) {
  if (num_tasks <= 0) return;
  if (workers_.empty() || num_tasks == 1) {
    for (int i = 0; i < num_tasks; ++i) call(task, i);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    call_ = call;
    task_ = task;
    num_tasks_ = num_tasks;
    next_task_.store(0);
    error_ = nullptr;
    open_ = true;
    ++generation_;
  }
  start_.notify_all();
  work();
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    open_ = false;
    done_.wait(lock, [&] { return active_workers_ == 0; });
    error = error_;
    error_ = nullptr;
    call_ = nullptr;
    task_ = nullptr;
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace tofguard
