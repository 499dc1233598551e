#include "core/base/number_format.h"

#include <charconv>

namespace reconar {
namespace {

// 32 characters hold the longest shortest form of a double ("-2.2250738585072014e-308" is 24).
template <typename T>
void AppendShortestImpl(std::string* out, T value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

}  // namespace

void AppendShortest(std::string* out, double value) { AppendShortestImpl(out, value); }
void AppendShortest(std::string* out, float value) { AppendShortestImpl(out, value); }

std::string FormatShortest(double value) {
  std::string text;
  AppendShortest(&text, value);
  return text;
}

std::string FormatShortest(float value) {
  std::string text;
  AppendShortest(&text, value);
  return text;
}

}  // namespace reconar
