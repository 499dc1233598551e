#include "core/base/log.h"

#include <cstdio>

namespace reconar {

void Log(LogLevel level, const std::string& message) {
  const char* prefix = level == LogLevel::kInfo ? "" : level == LogLevel::kWarning ? "warning: " : "error: ";
  std::fprintf(stderr, "%s%s\n", prefix, message.c_str());
}

}  // namespace reconar
