#pragma once
// A small fixed thread pool. ParallelFor splits [begin, end) into chunks taken dynamically,
// so uneven work (images of different sizes, pairs with different match counts) balances.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <queue>
#include <thread>
#include <vector>

namespace reconar {

class ThreadPool {
 public:
  // num_threads <= 0 means one per hardware core.
  explicit ThreadPool(int num_threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Runs fn(i, worker_index) for every i in [begin, end); blocks until all are done.
  // worker_index is in [0, num_threads()) and lets callers keep per-worker scratch (arenas).
  // The calling thread takes part as worker 0.
  void ParallelFor(size_t begin, size_t end, const std::function<void(size_t, int)>& fn);

  static int ResolveThreadCount(int requested);

 private:
  void WorkerLoop(int worker_index);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable work_ready_;
  std::condition_variable work_done_;
  const std::function<void(size_t, int)>* job_ = nullptr;
  size_t next_ = 0;
  size_t end_ = 0;
  size_t generation_ = 0;
  int active_ = 0;
  bool stop_ = false;
};

}  // namespace reconar
