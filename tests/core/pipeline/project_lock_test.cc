// ProjectLock: one process writes a project at a time; a second waits; a killed holder leaves no
// stale lock; nested holds in one process go on at once.
#include "core/pipeline/project_lock.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>

#include "tests/support/run_command.h"

namespace reconar {
namespace {

// A child process that holds the lock for `hold_seconds` (or until killed); returns its pid once
// it holds it, -1 when it could not take it.
pid_t HoldInChild(const std::string& root, double hold_seconds) {
  int ready[2];
  if (::pipe(ready) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    Result<ProjectLock> lock = ProjectLock::Acquire(root);
    const char byte = lock.ok() ? 1 : 0;
    if (::write(ready[1], &byte, 1) != 1) ::_exit(2);
    ::usleep(static_cast<useconds_t>(hold_seconds * 1e6));
    ::_exit(0);
  }
  char byte = 0;
  const bool held = pid > 0 && ::read(ready[0], &byte, 1) == 1 && byte == 1;
  ::close(ready[0]);
  ::close(ready[1]);
  return held ? pid : -1;
}

TEST(ProjectLock, ASecondProcessWaitsForTheFirstToFinish) {
  const std::string root = testing::MakeTestDirectory("project_lock_wait");
  const pid_t child = HoldInChild(root, 0.5);
  ASSERT_GT(child, 0) << "the child could not take the lock";
  int waits = 0;
  const auto start = std::chrono::steady_clock::now();
  Result<ProjectLock> lock = ProjectLock::Acquire(root, [&] { ++waits; });
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(lock.ok()) << lock.status().ToString();
  EXPECT_EQ(waits, 1);
  EXPECT_GT(waited, 0.2);
  int status = 0;
  ::waitpid(child, &status, 0);
}

TEST(ProjectLock, AKilledHolderLeavesNoStaleLock) {
  const std::string root = testing::MakeTestDirectory("project_lock_killed");
  const pid_t child = HoldInChild(root, 60.0);
  ASSERT_GT(child, 0) << "the child could not take the lock";
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  int waits = 0;
  Result<ProjectLock> lock = ProjectLock::Acquire(root, [&] { ++waits; });
  ASSERT_TRUE(lock.ok()) << lock.status().ToString();
  EXPECT_EQ(waits, 0);
}

// A child forked before the lock is taken (a fork shares the parent's open lock), told by `go` when
// to try: exits 3 when it had to wait, 0 when it took the lock at once.
pid_t TryInChild(const std::string& root, int go) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  char byte = 0;
  if (::read(go, &byte, 1) != 1) ::_exit(2);
  Result<ProjectLock> lock = ProjectLock::Acquire(root, [] { ::_exit(3); });
  ::_exit(lock.ok() ? 0 : 1);
}

int ExitCode(pid_t child) {
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ProjectLock, ANestedHoldInOneProcessGoesOnAtOnceAndTheLastReleases) {
  const std::string root = testing::MakeTestDirectory("project_lock_nested");
  int go[2];
  ASSERT_EQ(::pipe(go), 0);
  const pid_t while_held = TryInChild(root, go[0]);
  int waits = 0;
  {
    Result<ProjectLock> outer = ProjectLock::Acquire(root, [&] { ++waits; });
    ASSERT_TRUE(outer.ok()) << outer.status().ToString();
    {
      Result<ProjectLock> inner = ProjectLock::Acquire(root + "/.", [&] { ++waits; });
      ASSERT_TRUE(inner.ok()) << inner.status().ToString();
    }
    // Still held by `outer`: another process has to wait.
    ASSERT_EQ(::write(go[1], "x", 1), 1);
    EXPECT_EQ(ExitCode(while_held), 3) << "the other process did not have to wait";
  }
  EXPECT_EQ(waits, 0);
  const pid_t after = TryInChild(root, go[0]);
  ASSERT_EQ(::write(go[1], "x", 1), 1);
  EXPECT_EQ(ExitCode(after), 0) << "the lock was not released";
  ::close(go[0]);
  ::close(go[1]);
}

TEST(ProjectLock, AMissingDirectoryIsNotFound) {
  const std::string root = testing::MakeTestDirectory("project_lock_missing") + "/no_such_project";
  Result<ProjectLock> lock = ProjectLock::Acquire(root);
  ASSERT_FALSE(lock.ok());
  EXPECT_EQ(lock.status().code(), StatusCode::kNotFound);
  EXPECT_NE(lock.status().message().find(root), std::string::npos) << lock.status().ToString();
}

}  // namespace
}  // namespace reconar
