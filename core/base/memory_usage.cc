#include "core/base/memory_usage.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <cstdio>
#include <cstring>

namespace reconar {

MemoryUsage CurrentMemoryUsage() {
  MemoryUsage usage;
  std::FILE* file = std::fopen("/proc/self/status", "r");
  if (file == nullptr) return usage;
  char line[256];
  bool rss = false, hwm = false;
  while (std::fgets(line, sizeof(line), file) != nullptr) {
    unsigned long long kib = 0;
    if (std::sscanf(line, "VmRSS: %llu kB", &kib) == 1) {
      usage.resident_bytes = static_cast<size_t>(kib) * 1024;
      rss = true;
    } else if (std::sscanf(line, "VmHWM: %llu kB", &kib) == 1) {
      usage.peak_resident_bytes = static_cast<size_t>(kib) * 1024;
      hwm = true;
    }
  }
  std::fclose(file);
  usage.known = rss && hwm;
  return usage;
}

size_t PeakResidentBytes() { return CurrentMemoryUsage().peak_resident_bytes; }

bool ResetPeakResidentBytes() {
  std::FILE* file = std::fopen("/proc/self/clear_refs", "w");
  if (file == nullptr) return false;
  const bool written = std::fputs("5", file) >= 0;
  const bool closed = std::fclose(file) == 0;  // the write reaches the kernel at close
  return written && closed;
}

void ReleaseFreeHeapMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

}  // namespace reconar
