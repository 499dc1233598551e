#pragma once
// PROJECT/stages.txt: one "STAGE SETTINGS" line per finished stage, so that a re-run (of `reconar
// sfm`, or of `reconar reconstruct` after an interruption) reuses a stage only when it finished
// with the same settings. A stage is recorded after its outputs are written (atomically), so a
// killed run never records a stage it did not finish; recording a stage drops the record of every
// stage after it in kStageOrder, whose inputs it has just replaced, and of the side stages
// (kSideStages) that read it or a dropped stage.
#include <initializer_list>
#include <map>
#include <string>
#include <utility>

#include "core/base/status.h"
#include "core/pipeline/project.h"

namespace reconar {

// Tags read the photos alone; they come before matching so that matching again (reconstruct.h,
// the photos mapped weakly) keeps them.
inline constexpr const char* kStageOrder[] = {"features", "tags", "matching", "mapping", "dense", "mesh"};

// Stages off the chain: each reads one chain stage's outputs and no later stage reads its own.
struct SideStage {
  const char* stage;
  const char* input;
};
inline constexpr SideStage kSideStages[] = {{"map", "mapping"}};

inline bool IsSideStage(const std::string& stage) {
  for (const SideStage& side : kSideStages) {
    if (stage == side.stage) return true;
  }
  return false;
}

class StageRecord {
 public:
  // A missing or unreadable stages.txt reads as no finished stage.
  explicit StageRecord(const Project& project);

  bool Finished(const std::string& stage, const std::string& settings) const;
  Status Record(const std::string& stage, const std::string& settings);

  // "name=value name=value" with values printed to 12 significant digits.
  static std::string Settings(std::initializer_list<std::pair<const char*, double>> values);

 private:
  std::string path_;
  std::map<std::string, std::string> stages_;
};

}  // namespace reconar
