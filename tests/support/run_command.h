#pragma once
// Runs a shell command and captures its output and exit code: the tests of the `reconar`
// executable (tests/tools). Test support only.
#include <string>
#include <vector>

namespace reconar::testing {

struct CommandRun {
  int exit_code = -1;  // -1 when the command could not be started or did not exit normally
  std::string output;  // stdout; with StderrMode::kMerge also stderr, interleaved as written
  std::string error;   // stderr with StderrMode::kSeparate, else empty
};

enum class StderrMode {
  kMerge,     // 2>&1 into `output`
  kSeparate,  // into `error` (through a temporary file)
};

// A fresh directory "<gtest temp dir>/<prefix>_<pid>" (created with its parents) for a test's files.
std::string MakeTestDirectory(const std::string& prefix);

// A directory for one project that tests in several executables share (a heavy model two tests
// need): "<temp dir>/reconar_shared_<name>_<modification time of `binary`>", created if missing;
// the directories of other builds of `binary` are removed. Each build starts afresh, so no test
// reuses stages an older binary made. Runs on it wait for each other (the project's lock,
// core/pipeline/project_lock.h): the first test to get there makes the project, the others find
// its stages done. A test that changes the project works on a copy.
std::string SharedProjectDirectory(const std::string& name, const std::string& binary);

// `dir` (created with its parents) holding a symlink to source_dir/NAME for each of `names`
// (a subset of a dataset as a project's input); returns `dir`.
std::string LinkFiles(const std::string& dir, const std::string& source_dir, const std::vector<std::string>& names);

// `command` through /bin/sh (popen).
CommandRun RunCommand(const std::string& command, StderrMode stderr_mode = StderrMode::kMerge);

// Starts `command` through /bin/sh in a process of its own, its output discarded; returns its pid
// (for a test that kills it).
int SpawnCommand(const std::string& command);

#ifdef RECONAR_BINARY
// The reconar executable (RECONAR_BINARY, defined by the tests in tests/tools) with `arguments`.
inline CommandRun RunReconar(const std::string& arguments, StderrMode stderr_mode = StderrMode::kMerge) {
  return RunCommand(std::string(RECONAR_BINARY) + " " + arguments, stderr_mode);
}
#endif

}  // namespace reconar::testing
