#pragma once
// FNV-1a, 64 bits (Fowler, Noll, Vo): a digest of settings text for the stage records, stable
// across builds and machines (std::hash is not). Not for anything adversarial.
#include <cstdint>
#include <string_view>

namespace reconar {

class Fnv1a64 {
 public:
  void Add(std::string_view text) {
    for (const char c : text) {
      hash_ ^= static_cast<unsigned char>(c);
      hash_ *= 0x100000001b3ull;
    }
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ull;
};

}  // namespace reconar
