// `reconar measure`: distances, paths, areas and heights in a reconstructed project, each with a
// ± from the reconstruction (core/measure/measurement.h).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/base/json_writer.h"
#include "core/measure/measurement.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar measure PROJECT ITEM... [--json]\n"
    "\n"
    "Measures in a reconstructed project, each value with 1 sigma from the reconstruction: the\n"
    "bundle adjustment's covariance of the cameras and points involved, the metric scale's own\n"
    "uncertainty, calibrated on the scale tags' known size (docs/measure.md says what it includes).\n"
    "Metres on a project registered by tags (`reconstruct --tag-size`), else model units (sigma\n"
    "relative to the model's size).\n"
    "Items:\n"
    "  --distance A B          the distance between two points\n"
    "  --path A B C...         the length of a polyline\n"
    "  --area A B C...         the area of a polygon (its points in order)\n"
    "  --height A --plane B C D  A's signed distance from the plane through B, C, D\n"
    "Points:\n"
    "  tag:3                   a tag's centre;  tag:3:c2  its corner 2 (libapriltag's order)\n"
    "  xyz:X,Y,Z               world coordinates (metres, the world tag's frame)\n"
    "  IMG.JPG@X,Y             a pixel of a registered photo, its ray met with the mesh\n"
    "  IMG.JPG@X,Y+IMG2.JPG@X,Y  the same point in two (or more) photos, triangulated\n"
    "  (pixels: the centre of the top-left pixel is 0,0)\n"
    "  --pick-sigma PX          how precisely the pixels were picked, 1 sigma (default 1; 0.2 for\n"
    "                          detected corners)\n"
    "  --json                  print {\"metric\", \"setup\", \"items\": [{\"kind\", \"points\", \"point_names\",\n"
    "                          \"value\", \"sigma\", \"unit\"}]} on stdout\n";

bool IsItem(const char* arg) {
  return std::strcmp(arg, "--distance") == 0 || std::strcmp(arg, "--path") == 0 || std::strcmp(arg, "--area") == 0 ||
         std::strcmp(arg, "--height") == 0;
}

MeasureKind KindOf(const std::string& option) {
  if (option == "--path") return MeasureKind::kPath;
  if (option == "--area") return MeasureKind::kArea;
  if (option == "--height") return MeasureKind::kHeight;
  return MeasureKind::kDistance;
}

std::string WithSigma(const MeasuredItem& item) {
  char text[160];
  const bool square = item.unit == "m2";
  if (item.unit != "m" && item.unit != "m2") {
    std::snprintf(text, sizeof(text), "%.6g +- %.3g %s", item.value, item.sigma, item.unit.c_str());
  } else if (!std::isfinite(item.sigma)) {
    std::snprintf(text, sizeof(text), "%.4f %s +- ? (a point the photos do not fix)", item.value, item.unit.c_str());
  } else if (square) {
    std::snprintf(text, sizeof(text), "%.5f m2 +- %.5f m2", item.value, item.sigma);
  } else {
    std::snprintf(text, sizeof(text), "%.4f m +- %.1f mm", item.value, 1000.0 * item.sigma);
  }
  return text;
}

}  // namespace

int RunMeasure(int argc, char** argv, int first) {
  std::string project_dir;
  bool json = false;
  MeasureOptions options;
  std::vector<MeasureItem> items;
  std::vector<std::string> item_texts;
  for (int k = first; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (arg == "--json") {
      json = true;
    } else if (arg == "--pick-sigma") {
      char* end = nullptr;
      options.pick_sigma_px = k + 1 < argc ? std::strtod(argv[k + 1], &end) : 0.0;
      if (k + 1 >= argc || end == argv[k + 1] || *end != '\0' || !(options.pick_sigma_px > 0.0)) {
        return Fail(InvalidArgument("--pick-sigma takes a positive number of pixels"));
      }
      ++k;
    } else if (IsItem(argv[k]) || arg == "--plane") {
      if (arg == "--plane" && (items.empty() || items.back().kind != MeasureKind::kHeight ||
                               items.back().points.size() != 1)) {
        return Fail(InvalidArgument("--plane B C D follows --height A"));
      }
      if (arg != "--plane") {
        items.push_back({KindOf(arg), {}});
        item_texts.push_back(arg);
      }
      for (; k + 1 < argc && std::strncmp(argv[k + 1], "--", 2) != 0; ++k) {
        Result<MeasurePoint> point = ParseMeasurePoint(argv[k + 1]);
        if (!point.ok()) return Fail(point.status());
        items.back().points.push_back(*point);
        item_texts.back() += std::string(" ") + argv[k + 1];
      }
    } else if (arg.rfind("--", 0) == 0) {
      return Fail(InvalidArgument("unknown option " + arg + " (see reconar measure --help)"));
    } else if (project_dir.empty()) {
      project_dir = arg;
    } else {
      return Fail(InvalidArgument("'" + arg + "': points follow --distance, --path, --area or --height"));
    }
  }
  if (project_dir.empty() || items.empty()) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  Result<ProjectMeasurer> measurer = ProjectMeasurer::Open(Project(project_dir), options);
  if (!measurer.ok()) return Fail(measurer.status());
  std::vector<MeasuredItem> measured;
  for (size_t k = 0; k < items.size(); ++k) {
    Result<MeasuredItem> item = measurer->Measure(items[k]);
    if (!item.ok()) return Fail(Status(item.status().code(), item_texts[k] + ": " + item.status().message()));
    measured.push_back(*item);
  }
  if (json) {
    std::fputs(MeasurementsJson(measurer->setup(), measured).c_str(), stdout);
    return 0;
  }
  const MeasureSetup& setup = measurer->setup();
  if (setup.metric) {
    std::printf("metric: scale from %zu tags of %.4f m; sigma x %.2f from their %d edges and diagonals\n",
                setup.scale_tags.size(), setup.tag_size_m, setup.sigma_calibration, setup.scale_segments);
  } else {
    std::printf("not metric (no tags of known size registered the model): values and sigma in model units\n");
  }
  for (size_t k = 0; k < measured.size(); ++k) std::printf("%s: %s\n", item_texts[k].c_str() + 2, WithSigma(measured[k]).c_str());
  return 0;
}

}  // namespace reconar::tools
