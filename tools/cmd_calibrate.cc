// reconar calibrate: camera intrinsics (fx, fy, cx, cy, k1, k2) from photos of AprilTags.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/base/json_writer.h"
#include "core/pipeline/project.h"
#include "tools/commands.h"
#include "tracker/calibration.h"
#include "tracker/calibration_photos.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar calibrate IMAGES_DIR|IMAGE... --tag-size METRES --out FILE [options]\n"
    "\n"
    "Estimates the camera's intrinsics from photos (same camera, same size) showing AprilTags of a\n"
    "known size, from several viewpoints and tilts: Zhang's closed form on each tag's homography,\n"
    "then Levenberg-Marquardt over intrinsics and all tag poses. Tags anywhere work (a room with\n"
    "tags on its walls); with --layout, the tags of one rigid board share a pose per photo.\n"
    "Writes FILE in the format `reconar track/view --intrinsics FILE` reads.\n"
    "  --family F              tag family (default tag36h11)\n"
    "  --layout FILE           rigid multi-tag layout (tag_layout.h format)\n"
    "  --decimate D            quad decimation for detection (default 1: photos, small tags)\n"
    "  --fix-principal-point   keep cx, cy at the image centre\n"
    "  --no-distortion         keep k1 = k2 = 0\n"
    "  --json                  print the report as JSON on stdout\n";

}  // namespace

int RunCalibrate(int argc, char** argv, int first) {
  Args args({"tag-size", "out", "family", "layout", "decimate"}, {"fix-principal-point", "no-distortion", "json"});
  const CommandUsage usage = {1, SIZE_MAX, {"tag-size", "out"}};
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, usage)) return *exit_code;
  auto tag_size = args.GetDouble("tag-size", 0.0, 1e-4, 100.0);
  if (!tag_size.ok()) return Fail(tag_size.status());
  CalibrationPhotoOptions photo_options;
  auto family = ParseTagFamily(args.Get("family", "tag36h11"));
  if (!family.ok()) return Fail(family.status());
  photo_options.detector.family = *family;
  auto decimate = args.GetDouble("decimate", 1.0, 1.0, 8.0);
  if (!decimate.ok()) return Fail(decimate.status());
  photo_options.detector.quad_decimate = static_cast<float>(*decimate);
  auto paths = CollectImagePaths(args.positionals());
  if (!paths.ok()) return Fail(paths.status());

  CalibrationObservations targets;
  targets.tag_size = *tag_size;
  if (args.Has("layout")) {
    auto layout = ReadTagLayout(args.Get("layout"));
    if (!layout.ok()) return Fail(layout.status());
    targets.layout = std::move(*layout);
  }
  CalibrationOptions options;
  options.fix_principal_point = args.Has("fix-principal-point");
  if (args.Has("no-distortion")) options.estimate_k1 = options.estimate_k2 = false;
  auto run = CalibrateFromPhotos(*paths, std::move(targets), photo_options, options, args.Get("out"));
  if (!run.ok()) return Fail(run.status());
  const CalibrationReport* report = &run->calibration;

  const CameraIntrinsics& k = report->intrinsics;
  if (args.Has("json")) {
    JsonWriter json(2);
    json.BeginObject().Key("intrinsics").BeginObject();
    json.Key("width").Int(k.width).Key("height").Int(k.height);
    json.Key("fx").Double(k.fx).Key("fy").Double(k.fy).Key("cx").Double(k.cx).Key("cy").Double(k.cy);
    json.Key("k1").Double(k.k1).Key("k2").Double(k.k2).EndObject();
    json.Key("stddev").BeginObject();
    const char* names[6] = {"fx", "fy", "cx", "cy", "k1", "k2"};
    for (int i = 0; i < 6; ++i) json.Key(names[i]).Double(report->stddev[i]);
    json.EndObject();
    json.Key("rms_px").Double(report->rms_px).Key("initial_rms_px").Double(report->initial_rms_px);
    json.Key("images").Int(static_cast<long long>(run->images));
    json.Key("images_used").Int(report->num_images_used).Key("targets").Int(report->num_targets);
    json.Key("corners").Int(report->num_corners).Key("iterations").Int(report->iterations);
    json.Key("converged").Bool(report->converged).EndObject();
    std::printf("%s\n", json.str().c_str());
  }
  std::fprintf(stderr,
               "reconar calibrate: %d tags found; %d image(s), %d tag view(s), %d corners; rms %.3f px (closed form %.3f)\n"
               "  fx %.2f ± %.2f  fy %.2f ± %.2f  cx %.2f ± %.2f  cy %.2f ± %.2f  k1 %.4f ± %.4f  k2 %.4f ± %.4f\n"
               "  written to %s\n",
               run->tags_found, report->num_images_used, report->num_targets, report->num_corners, report->rms_px,
               report->initial_rms_px, k.fx, report->stddev[0], k.fy, report->stddev[1], k.cx, report->stddev[2], k.cy,
               report->stddev[3], k.k1, report->stddev[4], k.k2, report->stddev[5], args.Get("out").c_str());
  return 0;
}

}  // namespace reconar::tools
