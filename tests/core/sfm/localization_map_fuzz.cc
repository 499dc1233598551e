// Mutation fuzzer of the map file reader (ParseLocalizationMap, core/sfm/localization_map.h).
//
//   localization_map_fuzz [--seconds S] [--seed N]    (S: CPU seconds of this process)
//
// Starts from valid map files (tests/core/sfm/sample_localization_map.h) and applies 1-4 random
// mutations per iteration (tests/support/byte_mutator.h): bit flips, byte sets, special doubles,
// chunk deletions, duplications and insertions, truncations, and extreme values written into count
// fields (the offsets where the valid file holds one of the map's counts). In most iterations the
// header's payload size and CRC are then repaired so that the structural parser behind the
// checksum sees the damage. Every result must be an ok map whose invariants hold or an
// InvalidArgument naming the input; a crash or sanitizer report is the failure this harness exists
// to find (run it in an ASan+UBSan build). Exit status 1 when an accepted map breaks an invariant
// or a status is not InvalidArgument.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/sfm/localization_map.h"
#include "tests/core/sfm/sample_localization_map.h"
#include "tests/support/byte_mutator.h"

namespace reconar {
namespace {

constexpr size_t kHeaderBytes = 24;
constexpr char kWhat[] = "fuzz.rmap";

struct Seed {
  std::string bytes;
  testing::MutationHints hints;  // its header, and where it holds a uint32 equal to one of the map's counts
};

Seed MakeSeed(const LocalizationMap& map, const std::string& path) {
  Seed seed;
  const Status written = WriteLocalizationMap(path, map);
  if (!written.ok()) {
    std::fprintf(stderr, "%s\n", written.ToString().c_str());
    std::exit(2);
  }
  Result<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) {
    std::fprintf(stderr, "%s\n", bytes.status().ToString().c_str());
    std::exit(2);
  }
  std::remove(path.c_str());
  seed.bytes = std::move(bytes).value();
  seed.hints.header_bytes = kHeaderBytes;
  std::vector<uint32_t> counts = {static_cast<uint32_t>(map.frame.size()), static_cast<uint32_t>(map.points.size()),
                                  static_cast<uint32_t>(map.keyframes.size()),
                                  static_cast<uint32_t>(map.vocabulary.num_nodes()),
                                  static_cast<uint32_t>(map.vocabulary.num_words())};
  for (const MapKeyframe& keyframe : map.keyframes) {
    counts.push_back(static_cast<uint32_t>(keyframe.name.size()));
    counts.push_back(static_cast<uint32_t>(keyframe.point_ids.size()));
  }
  for (size_t at = kHeaderBytes; at + 4 <= seed.bytes.size(); ++at) {
    uint32_t value = 0;
    std::memcpy(&value, &seed.bytes[at], sizeof(value));
    for (const uint32_t count : counts) {
      if (value == count && count > 0) {
        seed.hints.count_offsets.push_back(at);
        break;
      }
    }
  }
  return seed;
}

// The promises of an accepted map (what localisation relies on without checking again).
std::string BrokenInvariant(const LocalizationMap& map) {
  const size_t n = map.points.size();
  if (map.colors.size() != n || map.point_descriptors.size() != 128 * n) return "point arrays differ in size";
  for (const Eigen::Vector3d& point : map.points) {
    if (!point.allFinite()) return "non-finite point";
  }
  if (map.keyframe_index.num_images() != static_cast<int>(map.keyframes.size())) return "index size";
  if (map.keyframe_index.num_words() != map.vocabulary.num_words()) return "index words";
  for (const MapKeyframe& keyframe : map.keyframes) {
    const size_t m = keyframe.point_ids.size();
    if (keyframe.keypoints.size() != m || keyframe.descriptors.size() != 128 * m) return "observation arrays";
    if (!(keyframe.camera.focal > 0.0) || !(keyframe.camera.aspect > 0.0)) return "camera";
    if (keyframe.width <= 0 || keyframe.height <= 0) return "image size";
    for (const char c : keyframe.name) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "control character in a name";
    }
    if (keyframe.name.empty()) return "empty name";
    const Eigen::Matrix3d& r = keyframe.cam_from_world.rotation;
    if (!((r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-6)) return "rotation";
    for (const int32_t id : keyframe.point_ids) {
      if (id < 0 || static_cast<size_t>(id) >= n) return "point id";
    }
    // Retrieval with the keyframe's own words: valid images, finite scores.
    std::vector<int32_t> words;
    for (size_t j = 0; j < keyframe.descriptors.size(); j += 128) {
      const int word = map.vocabulary.Quantize(&keyframe.descriptors[j]);
      if (word < -1 || word >= map.vocabulary.num_words()) return "word out of range";
      words.push_back(word);
    }
    const int num_images = map.keyframe_index.num_images();
    RetrievalScratch scratch;
    scratch.Reserve(static_cast<int>(words.size()), num_images);
    std::vector<RetrievalCandidate> ranked;
    ranked.reserve(static_cast<size_t>(num_images));
    map.keyframe_index.Query(words.data(), static_cast<int>(words.size()), num_images, &scratch, &ranked);
    for (const RetrievalCandidate& candidate : ranked) {
      if (candidate.image < 0 || candidate.image >= num_images) return "retrieved image out of range";
      if (!std::isfinite(candidate.score)) return "retrieval score not finite";
    }
  }
  return "";
}

// The kind of a refusal: its message without `what`, numbers and parenthesised details.
std::string RefusalKind(const std::string& message) {
  std::string kind = message.substr(std::min(message.size(), sizeof(kWhat) + 1));
  const size_t at_byte = kind.find(" at byte");
  if (at_byte != std::string::npos) kind.resize(at_byte);
  // "keyframe N (NAME): reason": the name may hold anything but control characters.
  const size_t name_begin = kind.rfind("keyframe ", 0) == 0 ? kind.find(" (") : std::string::npos;
  const size_t name_end = name_begin == std::string::npos ? name_begin : kind.find("): ", name_begin);
  if (name_end != std::string::npos) kind.erase(name_begin, name_end + 1 - name_begin);
  std::string out;
  int depth = 0;
  for (const char c : kind) {
    if (c == '(') ++depth;
    if (depth == 0 && (c < '0' || c > '9')) out.push_back(c);
    if (c == ')' && depth > 0) --depth;
  }
  return out;
}

int Run(double seconds, uint64_t seed_value) {
  const std::string temp =
      "/tmp/reconar_map_fuzz_" + std::to_string(seed_value) + "_" + std::to_string(std::time(nullptr));
  const std::vector<Seed> seeds = {MakeSeed(testing::SampleLocalizationMap(24, 2, 1), temp + "a.rmap"),
                                   MakeSeed(testing::SampleLocalizationMap(60, 3, 2), temp + "b.rmap")};
  for (const Seed& seed : seeds) {
    Result<LocalizationMap> map = ParseLocalizationMap(seed.bytes, kWhat);
    if (!map.ok()) {
      std::fprintf(stderr, "the valid seed is refused: %s\n", map.status().ToString().c_str());
      return 1;
    }
  }
  testing::ByteMutator mutator(seed_value);
  std::map<std::string, long> refusals;
  long iterations = 0;
  long accepted = 0;
  long rejected = 0;
  long repaired = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  std::string bytes;
  const auto cpu_seconds = [&] { return static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC; };
  while (cpu_seconds() < seconds) {
    const Seed& seed = seeds[static_cast<size_t>(mutator.Uniform(0, static_cast<int>(seeds.size()) - 1))];
    bytes = seed.bytes;
    const int num_mutations = mutator.Chance(0.6) ? 1 : mutator.Uniform(2, 4);
    for (int i = 0; i < num_mutations; ++i) mutator.Mutate(seed.hints, &bytes);
    if (mutator.Chance(0.85)) {
      testing::RepairMapHeader(&bytes);
      ++repaired;
    }
    Result<LocalizationMap> map = ParseLocalizationMap(bytes, kWhat);
    ++iterations;
    if (map.ok()) {
      ++accepted;
      const std::string broken = BrokenInvariant(*map);
      if (!broken.empty()) {
        std::fprintf(stderr, "iteration %ld: an accepted map breaks an invariant: %s\n", iterations, broken.c_str());
        return 1;
      }
    } else {
      ++rejected;
      const Status& status = map.status();
      if (status.code() != StatusCode::kInvalidArgument || status.message().rfind(std::string(kWhat) + ": ", 0) != 0) {
        std::fprintf(stderr, "iteration %ld: unexpected status %s\n", iterations, status.ToString().c_str());
        return 1;
      }
      ++refusals[RefusalKind(status.message())];
    }
  }
  const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "localization_map_fuzz: seed %llu, %.1f CPU s (%.1f s wall), %ld iterations (%ld with a repaired "
      "header): %ld accepted, %ld rejected\n",
      static_cast<unsigned long long>(seed_value), cpu_seconds(), wall_seconds, iterations, repaired, accepted,
      rejected);
  for (const auto& [kind, count] : refusals) std::printf("  %8ld  %s\n", count, kind.c_str());
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  double seconds = 10.0;
  uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else if (arg == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else {
      std::fprintf(stderr, "usage: %s [--seconds S] [--seed N]\n", argv[0]);
      return 2;
    }
  }
  return reconar::Run(seconds, seed);
}
