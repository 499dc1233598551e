#include "core/base/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace reconar {

namespace {

std::string ErrnoText(int err) { return std::strerror(err); }

// The pid of a "<name>.tmp-<pid>" file name, or -1.
long TemporaryFilePid(const std::string& name) {
  const size_t at = name.rfind(".tmp-");
  if (at == std::string::npos || at + 5 == name.size()) return -1;
  long pid = 0;
  for (size_t i = at + 5; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9' || pid > (1L << 40)) return -1;
    pid = 10 * pid + (name[i] - '0');
  }
  return pid;
}

}  // namespace

Status WriteFileAtomically(const std::string& path, const std::function<Status(std::FILE*)>& writer) {
  const std::string temp_path = path + ".tmp-" + std::to_string(::getpid());
  std::FILE* file = std::fopen(temp_path.c_str(), "wb");
  if (file == nullptr) {
    return FileError(StatusCode::kIoError, path, "cannot create temporary file: " + ErrnoText(errno));
  }
  Status status = writer(file);
  if (status.ok() && std::ferror(file)) status = FileError(StatusCode::kIoError, path, "write failed");
  if (status.ok() && std::fflush(file) != 0) {
    status = FileError(StatusCode::kIoError, path, "write failed: " + ErrnoText(errno));
  }
  if (status.ok() && ::fsync(fileno(file)) != 0) {
    status = FileError(StatusCode::kIoError, path, "fsync failed: " + ErrnoText(errno));
  }
  if (std::fclose(file) != 0 && status.ok()) {
    status = FileError(StatusCode::kIoError, path, "close failed: " + ErrnoText(errno));
  }
  if (status.ok() && std::rename(temp_path.c_str(), path.c_str()) != 0) {
    status = FileError(StatusCode::kIoError, path, "rename failed: " + ErrnoText(errno));
  }
  if (!status.ok()) std::remove(temp_path.c_str());
  return status;
}

Status WriteFileAtomically(const std::string& path, std::string_view content) {
  return WriteFileAtomically(path, [&](std::FILE* file) {
    if (!content.empty() && std::fwrite(content.data(), 1, content.size(), file) != content.size()) {
      return FileError(StatusCode::kIoError, path, "write failed: " + ErrnoText(errno));
    }
    return Status::Ok();
  });
}

Result<std::string> ReadFileToString(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    const int err = errno;
    return FileError(err == ENOENT ? StatusCode::kNotFound : StatusCode::kIoError, path,
                     "cannot open: " + ErrnoText(err));
  }
  std::string content;
  char buffer[1 << 16];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), file)) > 0) content.append(buffer, n);
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return FileError(StatusCode::kIoError, path, "read failed");
  return content;
}

Status CreateDirectories(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) return FileError(StatusCode::kIoError, path, "cannot create directory: " + ec.message());
  return Status::Ok();
}

Result<int> RemoveStaleTemporaryFiles(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(dir, error)) return 0;
  int removed = 0;
  for (auto it = fs::recursive_directory_iterator(dir, error); !error && it != fs::recursive_directory_iterator();
       it.increment(error)) {
    if (!it->is_regular_file(error)) continue;
    const long pid = TemporaryFilePid(it->path().filename().string());
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    if (fs::remove(it->path(), error)) ++removed;
    if (error) return FileError(StatusCode::kIoError, it->path().string(), "cannot remove: " + error.message());
  }
  if (error) return FileError(StatusCode::kIoError, dir, "cannot list: " + error.message());
  return removed;
}

}  // namespace reconar
