#include "core/pipeline/matches_file.h"

#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar {

Status WriteMatchesFile(const Project& project, const std::vector<ProjectImage>& images,
                        const std::vector<VerifiedPair>& pairs) {
  std::ostringstream out;
  out << "# reconar matches v1\n";
  out.precision(12);
  for (const VerifiedPair& pair : pairs) {
    const TwoViewGeometry& g = pair.geometry;
    if (g.config == TwoViewGeometry::Config::kTooFewInliers) continue;
    out << "pair " << images[static_cast<size_t>(pair.image_a)].name << ' '
        << images[static_cast<size_t>(pair.image_b)].name << ' '
        << (g.config == TwoViewGeometry::Config::kVerified ? "verified" : "planar") << ' '
        << pair.inlier_matches.size();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) out << ' ' << g.F(r, c);
    }
    out << '\n';
    for (const FeatureMatch& m : pair.inlier_matches) out << m.index_a << ' ' << m.index_b << '\n';
  }
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project.MatchesDir()));
  return WriteFileAtomically(project.MatchesPath(), out.str());
}

Result<std::vector<MatchesFilePair>> ReadMatchesFile(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  std::vector<MatchesFilePair> pairs;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string tag;
    MatchesFilePair pair;
    size_t count = 0;
    if (!(fields >> tag >> pair.name_a >> pair.name_b >> pair.config >> count) || tag != "pair") {
      return FileError(StatusCode::kCorruptData, path, "expected a 'pair' line, got: " + line.substr(0, 80));
    }
    if (pair.config != "verified" && pair.config != "planar") {
      return FileError(StatusCode::kCorruptData, path,
                       "pair config must be 'verified' or 'planar', got: " + line.substr(0, 80));
    }
    for (int k = 0; k < 9; ++k) fields >> pair.F(k / 3, k % 3);
    if (!fields) return FileError(StatusCode::kCorruptData, path, "bad F on pair line: " + line.substr(0, 80));
    pair.matches.resize(count);
    for (FeatureMatch& m : pair.matches) {
      if (!std::getline(in, line)) return FileError(StatusCode::kCorruptData, path, "truncated match list");
      std::istringstream match_fields(line);
      if (!(match_fields >> m.index_a >> m.index_b)) {
        return FileError(StatusCode::kCorruptData, path, "bad match line: " + line.substr(0, 80));
      }
    }
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

}  // namespace reconar
