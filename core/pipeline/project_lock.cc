#include "core/pipeline/project_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>

namespace reconar {
namespace {

struct Hold {
  int fd = -1;
  int holders = 0;
};

// The locks this process holds, by lock file: flock() conflicts between two descriptors of one
// process too, so a nested hold shares the first one's descriptor.
std::mutex& HoldsMutex() {
  static std::mutex mutex;
  return mutex;
}
std::map<std::string, Hold>& Holds() {
  static std::map<std::string, Hold> holds;
  return holds;
}

}  // namespace

Result<ProjectLock> ProjectLock::Acquire(const std::string& project_root, const std::function<void()>& on_wait) {
  std::error_code error;
  const std::string root = std::filesystem::canonical(project_root, error).string();
  if (error) return NotFound(project_root + ": no such project directory (" + error.message() + ")");
  const std::string path = root + "/.lock";
  std::lock_guard<std::mutex> guard(HoldsMutex());
  Hold& hold = Holds()[path];
  if (hold.holders > 0) {
    ++hold.holders;
    return ProjectLock(path);
  }
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    Holds().erase(path);
    return IoError(path + ": cannot open the project's lock: " + std::strerror(errno));
  }
  int result = ::flock(fd, LOCK_EX | LOCK_NB);
  if (result != 0 && errno == EWOULDBLOCK) {
    if (on_wait) on_wait();
    do {
      result = ::flock(fd, LOCK_EX);
    } while (result != 0 && errno == EINTR);
  }
  if (result != 0) {
    const int saved = errno;
    ::close(fd);
    Holds().erase(path);
    return IoError(path + ": cannot lock the project: " + std::strerror(saved));
  }
  hold.fd = fd;
  hold.holders = 1;
  return ProjectLock(path);
}

ProjectLock::~ProjectLock() {
  if (key_.empty()) return;
  std::lock_guard<std::mutex> guard(HoldsMutex());
  auto it = Holds().find(key_);
  if (it == Holds().end() || --it->second.holders > 0) return;
  ::close(it->second.fd);  // releases the flock
  Holds().erase(it);
}

Result<ProjectLock> LockProject(const Project& project) {
  return ProjectLock::Acquire(project.root(), [&] {
    std::fprintf(stderr, "reconar: %s is in use by another run; waiting for it to finish\n", project.root().c_str());
  });
}

}  // namespace reconar
