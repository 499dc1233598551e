#pragma once
// Plain stderr logging for the command-line tools and long stages. No global state beyond stderr.
#include <string>

namespace reconar {

enum class LogLevel { kInfo, kWarning, kError };

void Log(LogLevel level, const std::string& message);
inline void LogInfo(const std::string& message) { Log(LogLevel::kInfo, message); }
inline void LogWarning(const std::string& message) { Log(LogLevel::kWarning, message); }
inline void LogError(const std::string& message) { Log(LogLevel::kError, message); }

}  // namespace reconar
