#pragma once
// Arena: a bump allocator over one block reserved up front. Hot paths (SIFT per octave,
// matching per pair, tracking per frame) take memory from it and give it all back at once
// with a Scope, so steady state makes no system calls. Capacity is fixed: running out is
// reported (nullptr + exhausted()), never papered over by growing.
#include <cstddef>
#include <cstdint>
#include <memory>

namespace reconar {

class Arena {
 public:
  static constexpr size_t kDefaultAlignment = 64;  // a cache line; enough for AVX-512 loads

  explicit Arena(size_t capacity_bytes);
  Arena(const Arena&) = delete;
  Arena& operator=(const Arena&) = delete;

  // Returns nullptr when the request does not fit; the arena is unchanged then.
  void* Allocate(size_t bytes, size_t alignment = kDefaultAlignment);

  template <typename T>
  T* AllocateArray(size_t count) {
    return static_cast<T*>(Allocate(count * sizeof(T), alignof(T) > kDefaultAlignment ? alignof(T)
                                                                                     : kDefaultAlignment));
  }

  // Frees everything allocated after `mark` (from Mark()).
  void ResetTo(size_t mark);
  void Reset() { ResetTo(0); }
  size_t Mark() const { return used_; }

  size_t capacity() const { return capacity_; }
  size_t used() const { return used_; }
  size_t peak_used() const { return peak_used_; }
  size_t wasted() const { return wasted_; }     // bytes lost to alignment padding
  size_t failed_allocations() const { return failed_allocations_; }

  // Frees on destruction everything allocated inside its lifetime.
  class Scope {
   public:
    explicit Scope(Arena& arena) : arena_(arena), mark_(arena.Mark()) {}
    ~Scope() { arena_.ResetTo(mark_); }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    Arena& arena_;
    size_t mark_;
  };

 private:
  struct FreeDeleter {
    void operator()(void* p) const;
  };
  std::unique_ptr<uint8_t, FreeDeleter> block_;
  size_t capacity_ = 0;
  size_t used_ = 0;
  size_t peak_used_ = 0;
  size_t wasted_ = 0;
  size_t failed_allocations_ = 0;
};

}  // namespace reconar
