// reconar map PROJECT: (re)builds the project's localisation map, as the map stage of `reconar
// reconstruct` does.
#include <cstdio>

#include "core/base/json_writer.h"
#include "core/base/thread_pool.h"
#include "core/pipeline/map_stage.h"
#include "core/pipeline/reconstruct.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar map PROJECT_DIR [--threads N] [--json]\n"
    "\n"
    "Builds PROJECT_DIR/map/map.rmap, the localisation map that `reconar "
    "localize` and the AR view\n"
    "use to find the camera without a tag in view: the sparse model's points "
    "with their SIFT\n"
    "descriptors, the registered photos as keyframes and a vocabulary tree "
    "over them. `reconar\n"
    "reconstruct` builds it after mapping; this command rebuilds it on an "
    "existing project.\n"
    "  --threads N   worker threads (default: one per core)\n"
    "  --json        print the map's summary as JSON on stdout\n";

}  // namespace

int RunMap(int argc, char** argv, int first) {
  Args args({"threads"}, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 1, 1)) return *exit_code;
  auto threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  const Project project(args.positionals()[0]);
  MapStageOptions options = ReconstructOptions().map;
  options.build.num_threads = ThreadPool::ResolveThreadCount(*threads);
  auto report = RunMapStage(project, options);  // records the stage: a later `reconstruct` reuses the map
  if (!report.ok()) return Fail(report.status());
  if (args.Has("json")) {
    JsonWriter json;
    json.BeginObject().Key("path").String(report->path).Key("frame").String(report->frame);
    json.Key("keyframes").Int(report->build.keyframes).Key("points").Int(report->build.points);
    json.Key("observations").Int(report->build.observations).Key("words").Int(report->build.words);
    json.Key("file_bytes").Int(static_cast<long long>(report->file_bytes));
    json.Key("memory_bytes").Int(static_cast<long long>(report->build.memory_bytes));
    json.Key("seconds").Double(report->seconds).EndObject();
    std::printf("%s\n", json.str().c_str());
  } else {
    std::printf(
        "%s: %d keyframes, %d points, %d observations, %d words, %.1f "
        "MiB on disk, %.1f s (frame: %s)\n",
        report->path.c_str(), report->build.keyframes, report->build.points, report->build.observations,
        report->build.words, report->file_bytes / 1048576.0, report->seconds, report->frame.c_str());
  }
  return 0;
}

}  // namespace reconar::tools
