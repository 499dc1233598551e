#include "core/base/thread_pool.h"

namespace reconar {

int ThreadPool::ResolveThreadCount(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

ThreadPool::ThreadPool(int num_threads) {
  const int total = ResolveThreadCount(num_threads);
  for (int i = 1; i < total; ++i) workers_.emplace_back([this, i] { WorkerLoop(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_ready_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::ParallelFor(size_t begin, size_t end, const std::function<void(size_t, int)>& fn) {
  if (begin >= end) return;
  if (workers_.empty()) {
    for (size_t i = begin; i < end; ++i) fn(i, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    next_ = begin;
    end_ = end;
    active_ = static_cast<int>(workers_.size());
    ++generation_;
  }
  work_ready_.notify_all();
  for (;;) {
    size_t i;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (next_ >= end_) break;
      i = next_++;
    }
    fn(i, 0);
  }
  std::unique_lock<std::mutex> lock(mutex_);
  work_done_.wait(lock, [this] { return active_ == 0; });
  job_ = nullptr;
}

void ThreadPool::WorkerLoop(int worker_index) {
  size_t seen_generation = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    work_ready_.wait(lock, [&] { return stop_ || generation_ != seen_generation; });
    if (stop_) return;
    seen_generation = generation_;
    while (next_ < end_) {
      const size_t i = next_++;
      const auto* job = job_;
      lock.unlock();
      (*job)(i, worker_index);
      lock.lock();
    }
    if (--active_ == 0) work_done_.notify_all();
  }
}

}  // namespace reconar
