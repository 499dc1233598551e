#pragma once
// Memory use of this process as Linux reports it in /proc/self/status: the resident set (VmRSS)
// and its high-water mark (VmHWM, the peak RSS since start or since the last reset).
// ResetPeakResidentBytes writes "5" to /proc/self/clear_refs, which sets VmHWM back to the current
// RSS (Linux >= 4.0); where that is not permitted (other kernels, sandboxes) it returns false and
// the peak keeps counting from the start of the process, so a per-phase peak is then an upper bound.
#include <cstddef>

namespace reconar {

struct MemoryUsage {
  size_t resident_bytes = 0;       // VmRSS
  size_t peak_resident_bytes = 0;  // VmHWM
  bool known = false;              // false when /proc/self/status could not be read (not Linux)
};

MemoryUsage CurrentMemoryUsage();

// Peak RSS in bytes (VmHWM); 0 when unknown.
size_t PeakResidentBytes();

// True when the kernel accepted the reset.
bool ResetPeakResidentBytes();

// Gives the heap's free pages back to the kernel (glibc malloc_trim), so that RSS shows what is in
// use: a long run's earlier stages leave freed memory resident, which would hide what the next one
// allocates. No-op elsewhere.
void ReleaseFreeHeapMemory();

// Bytes in MiB, as reports print them.
inline double Mib(size_t bytes) { return static_cast<double>(bytes) / (1 << 20); }

}  // namespace reconar
