#include "core/pipeline/weak_registrations.h"

#include <set>
#include <string>

#include "core/base/json_reader.h"
#include "core/pipeline/matches_file.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

const std::string& StringAt(const JsonValue& object, const char* key) {
  static const std::string kEmpty;
  const JsonValue* value = object.Find(key);
  return value != nullptr && value->is_string() ? value->string() : kEmpty;
}

}  // namespace

Result<std::map<std::string, std::string>> WeaklyRegisteredPhotos(const Project& project) {
  std::map<std::string, std::string> weak;
  RECONAR_ASSIGN_OR_RETURN(const JsonValue sparse, ReadJsonFile(project.SparseDir() + "/report.json"));
  if (const JsonValue* provisional = sparse.Find("provisional")) {
    for (size_t i = 0; i < provisional->size(); ++i) {
      const JsonValue& photo = (*provisional)[i];
      const JsonValue* kept = photo.Find("kept");
      const JsonValue* inliers = photo.Find("inliers");
      if (kept == nullptr || !kept->is_bool() || !kept->bool_value()) continue;
      weak.emplace(StringAt(photo, "image"),
                   "registered provisionally (" + StringAt(photo, "evidence") + ", " +
                       std::to_string(inliers != nullptr && inliers->is_number() ? static_cast<int>(inliers->number())
                                                                                  : 0) +
                       " points)");
    }
  }
  RECONAR_ASSIGN_OR_RETURN(const std::vector<MatchesFilePair> pairs, ReadMatchesFile(project.MatchesPath()));
  std::set<std::string> paired;
  for (const MatchesFilePair& pair : pairs) paired.insert({pair.name_a, pair.name_b});
  if (const JsonValue* unregistered = sparse.Find("unregistered")) {
    for (size_t i = 0; i < unregistered->size(); ++i) {
      const std::string& name = StringAt((*unregistered)[i], "image");
      if (paired.count(name) != 0) weak.emplace(name, "not registered: " + StringAt((*unregistered)[i], "reason"));
    }
  }
  // The partners: of a registered photo, the photos that share a point with it in the model (its
  // pose rests on them); of one left out, those it has verified pairs with.
  std::map<std::string, std::string> partners;
  const auto add_partner = [&](const std::string& partner, const char* how, const std::string& photo) {
    if (weak.count(partner) == 0) partners.emplace(partner, how + photo + ", " + weak.at(photo));
  };
  RECONAR_ASSIGN_OR_RETURN(const Reconstruction model, ReadColmapTextModel(project.SparseDir()));
  std::set<std::string> registered;
  for (const SfmImage& image : model.images) {
    if (!image.registered || weak.count(image.name) == 0) continue;
    registered.insert(image.name);
    std::set<int> others;
    for (const int id : image.point3d_ids) {
      if (id < 0) continue;
      for (const TrackElement& e : model.points[static_cast<size_t>(id)].track) others.insert(e.image_id);
    }
    for (const int other : others) {
      if (model.images[static_cast<size_t>(other)].name != image.name)
        add_partner(model.images[static_cast<size_t>(other)].name, "sees points with ", image.name);
    }
  }
  for (const MatchesFilePair& pair : pairs) {
    for (const auto& [photo, partner] : {std::make_pair(pair.name_a, pair.name_b), std::make_pair(pair.name_b, pair.name_a)}) {
      if (weak.count(photo) != 0 && registered.count(photo) == 0) add_partner(partner, "paired with ", photo);
    }
  }
  weak.insert(partners.begin(), partners.end());
  // Less the photos extracted again already.
  if (auto matching = ReadJsonFile(project.MatchesDir() + "/report.json"); matching.ok()) {
    if (const JsonValue* again = matching->Find("reextracted")) {
      for (size_t i = 0; i < again->size(); ++i) weak.erase(StringAt((*again)[i], "image"));
    }
  }
  return weak;
}

std::map<std::string, std::string> RecordedExtractAgain(const Project& project) {
  std::map<std::string, std::string> names;
  auto matching = ReadJsonFile(project.MatchesDir() + "/report.json");
  if (!matching.ok()) return names;
  const JsonValue* asked = matching->Find("extract_again");
  for (size_t i = 0; asked != nullptr && i < asked->size(); ++i)
    names.emplace(StringAt((*asked)[i], "image"), StringAt((*asked)[i], "reason"));
  return names;
}

}  // namespace reconar
