#pragma once
// File names of a rendered capture's frames: "walk_07.png", "view_123.png". Test support only.
#include <algorithm>
#include <string>

namespace reconar::testing {

// prefix + index zero-padded to the digits of count - 1 (at least min_digits) + suffix, so that a
// plain string sort keeps the capture's order.
inline std::string NumberedName(const std::string& prefix, int index, int count, int min_digits,
                                const std::string& suffix) {
  const int digits = std::max(min_digits, static_cast<int>(std::to_string(std::max(0, count - 1)).size()));
  const std::string number = std::to_string(index);
  return prefix + std::string(static_cast<size_t>(std::max(0, digits - static_cast<int>(number.size()))), '0') +
         number + suffix;
}

}  // namespace reconar::testing
