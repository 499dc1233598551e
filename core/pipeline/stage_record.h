#pragma once
// PROJECT/stages.txt: one "STAGE SETTINGS" line per finished stage, so that a re-run (of `reconar
// sfm`, or of `reconar reconstruct` after an interruption) reuses a stage only when it finished
// with the same settings. A stage is recorded after its outputs are written (atomically), so a
// killed run never records a stage it did not finish; recording a stage drops the record of every
// stage that reads it (kStageInputs). Several records of one project may be open at once (the
// stage runner's, and the map stage's, which records itself): each reads the file again before it
// writes, so none undoes another's lines.
#include <initializer_list>
#include <map>
#include <string>
#include <utility>

#include "core/base/status.h"
#include "core/pipeline/project.h"

namespace reconar {

// What each stage reads of the others (the photos aside). Recording a stage drops the record of
// every stage that reads it, directly or through another, since its inputs were just replaced.
// Tags read the photos alone (the features stand for them: a new set of photos is extracted
// again), so matching again (reconstruct.h, the photos mapped weakly) keeps them, and tags
// detected after a capture recorded its matches keep those.
struct StageInputs {
  const char* stage;
  const char* inputs[2];
};
inline constexpr StageInputs kStageInputs[] = {
    {"features", {nullptr, nullptr}}, {"tags", {"features", nullptr}}, {"matching", {"features", nullptr}},
    {"mapping", {"tags", "matching"}},  {"dense", {"mapping", nullptr}}, {"mesh", {"dense", nullptr}},
    {"texture", {"mesh", nullptr}}, {"map", {"mapping", nullptr}},
};

// A stage off the chain: no other stage reads it (the localisation map).
inline bool IsSideStage(const std::string& stage) {
  for (const StageInputs& other : kStageInputs) {
    for (const char* input : other.inputs) {
      if (input != nullptr && stage == input) return false;
    }
  }
  return true;
}

class StageRecord {
 public:
  // A missing or unreadable stages.txt reads as no finished stage.
  explicit StageRecord(const Project& project);

  bool Finished(const std::string& stage, const std::string& settings) const;
  // Reads stages.txt again, sets the stage's line and writes the file (atomically).
  Status Record(const std::string& stage, const std::string& settings);

  // "name=value name=value" with values printed to 12 significant digits.
  static std::string Settings(std::initializer_list<std::pair<const char*, double>> values);

 private:
  void Read();

  std::string path_;
  std::map<std::string, std::string> stages_;
};

}  // namespace reconar
