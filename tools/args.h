#pragma once
// Minimal command-line parsing for the reconar subcommands: positionals, "--name value" options
// and "--flag" switches, each declared up front so that unknown options are usage errors.
// The options several commands share mean the same everywhere and are read here:
//   --memory-budget SIZE   GetMemoryBudget: a size with K, M or G (KiB, MiB, GiB; a plain number
//                          is MiB; at least 1M, the stages set their own minimum); default
//                          kDefaultMemoryBudgetBytes (2560M, core/pipeline/project.h)
//   --threads N            GetThreads: worker threads, 0 or absent: one per core
//   --json                 the command's result as JSON on stdout instead of its summary
//   --help, -h             the command's usage on stdout
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar::tools {

class Args {
 public:
  // `valued` options take a value, `flags` do not. "--help"/"-h" is always a flag.
  Args(std::set<std::string> valued, std::set<std::string> flags);
  Status Parse(int argc, char** argv, int first);

  const std::vector<std::string>& positionals() const { return positionals_; }
  bool Has(const std::string& name) const { return values_.count(name) != 0; }
  std::string Get(const std::string& name, const std::string& fallback = "") const;
  // InvalidArgument naming the option when the value is not a number in [min, max].
  Result<int> GetInt(const std::string& name, int fallback, int min, int max) const;
  Result<double> GetDouble(const std::string& name, double fallback, double min, double max) const;
  // --memory-budget in bytes (see above); `fallback` when absent.
  Result<size_t> GetMemoryBudget(size_t fallback) const;
  // --threads: 0 (one per core) when absent.
  Result<int> GetThreads() const;
  // A list of ids and ranges, "0-9,12": the ids in increasing order, each once; empty when absent.
  // InvalidArgument naming the option for anything else.
  Result<std::vector<int>> GetIdList(const std::string& name) const;

 private:
  std::set<std::string> valued_, flags_;
  std::vector<std::string> positionals_;
  std::map<std::string, std::string> values_;
};

// "a,b,,c" -> {"a", "b", "c"}.
std::vector<std::string> SplitCommas(const std::string& text);

// The file name's extension in lower case, dot included ("sheet.PDF" -> ".pdf"); "" without one.
std::string LowercaseExtension(const std::string& path);

// Exit codes (DESIGN.md): 0 ok, 1 failed run, 2 bad usage or input.
int ExitCodeFor(const Status& status);
int Fail(const Status& status);  // prints "reconar: error: ..." and returns the exit code

// When a command's usage is right, beyond what Args::Parse checks: the positional count, the
// options it cannot do without, and any further rule (e.g. "--model or --project, not both").
struct CommandUsage {
  size_t min_positionals = 0;
  size_t max_positionals = SIZE_MAX;
  std::vector<std::string> required;          // options that must be given
  bool (*rule)(const Args& args) = nullptr;  // nullptr: none
};

// The start of every command: parses; with --help prints `help` on stdout (exit code 0); with a
// parse error prints it, and with a usage that breaks `usage` prints `help` on stderr (exit code
// 2). Returns the exit code to stop with, or nullopt to go on.
std::optional<int> ParseCommand(Args* args, int argc, char** argv, int first, const std::string& help,
                                const CommandUsage& usage);
// The same with only a positional count in [min_positionals, max_positionals].
std::optional<int> ParseCommand(Args* args, int argc, char** argv, int first, const char* help,
                                size_t min_positionals, size_t max_positionals);
// `help` on stderr, and the exit code of a usage error (2): for a usage a command can judge only
// later (match's images, once its options are read).
int UsageError(const std::string& help);

}  // namespace reconar::tools
