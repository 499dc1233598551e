#pragma once
// Map stage: the project's sparse model (PROJECT/sparse) and its features (PROJECT/features) -> the
// localisation map (core/sfm/localization_map.h) at PROJECT/map/map.rmap, and
// PROJECT/map/report.json (its size and build times), each written atomically, report last; then
// the stage is recorded as finished in PROJECT/stages.txt (stage_record.h), so that a later
// `reconar reconstruct` reuses the map. The map's frame is the model's: metres in the world tag's
// frame when PROJECT/tags.json says the model is metric. `reconar map PROJECT` runs this stage
// alone on an existing project.

#include <string>

#include "core/base/status.h"
#include "core/pipeline/project.h"
#include "core/sfm/localization_map.h"

namespace reconar {

struct MapStageOptions {
  MapBuildOptions build;

  Status Check() const { return build.Check(); }
};

struct MapStageReport {
  MapBuildReport build;
  std::string frame;
  bool metric = false;
  std::string path;
  size_t file_bytes = 0;
  double seconds = 0.0;
};

// The stage's settings as PROJECT/stages.txt records them.
std::string MapStageSettings(const MapStageOptions& options);

// FailedPrecondition when the project has no sparse model; errors of its files name the file, and
// of stages.txt.
Result<MapStageReport> RunMapStage(const Project& project, const MapStageOptions& options);

}  // namespace reconar
