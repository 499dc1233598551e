// tag_edge_sigma PROJECT: how honest `reconar measure`'s σ is, on the tags that did not set the
// scale (`reconstruct --tag-size M --scale-tags IDS`): each such tag's 4 edges and 2 diagonals,
// measured corner to corner (core/measure/measurement.h) against the printed size and its root
// two. Prints every segment, the share within 2σ and the median σ.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "core/base/json_reader.h"
#include "core/measure/measurement.h"
#include "core/sfm/tag_observations.h"

namespace reconar {
namespace {

int Run(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: tag_edge_sigma PROJECT\n");
    return 2;
  }
  const Project project(argv[1]);
  Result<ProjectMeasurer> measurer = ProjectMeasurer::Open(project);
  Result<JsonValue> tags = ReadJsonFile(project.TagsJsonPath());
  for (const Status& s : {measurer.status(), tags.status()}) {
    if (!s.ok()) {
      std::fprintf(stderr, "%s\n", s.ToString().c_str());
      return 1;
    }
  }
  const MeasureSetup& setup = measurer->setup();
  if (!setup.metric) {
    std::fprintf(stderr, "%s is not metric\n", argv[1]);
    return 1;
  }
  const std::set<int> scale(setup.scale_tags.begin(), setup.scale_tags.end());
  std::printf("%d cameras, %d points, %d observations, sigma0 %.3f px; scale from %zu tags, spread %.3f %%; sigma x %.2f "
              "from their %d segments; set up in %.3f s\n",
              setup.cameras, setup.points, setup.observations, setup.sigma0_px, scale.size(),
              100 * setup.scale_relative_sigma, setup.sigma_calibration, setup.scale_segments, setup.seconds_setup);
  const JsonValue& list = *tags->Find("tags");
  int within = 0, total = 0;
  std::vector<double> sigmas, errors;
  for (size_t t = 0; t < list.size(); ++t) {
    const int id = static_cast<int>(*list[t].Find("id")->AsInteger());
    if (scale.count(id)) continue;
    for (int s = 0; s < 6; ++s) {
      MeasureItem item;
      for (int end = 0; end < 2; ++end) {
        item.points.push_back(*ParseMeasurePoint("tag:" + std::to_string(id) + ":c" + std::to_string(kTagSegments[s][end])));
      }
      Result<MeasuredItem> measured = measurer->Measure(item);
      if (!measured.ok()) {
        std::printf("tag %2d segment %d: %s\n", id, s, measured.status().ToString().c_str());
        continue;
      }
      const double truth = s < 4 ? setup.tag_size_m : setup.tag_size_m * std::sqrt(2.0);
      const double error = measured->value - truth;
      within += std::abs(error) <= 2 * measured->sigma ? 1 : 0;
      ++total;
      sigmas.push_back(measured->sigma);
      errors.push_back(std::abs(error));
      std::printf("tag %2d %s %d: %.5f m, error %+.2f mm, sigma %.2f mm\n", id, s < 4 ? "edge" : "diagonal",
                  s < 4 ? s : s - 4, measured->value, 1000 * error, 1000 * measured->sigma);
    }
  }
  if (total == 0) {
    std::printf("no tag outside the scale tags\n");
    return 0;
  }
  std::sort(sigmas.begin(), sigmas.end());
  std::sort(errors.begin(), errors.end());
  std::printf("check segments: %d; within 2 sigma: %d (%.1f %%); median sigma %.2f mm; median |error| %.2f mm\n", total,
              within, 100.0 * within / total, 1000 * sigmas[sigmas.size() / 2], 1000 * errors[errors.size() / 2]);
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
