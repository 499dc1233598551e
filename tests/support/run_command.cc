#include "tests/support/run_command.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace reconar::testing {

std::string MakeTestDirectory(const std::string& prefix) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()));
  // Emptied first: a directory left by an earlier run whose process had the same id (CI's
  // LocalizeRoom failed on a stale symlink there).
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string SharedProjectDirectory(const std::string& name, const std::string& binary) {
  namespace fs = std::filesystem;
  const auto stamp = fs::last_write_time(binary).time_since_epoch().count();
  const std::string prefix = "reconar_shared_" + name + "_";
  const fs::path dir = fs::temp_directory_path() / (prefix + std::to_string(stamp));
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(fs::temp_directory_path(), error)) {
    const std::string other = entry.path().filename().string();
    if (other.rfind(prefix, 0) == 0 && entry.path() != dir) fs::remove_all(entry.path(), error);
  }
  fs::create_directories(dir);
  return dir.string();
}

std::string LinkFiles(const std::string& dir, const std::string& source_dir, const std::vector<std::string>& names) {
  std::filesystem::create_directories(dir);
  for (const std::string& name : names) {
    std::filesystem::create_symlink(std::filesystem::path(source_dir) / name, std::filesystem::path(dir) / name);
  }
  return dir;
}

CommandRun RunCommand(const std::string& command, StderrMode stderr_mode) {
  CommandRun run;
  std::string err_path;
  std::string shell_command = command;
  if (stderr_mode == StderrMode::kSeparate) {
    std::string path_template = (std::filesystem::temp_directory_path() / "reconar_stderr_XXXXXX").string();
    const int fd = mkstemp(path_template.data());
    if (fd < 0) return run;
    close(fd);
    err_path = path_template;
    shell_command += " 2>" + err_path;
  } else {
    shell_command += " 2>&1";
  }
  if (FILE* pipe = popen(shell_command.c_str(), "r")) {
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) run.output.append(buffer, n);
    const int status = pclose(pipe);
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  if (!err_path.empty()) {
    std::ifstream err(err_path, std::ios::binary);
    std::ostringstream text;
    text << err.rdbuf();
    run.error = text.str();
    std::remove(err_path.c_str());
  }
  return run;
}

int SpawnCommand(const std::string& command) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", ("exec " + command + " > /dev/null 2>&1").c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

}  // namespace reconar::testing
