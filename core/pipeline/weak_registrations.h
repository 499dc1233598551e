#pragma once
// The photos a mapping found weak, to be extracted again with richer features (match_stage.h,
// MatchStageOptions::extract_again) and mapped again (reconstruct.h): a photo the mapper could
// register only provisionally (from fewer than 30 points, or from a neighbour's two-view geometry:
// core/sfm/provisional_registration.h), or not at all although it has verified pairs, has too few
// features for the model; so have its partners, whose features its own must match: the photos that
// share a point with it in the model (its pose rests on them), or, for a photo left out, those it
// has verified pairs with. A set the mapper registers firmly (the room, fountain-P11) is left as it
// is.
#include <map>
#include <string>

#include "core/base/status.h"
#include "core/pipeline/project.h"

namespace reconar {

// From PROJECT/sparse/report.json (provisional, unregistered), PROJECT/sparse/ (the model),
// PROJECT/matches/matches.txt (the verified pairs) and PROJECT/matches/report.json (the photos
// already extracted again): the photos
// to extract again that have not been, by name, each with why. Empty when the mapping registered
// every photo firmly. File errors pass through.
Result<std::map<std::string, std::string>> WeaklyRegisteredPhotos(const Project& project);

// The photos MatchStageOptions::extract_again named in the project's last matching
// (PROJECT/matches/report.json "extract_again"), so that a run resumed after a second matching
// continues from it; empty when there is none.
std::map<std::string, std::string> RecordedExtractAgain(const Project& project);

}  // namespace reconar
