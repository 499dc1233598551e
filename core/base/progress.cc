#include "core/base/progress.h"

#include <unistd.h>

#include <algorithm>

namespace reconar {

Progress::Progress(std::string label, size_t total, std::FILE* stream)
    : label_(std::move(label)), total_(total), terminal_(isatty(fileno(stream)) != 0), stream_(stream),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

Progress::~Progress() { Finish(); }

void Progress::Advance(size_t steps) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  done_ = std::min(total_, done_ + steps);
  Draw(false);
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  Draw(true);
}

void Progress::Draw(bool final_line) {
  const double fraction = total_ == 0 ? 1.0 : static_cast<double>(done_) / static_cast<double>(total_);
  const auto now = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(now - start_).count();
  if (terminal_) {
    if (!final_line && now - last_draw_ < std::chrono::milliseconds(100) && done_ != total_) return;
    last_draw_ = now;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::string bar(static_cast<size_t>(filled), '#');
    bar.resize(kWidth, '.');
    std::fprintf(stream_, "\r%s [%s] %zu/%zu %5.1fs%s", label_.c_str(), bar.c_str(), done_, total_, seconds,
                 final_line ? "\n" : "");
  } else {
    const int decile = static_cast<int>(fraction * 10.0);
    if (!final_line && decile == last_decile_) return;
    if (final_line && decile == last_decile_ && done_ == total_) {
      std::fprintf(stream_, "%s: done in %.1fs\n", label_.c_str(), seconds);
    } else {
      last_decile_ = decile;
      std::fprintf(stream_, "%s: %zu/%zu (%d%%) %.1fs\n", label_.c_str(), done_, total_,
                   static_cast<int>(fraction * 100.0), seconds);
    }
  }
  std::fflush(stream_);
}

}  // namespace reconar
