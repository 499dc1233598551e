#include "tools/view_measure.h"

#include <cstdio>
#include <memory>

#include "core/base/json_writer.h"

namespace reconar::tools {

namespace {

Result<std::shared_ptr<ProjectMeasurer>> OpenMeasurer(const std::string& project) {
  RECONAR_ASSIGN_OR_RETURN(ProjectMeasurer measurer, ProjectMeasurer::Open(Project(project)));
  RECONAR_RETURN_IF_ERROR(measurer.LoadSurface());
  return std::make_shared<ProjectMeasurer>(std::move(measurer));
}

}  // namespace

Status ReadMeasureArgs(const Args& args, ArViewOptions* options) {
  if (!args.Has("measure")) {
    if (args.Has("out") || !args.Has("project")) return Status::Ok();
    // In a window, clicks measure, when the project has what it takes (a mesh, dense points).
    Result<std::shared_ptr<ProjectMeasurer>> measurer = OpenMeasurer(args.Get("project"));
    if (!measurer.ok()) {
      std::fprintf(stderr, "reconar view: no measuring by clicks: %s\n", measurer.status().message().c_str());
      return Status::Ok();
    }
    options->measurer = *measurer;
    std::fprintf(stderr, "reconar view: click two points on the model to measure between them\n");
    return Status::Ok();
  }
  if (!args.Has("project")) return InvalidArgument("--measure needs --project (the model to measure on)");
  const std::string text = args.Get("measure");
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf %lf,%lf %c", &x1, &y1, &x2, &y2, &extra) != 4) {
    return InvalidArgument("--measure '" + text + "': expected \"X1,Y1 X2,Y2\", two pixels of the video");
  }
  RECONAR_ASSIGN_OR_RETURN(options->measurer, OpenMeasurer(args.Get("project")));
  options->measure_pixels = std::array<Eigen::Vector2d, 2>{Eigen::Vector2d(x1, y1), Eigen::Vector2d(x2, y2)};
  return Status::Ok();
}

std::string WithMeasurement(std::string frame_json, const ViewMeasurement& measurement) {
  const bool measured = measurement.measured || !measurement.error.empty();
  if (!measured || frame_json.empty() || frame_json.back() != '}') return frame_json;
  frame_json.pop_back();
  std::string measure;
  if (measurement.measured) {
    measure = MeasuredItemJson(measurement.item);
    measure.pop_back();
  } else {
    measure = "{\"error\": " + JsonQuote(measurement.error);
  }
  char ms[48];
  std::snprintf(ms, sizeof(ms), ", \"ms\": %.3f}", measurement.ms);
  return frame_json + ", \"measure\": " + measure + ms + "}";
}

}  // namespace reconar::tools
