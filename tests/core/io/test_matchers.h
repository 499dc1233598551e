#pragma once
// gmock is not available for every target we cross-build for, so the substring check is ours.
#include <gtest/gtest.h>

#include <string>

namespace reconar::testing {

inline ::testing::AssertionResult HasSubstring(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" does not contain \"" << part << "\"";
}

}  // namespace reconar::testing
