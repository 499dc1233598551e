#pragma once
// The median of a set of numbers: the upper middle element for an even count (no averaging, so
// the result is one of the values), found by partial sorting in place.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace reconar {

// Reorders values[0, count); count must be positive.
template <typename T>
T MedianInPlace(T* values, size_t count) {
  T* middle = values + count / 2;
  std::nth_element(values, middle, values + count);
  return *middle;
}

// 0 for no values.
template <typename T>
T Median(std::vector<T> values) {
  return values.empty() ? T(0) : MedianInPlace(values.data(), values.size());
}

}  // namespace reconar
