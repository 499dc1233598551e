#pragma once
// Atomic file writes: the content goes to "<path>.tmp-<pid>" in the same directory, is flushed
// and fsync'ed, then renamed over <path>. A failure (full disk, permissions) removes the
// temporary and leaves any previous <path> untouched: readers never see a half file.
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

#include "core/base/status.h"

namespace reconar {

// `writer` writes to the FILE*; its Status (or a failed fwrite/fflush/fsync) aborts the write.
Status WriteFileAtomically(const std::string& path, const std::function<Status(std::FILE*)>& writer);
Status WriteFileAtomically(const std::string& path, std::string_view content);

// Removes the temporaries ("<name>.tmp-<pid>") that a process killed mid-write left anywhere
// below `dir`: those whose process no longer exists. Returns how many were removed; a missing
// `dir` removes none.
Result<int> RemoveStaleTemporaryFiles(const std::string& dir);

// Reads a whole file; errors name the file.
Result<std::string> ReadFileToString(const std::string& path);

// Creates a directory and its parents; ok if it already exists.
Status CreateDirectories(const std::string& path);

}  // namespace reconar
