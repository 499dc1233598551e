#include "tools/ar_args.h"

#include <cstdlib>
#include <vector>

#include "core/io/intrinsics_file.h"

namespace reconar::tools {

Result<CameraIntrinsics> IntrinsicsFromArg(const std::string& value) {
  if (value.find(',') == std::string::npos) return ReadIntrinsics(value);
  std::vector<double> numbers;
  size_t pos = 0;
  while (pos <= value.size()) {
    const size_t comma = value.find(',', pos);
    const std::string item = value.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    char* end = nullptr;
    const double number = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) {
      return InvalidArgument("--intrinsics: '" + item + "' is not a number (expected fx,fy,cx,cy[,k1,k2])");
    }
    numbers.push_back(number);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  if (numbers.size() != 4 && numbers.size() != 6) {
    return InvalidArgument("--intrinsics: expected 4 or 6 numbers (fx,fy,cx,cy[,k1,k2]), got " +
                           std::to_string(numbers.size()));
  }
  CameraIntrinsics intrinsics;
  intrinsics.fx = numbers[0];
  intrinsics.fy = numbers[1];
  intrinsics.cx = numbers[2];
  intrinsics.cy = numbers[3];
  if (numbers.size() == 6) {
    intrinsics.k1 = numbers[4];
    intrinsics.k2 = numbers[5];
  }
  if (!intrinsics.valid()) return InvalidArgument("--intrinsics: fx and fy must be positive");
  return intrinsics;
}

Result<std::optional<ArProject>> ProjectFromArgs(const Args& args, TrackerDefaults* defaults) {
  if (!args.Has("project")) return std::optional<ArProject>();
  ArProjectOptions options;
  options.load_map = !args.Has("no-map");
  RECONAR_ASSIGN_OR_RETURN(ArProject project, LoadArProject(args.Get("project"), options));
  defaults->intrinsics.reset();
  if (!project.photo_cameras.empty()) defaults->intrinsics = project.photo_cameras.front();
  defaults->track_tags = project.has_tags;
  if (project.has_tags) {
    defaults->tag_size = project.tag_size;
    defaults->family = project.family;
  }
  return std::optional<ArProject>(std::move(project));
}

Result<TagTrackerOptions> TrackerOptionsFromArgs(const Args& args, const TrackerDefaults& defaults) {
  TagTrackerOptions options;
  if (args.Has("intrinsics")) {
    auto intrinsics = IntrinsicsFromArg(args.Get("intrinsics"));
    if (!intrinsics.ok()) return intrinsics.status();
    options.intrinsics = *intrinsics;
  } else if (defaults.intrinsics) {
    options.intrinsics = *defaults.intrinsics;
  } else {
    return InvalidArgument("--intrinsics is required (fx,fy,cx,cy or a file)");
  }
  if (!defaults.track_tags) return options;
  if (!args.Has("tag-size") && !defaults.tag_size) {
    return InvalidArgument("--tag-size is required (metres, edge of the black square)");
  }
  auto tag_size = args.GetDouble("tag-size", defaults.tag_size.value_or(0.0), 1e-4, 100.0);
  if (!tag_size.ok()) return tag_size.status();
  options.tag_size = *tag_size;
  auto family = ParseTagFamily(args.Get("family", defaults.family.value_or("tag36h11")));
  if (!family.ok()) return family.status();
  options.detector.family = *family;
  auto decimate = args.GetDouble("decimate", options.detector.quad_decimate, 1.0, 8.0);
  if (!decimate.ok()) return decimate.status();
  options.detector.quad_decimate = static_cast<float>(*decimate);
  auto threads = args.GetInt("threads", 1, 1, 64);
  if (!threads.ok()) return threads.status();
  options.detector.threads = *threads;
  auto interval = args.GetInt("full-frame-interval", options.full_frame_interval, 0, 1000000);
  if (!interval.ok()) return interval.status();
  options.full_frame_interval = *interval;
  auto max_tags = args.GetInt("max-tags", options.max_tags, 1, 1024);
  if (!max_tags.ok()) return max_tags.status();
  options.max_tags = *max_tags;
  if (Status s = options.Check(); !s.ok()) return s;
  return options;
}

}  // namespace reconar::tools
