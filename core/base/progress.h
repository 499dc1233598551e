#pragma once
// Progress of a long stage: a redrawn bar when the stream is a terminal, plain lines
// ("features: 3/16 (18%)") at every 10 % otherwise, so CI logs stay short. Thread-safe.
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace reconar {

class Progress {
 public:
  Progress(std::string label, size_t total, std::FILE* stream = stderr);
  ~Progress();
  void Advance(size_t steps = 1);
  void Finish();

  // Exposed for tests: whether the bar form is used.
  bool is_terminal() const { return terminal_; }

 private:
  void Draw(bool final_line);

  std::string label_;
  size_t total_;
  size_t done_ = 0;
  int last_decile_ = -1;
  bool finished_ = false;
  bool terminal_;
  std::FILE* stream_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace reconar
