#pragma once
// The mutations of the file readers' mutation fuzzers (tests/core/sfm/localization_map_fuzz.cc,
// tests/core/compare/design_fuzz.cc): bit flips, byte sets, special doubles, chunk deletions,
// duplications and insertions, truncations and extreme values written into count fields; for text
// formats also tokens spliced in or put in place of a word, and lines deleted or duplicated. The
// same seed and the same calls give the same mutations. Test support only.
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace reconar::testing {

// What the mutator knows of a valid file.
struct MutationHints {
  // Mutations land in the first `header_bytes` bytes only 5 % of the time (a header the reader
  // checks first, or that the fuzzer repairs after mutating).
  size_t header_bytes = 0;
  // Offsets of the little-endian uint32 fields that hold counts: a "count field" mutation writes an
  // extreme value at one of them 80 % of the time, anywhere otherwise.
  std::vector<size_t> count_offsets;
  // For text formats: tokens ("nan", "-1", "end_header\n") spliced in at random places or put in
  // place of a word. Empty for binary formats: the byte mutations only, in the same proportions
  // (and from the same random draws) as without hints.
  std::vector<std::string> text_tokens;
};

class ByteMutator {
 public:
  explicit ByteMutator(uint64_t seed) : random_(seed) {}

  int Uniform(int lo, int hi);  // in [lo, hi]
  bool Chance(double probability);

  // One mutation of *bytes; returns its name ("bit flip", ...), or "none" when it did not apply
  // (e.g. a bit flip in an empty file).
  const char* Mutate(const MutationHints& hints, std::string* bytes);

 private:
  // A position in `bytes`, mostly after the header; 0 when it is empty.
  size_t Position(const std::string& bytes, const MutationHints& hints);
  uint32_t InterestingCount(uint32_t original);
  const char* SpliceToken(const MutationHints& hints, bool in_place_of_a_word, std::string* bytes);
  const char* DeleteOrDuplicateLine(const MutationHints& hints, std::string* bytes);

  std::mt19937_64 random_;
};

}  // namespace reconar::testing
