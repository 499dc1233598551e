#pragma once
// Minimal command-line parsing for the reconar subcommands: positionals, "--name value" options
// and "--flag" switches, each declared up front so that unknown options are usage errors.
#include <map>
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

 private:
  std::set<std::string> valued_, flags_;
  std::vector<std::string> positionals_;
  std::map<std::string, std::string> values_;
};

// The file name's extension in lower case, dot included ("sheet.PDF" -> ".pdf"); "" without one.
std::string LowercaseExtension(const std::string& path);

// Exit codes (DESIGN.md): 0 ok, 1 failed run, 2 bad usage or input.
int ExitCodeFor(const Status& status);
int Fail(const Status& status);  // prints "reconar: error: ..." and returns the exit code

}  // namespace reconar::tools
