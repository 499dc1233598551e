#include "tests/support/byte_mutator.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <limits>

namespace reconar::testing {

namespace {

// A character of a word that SpliceToken may replace: a number, a keyword, a JSON key.
bool IsWordCharacter(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '_' || c == '+' || c == '-';
}

size_t LineStart(const std::string& bytes, size_t at) {
  if (at == 0) return 0;
  const size_t newline = bytes.rfind('\n', at - 1);
  return newline == std::string::npos ? 0 : newline + 1;
}

}  // namespace

int ByteMutator::Uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random_); }

bool ByteMutator::Chance(double probability) {
  return std::uniform_real_distribution<double>(0.0, 1.0)(random_) < probability;
}

size_t ByteMutator::Position(const std::string& bytes, const MutationHints& hints) {
  if (bytes.empty()) return 0;
  if (bytes.size() > hints.header_bytes && !Chance(0.05)) {
    return static_cast<size_t>(Uniform(static_cast<int>(hints.header_bytes), static_cast<int>(bytes.size()) - 1));
  }
  return static_cast<size_t>(Uniform(0, static_cast<int>(bytes.size()) - 1));
}

uint32_t ByteMutator::InterestingCount(uint32_t original) {
  switch (Uniform(0, 9)) {
    case 0:
      return 0;
    case 1:
      return 1;
    case 2:
      return original + 1;
    case 3:
      return original - 1;
    case 4:
      return 0xffffffffu;
    case 5:
      return 0x7fffffffu;
    case 6:
      return 0x80000000u;
    case 7:
      return original * 2;
    case 8:
      return static_cast<uint32_t>(Uniform(0, 1 << 16));
    default:
      return static_cast<uint32_t>(random_());
  }
}

const char* ByteMutator::Mutate(const MutationHints& hints, std::string* bytes) {
  const size_t size = bytes->size();
  // Kinds 0-8 are the byte mutations, 9-14 the text ones.
  switch (Uniform(0, hints.text_tokens.empty() ? 8 : 14)) {
    case 0: {
      if (size == 0) return "none";
      const size_t at = Position(*bytes, hints);
      (*bytes)[at] = static_cast<char>((*bytes)[at] ^ (1 << Uniform(0, 7)));
      return "bit flip";
    }
    case 1: {
      if (size == 0) return "none";
      static constexpr uint8_t kValues[] = {0x00, 0xff, 0x7f, 0x80, 0x01, 0xfe};
      const size_t at = Position(*bytes, hints);
      (*bytes)[at] = static_cast<char>(Chance(0.5) ? kValues[Uniform(0, 5)] : Uniform(0, 255));
      return "byte set";
    }
    case 2: {
      if (size < 8) return "none";
      const double kDoubles[] = {std::numeric_limits<double>::quiet_NaN(),
                                 std::numeric_limits<double>::infinity(),
                                 -std::numeric_limits<double>::infinity(),
                                 0.0,
                                 -1.0,
                                 1e308,
                                 1e-310};
      const size_t at = std::min(Position(*bytes, hints), size - 8);
      std::memcpy(&(*bytes)[at], &kDoubles[Uniform(0, 6)], sizeof(double));
      return "special double";
    }
    case 3: {
      if (size == 0) return "none";
      const size_t at = Position(*bytes, hints);
      const size_t length = std::min(size - at, static_cast<size_t>(Chance(0.8) ? Uniform(1, 16) : Uniform(1, 512)));
      bytes->erase(at, length);
      return "chunk deletion";
    }
    case 4: {
      if (size == 0) return "none";
      const size_t from = Position(*bytes, hints);
      const size_t length = std::min(size - from, static_cast<size_t>(Uniform(1, 256)));
      const std::string chunk = bytes->substr(from, length);
      bytes->insert(Chance(0.5) ? from : Position(*bytes, hints), chunk);
      return "chunk duplication";
    }
    case 5: {
      std::string chunk(static_cast<size_t>(Chance(0.8) ? Uniform(1, 16) : Uniform(1, 512)), '\0');
      for (char& c : chunk) c = static_cast<char>(Uniform(0, 255));
      bytes->insert(Position(*bytes, hints), chunk);
      return "chunk insertion";
    }
    case 6: {
      if (size == 0) return "none";
      bytes->resize(static_cast<size_t>(Uniform(0, static_cast<int>(size) - 1)));
      return "truncation";
    }
    case 7:
    case 8: {
      size_t at = 0;
      if (!hints.count_offsets.empty() && Chance(0.8)) {
        at = hints.count_offsets[static_cast<size_t>(Uniform(0, static_cast<int>(hints.count_offsets.size()) - 1))];
      } else {
        at = Position(*bytes, hints);
      }
      if (at + 4 > size) return "none";
      uint32_t value = 0;
      std::memcpy(&value, &(*bytes)[at], sizeof(value));
      value = InterestingCount(value);
      std::memcpy(&(*bytes)[at], &value, sizeof(value));
      return "count field";
    }
    case 9:
    case 10:
      return SpliceToken(hints, false, bytes);
    case 11:
    case 12:
      return SpliceToken(hints, true, bytes);
    default:
      return DeleteOrDuplicateLine(hints, bytes);
  }
}

const char* ByteMutator::SpliceToken(const MutationHints& hints, bool in_place_of_a_word, std::string* bytes) {
  const std::string& token =
      hints.text_tokens[static_cast<size_t>(Uniform(0, static_cast<int>(hints.text_tokens.size()) - 1))];
  size_t at = Position(*bytes, hints);
  if (!in_place_of_a_word) {
    bytes->insert(at, token);
    return "token insertion";
  }
  while (at < bytes->size() && !IsWordCharacter((*bytes)[at])) ++at;
  if (at == bytes->size()) return "none";
  size_t begin = at;
  while (begin > 0 && IsWordCharacter((*bytes)[begin - 1])) --begin;
  size_t end = at;
  while (end < bytes->size() && IsWordCharacter((*bytes)[end])) ++end;
  bytes->replace(begin, end - begin, token);
  return "token in place of a word";
}

const char* ByteMutator::DeleteOrDuplicateLine(const MutationHints& hints, std::string* bytes) {
  if (bytes->empty()) return "none";
  const size_t at = Position(*bytes, hints);
  const size_t begin = LineStart(*bytes, at);
  const size_t newline = bytes->find('\n', at);
  const size_t end = newline == std::string::npos ? bytes->size() : newline + 1;
  if (Chance(0.4)) {
    bytes->erase(begin, end - begin);
    return "line deletion";
  }
  const std::string line = bytes->substr(begin, end - begin);
  bytes->insert(Chance(0.5) ? end : LineStart(*bytes, Position(*bytes, hints)), line);
  return "line duplication";
}

}  // namespace reconar::testing
