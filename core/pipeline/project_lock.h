#pragma once
// One run writes a project at a time. A run holds PROJECT/.lock (flock) while it works; the kernel
// lets go of it when the process ends, however it ends, so a killed run leaves no stale lock. A
// second run on the same project waits for the first to finish and then finds its stages done.
// Within one process the hold is shared: a stage that locks inside a run that holds the lock
// already goes on at once.
#include <functional>
#include <string>

#include "core/base/status.h"
#include "core/pipeline/project.h"

namespace reconar {

class ProjectLock {
 public:
  // Waits for the project (an existing directory) to be free. `on_wait` is called once,
  // before waiting, when another process holds it.
  static Result<ProjectLock> Acquire(const std::string& project_root, const std::function<void()>& on_wait = {});

  ProjectLock(ProjectLock&& other) noexcept : key_(std::move(other.key_)) { other.key_.clear(); }
  ProjectLock& operator=(ProjectLock&&) = delete;
  ProjectLock(const ProjectLock&) = delete;
  ProjectLock& operator=(const ProjectLock&) = delete;
  ~ProjectLock();

 private:
  explicit ProjectLock(std::string key) : key_(std::move(key)) {}
  std::string key_;  // the lock file's canonical path; empty once moved from
};

// The project's lock for a run of a stage or of the pipeline; while another process holds it, says
// so on stderr and waits.
Result<ProjectLock> LockProject(const Project& project);

}  // namespace reconar
