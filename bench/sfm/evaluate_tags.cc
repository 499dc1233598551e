// evaluate_tags: how well a sparse model (COLMAP text: ours or COLMAP's own) measures the AprilTags
// seen in its photos. Each tag's corners are triangulated from the model's cameras (the path
// `reconar reconstruct --no-tags-in-ba` takes), the model is scaled by the mean edge of all tags,
// and the edges are compared with the printed size, also with each tag held out of the scale.
// A JSON object on stdout (a compact form of tags.json, written by core/base JsonWriter with one
// key per line); --tags-json writes the full tags.json.
//
//   evaluate_tags MODEL_DIR DETECTIONS --tag-size METRES [--tags-json FILE]
//
// DETECTIONS is a project's tags/detections.txt; images are matched by file name (the last path
// component of NAME in images.txt). Exit codes: 0 ok, 1 no tag could be measured, 2 bad usage or input.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_observations.h"
#include "core/sfm/tag_registration.h"

namespace reconar {
namespace {

int Usage(const char* message) {
  if (message != nullptr) std::fprintf(stderr, "evaluate_tags: %s\n", message);
  std::fprintf(stderr,
               "usage: evaluate_tags MODEL_DIR DETECTIONS --tag-size METRES [--tags-json FILE]\n"
               "  MODEL_DIR   cameras.txt, images.txt, points3D.txt (COLMAP text)\n"
               "  DETECTIONS  tags/detections.txt of a reconar project on the same photos\n");
  return 2;
}

int Run(int argc, char** argv) {
  std::vector<std::string> positional;
  double tag_size = 0.0;
  std::string tags_json;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--tag-size" && i + 1 < argc) {
      tag_size = std::atof(argv[++i]);
    } else if (arg == "--tags-json" && i + 1 < argc) {
      tags_json = argv[++i];
    } else if (arg == "-h" || arg == "--help") {
      return Usage(nullptr);
    } else if (!arg.empty() && arg[0] == '-') {
      return Usage(("unknown option " + arg).c_str());
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.size() != 2) return Usage("needs MODEL_DIR and DETECTIONS");
  if (!(tag_size > 0.0)) return Usage("--tag-size must be a positive number of metres");

  auto model = ReadColmapTextModel(positional[0]);
  if (!model.ok()) return Usage(model.status().ToString().c_str());
  auto detections = ReadTagDetections(positional[1]);
  if (!detections.ok()) return Usage(detections.status().ToString().c_str());

  std::map<std::string, const ImageTagObservations*> by_name;
  for (const ImageTagObservations& image : detections->images) by_name[image.image_name] = &image;
  std::vector<std::vector<TagObservation>> observations(model->images.size());
  for (size_t i = 0; i < model->images.size(); ++i) {
    const auto found = by_name.find(std::filesystem::path(model->images[i].name).filename().string());
    if (found != by_name.end()) observations[i] = found->second->tags;
  }
  TagRegistrationOptions options;
  options.tag_size_m = tag_size;
  auto report = RegisterToTags(observations, {}, options, &*model);
  if (!report.ok()) return Usage(report.status().ToString().c_str());
  if (!tags_json.empty()) {
    const Status written = WriteFileAtomically(tags_json, TagRegistrationJson(*report, detections->family, tag_size));
    if (!written.ok()) return Usage(written.ToString().c_str());
  }
  // Pretty-printed: compare_tag_edges.sh reads one "key": value per line.
  JsonWriter json(2);
  json.BeginObject();
  if (!report->metric) {
    json.Key("metric").Bool(false).Key("reason").String(report->reason).EndObject();
    std::printf("%s\n", json.str().c_str());
    return 1;
  }
  // Edges 0 and 2 run along the tag's x axis, 1 and 3 along y: a difference between the two shows
  // a print (or pixel) aspect error rather than a reconstruction one.
  double x_sum = 0.0, y_sum = 0.0;
  for (const RegisteredTag& tag : report->tags) {
    x_sum += tag.edges_m[0] + tag.edges_m[2];
    y_sum += tag.edges_m[1] + tag.edges_m[3];
  }
  const double pairs = 2.0 * static_cast<double>(report->tags.size());
  json.Key("registered").Int(model->NumRegisteredImages());
  json.Key("tags").Int(static_cast<long long>(report->tags.size()));
  json.Key("edge_mean_m").Double(report->edge_mean_m);
  json.Key("edge_std_m").Double(report->edge_std_m);
  json.Key("edge_max_abs_error_m").Double(report->edge_max_abs_error_m);
  json.Key("held_out_edge_mean_m").Double(report->held_out_edge_mean_m);
  json.Key("held_out_edge_std_m").Double(report->held_out_edge_std_m);
  json.Key("held_out_edge_max_abs_error_m").Double(report->held_out_edge_max_abs_error_m);
  json.Key("x_edge_mean_m").Double(x_sum / pairs);
  json.Key("y_edge_mean_m").Double(y_sum / pairs);
  json.Key("tag_mean_edge_m").BeginObject();
  for (const RegisteredTag& tag : report->tags) {
    json.Key(std::to_string(tag.id)).Double((tag.edges_m[0] + tag.edges_m[1] + tag.edges_m[2] + tag.edges_m[3]) / 4.0);
  }
  json.EndObject().EndObject();
  std::printf("%s\n", json.str().c_str());
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
