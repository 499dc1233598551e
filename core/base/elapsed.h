#pragma once
// Seconds since a point of the steady clock: the timings that reports carry.
#include <chrono>

namespace reconar {

inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace reconar
