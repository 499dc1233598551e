#include "tools/args.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>

namespace reconar::tools {

Args::Args(std::set<std::string> valued, std::set<std::string> flags)
    : valued_(std::move(valued)), flags_(std::move(flags)) {
  flags_.insert("help");
}

Status Args::Parse(int argc, char** argv, int first) {
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "-h") arg = "--help";
    if (arg.rfind("--", 0) != 0 || arg.size() == 2) {
      positionals_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2);
    std::string value;
    const size_t eq = name.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    if (flags_.count(name) != 0) {
      if (inline_value) return InvalidArgument("option --" + name + " takes no value");
      values_[name] = "1";
    } else if (valued_.count(name) != 0) {
      if (!inline_value) {
        if (i + 1 >= argc) return InvalidArgument("option --" + name + " needs a value");
        value = argv[++i];
      }
      values_[name] = value;
    } else {
      return InvalidArgument("unknown option --" + name + " (see --help)");
    }
  }
  return Status::Ok();
}

std::string Args::Get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

Result<int> Args::GetInt(const std::string& name, int fallback, int min, int max) const {
  if (!Has(name)) return fallback;
  const std::string text = Get(name);
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || value < min || value > max) {
    return InvalidArgument("--" + name + " expects an integer in [" + std::to_string(min) + ", " +
                           std::to_string(max) + "], got '" + text + "'");
  }
  return static_cast<int>(value);
}

Result<double> Args::GetDouble(const std::string& name, double fallback, double min, double max) const {
  if (!Has(name)) return fallback;
  const std::string text = Get(name);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(value >= min && value <= max)) {
    return InvalidArgument("--" + name + " expects a number in [" + std::to_string(min) + ", " +
                           std::to_string(max) + "], got '" + text + "'");
  }
  return value;
}

Result<size_t> Args::GetMemoryBudget(size_t fallback) const {
  if (!Has("memory-budget")) return fallback;
  const std::string text = Get("memory-budget");
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  const std::string unit = end;
  double mib = value;
  if (unit == "G" || unit == "g" || unit == "GiB" || unit == "GB") {
    mib = value * 1024.0;
  } else if (unit == "K" || unit == "k" || unit == "KiB" || unit == "KB") {
    mib = value / 1024.0;
  } else if (!(unit.empty() || unit == "M" || unit == "m" || unit == "MiB" || unit == "MB")) {
    return InvalidArgument("--memory-budget: '" + text + "' is not a size (MiB, or a number with K, M or G)");
  }
  if (text.empty() || end == text.c_str() || !(mib >= 1.0) || mib > 1e7) {
    return InvalidArgument("--memory-budget must be a size of at least 1M, got '" + text + "'");
  }
  return static_cast<size_t>(mib * (1 << 20));
}

Result<int> Args::GetThreads() const { return GetInt("threads", 0, 0, 1024); }

Result<std::vector<int>> Args::GetIdList(const std::string& name) const {
  std::set<int> ids;
  for (const std::string& part : SplitCommas(Get(name))) {
    const size_t dash = part.find('-', 1);
    const std::string first = part.substr(0, dash), last = dash == std::string::npos ? first : part.substr(dash + 1);
    char* end_first = nullptr;
    char* end_last = nullptr;
    const long from = std::strtol(first.c_str(), &end_first, 10);
    const long to = std::strtol(last.c_str(), &end_last, 10);
    if (first.empty() || last.empty() || *end_first != '\0' || *end_last != '\0' || from < 0 || to < from ||
        to > (1 << 20)) {
      return InvalidArgument("--" + name + ": '" + part + "' is not an id or a range of ids (e.g. 0-9,12)");
    }
    for (long id = from; id <= to; ++id) ids.insert(static_cast<int>(id));
  }
  return std::vector<int>(ids.begin(), ids.end());
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    if (comma > start) parts.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return parts;
}

std::string LowercaseExtension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string extension = path.substr(dot);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

int ExitCodeFor(const Status& status) {
  switch (status.code()) {
    case StatusCode::kOk: return 0;
    case StatusCode::kInvalidArgument:
    case StatusCode::kNotFound:
    case StatusCode::kCorruptData:
    case StatusCode::kUnsupported: return 2;
    default: return 1;
  }
}

int Fail(const Status& status) {
  std::fprintf(stderr, "reconar: error: %s\n", status.ToString().c_str());
  return ExitCodeFor(status);
}

int UsageError(const std::string& help) {
  std::fputs(help.c_str(), stderr);
  return 2;
}

std::optional<int> ParseCommand(Args* args, int argc, char** argv, int first, const std::string& help,
                                const CommandUsage& usage) {
  if (Status s = args->Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args->Has("help")) {
    std::fputs(help.c_str(), stdout);
    return 0;
  }
  const size_t count = args->positionals().size();
  bool right = count >= usage.min_positionals && count <= usage.max_positionals;
  for (const std::string& option : usage.required) right = right && args->Has(option);
  if (!right || (usage.rule != nullptr && !usage.rule(*args))) return UsageError(help);
  return std::nullopt;
}

std::optional<int> ParseCommand(Args* args, int argc, char** argv, int first, const char* help,
                                size_t min_positionals, size_t max_positionals) {
  CommandUsage usage;
  usage.min_positionals = min_positionals;
  usage.max_positionals = max_positionals;
  return ParseCommand(args, argc, argv, first, help, usage);
}

}  // namespace reconar::tools
