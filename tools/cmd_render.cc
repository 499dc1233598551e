#include <cstdio>
#include <string>

#include "render/ar/photo_render.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar render PROJECT_DIR IMAGE_NAME... --out DIR [--model PATH]\n"
    "\n"
    "Draws the project's model alone from the viewpoint of registered photos, with each photo's\n"
    "camera undistorted (same focal length, principal point and size; no lens distortion):\n"
    "  DIR/NAME.png         the model, unlit, on black (its vertex colours, or its texture at the\n"
    "                       photo's exposure: the photo's own gain when it was textured from,\n"
    "                       else the gain its EXIF exposure settings predict)\n"
    "  DIR/NAME.mask.png    white where the model covers the pixel\n"
    "  DIR/NAME.photo.png   the photo undistorted to the same camera, to compare with\n"
    "IMAGE_NAME is a photo's file name as the project lists it (e.g. IMG_1415.JPG).\n"
    "  --out DIR        where to write (created)\n"
    "  --model PATH     the model to draw (.glb with or without texture, .ply, .obj); default the\n"
    "                   project's textured model (mesh/textured.glb), else its mesh (mesh/mesh.ply)\n"
    "  --no-photos      do not write NAME.photo.png\n"
    "  --as-textured    draw the texture at its own exposure, not the photo's\n";

}  // namespace

int RunRender(int argc, char** argv, int first) {
  Args args({"out", "model"}, {"no-photos", "as-textured"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, 100000)) return *exit_code;
  if (!args.Has("out")) return Fail(InvalidArgument("render: --out DIR is required"));
  PhotoRenderOptions options;
  options.image_names.assign(args.positionals().begin() + 1, args.positionals().end());
  options.out_dir = args.Get("out");
  options.model_path = args.Get("model");
  options.write_photos = !args.Has("no-photos");
  options.match_photo_exposure = !args.Has("as-textured");
  auto report = RenderFromPhotos(args.positionals()[0], options);
  if (!report.ok()) return Fail(report.status());
  if (!report->warning.empty()) std::fprintf(stderr, "warning: render: %s\n", report->warning.c_str());
  std::printf("render: %s (%zu faces, %s)\n", report->model_path.c_str(), report->faces,
              report->textured ? "textured" : "vertex colours");
  for (size_t i = 0; i < report->written.size(); ++i) {
    std::printf("render: %s (model covers %.0f%%", report->written[i].c_str(), 100.0 * report->coverage[i]);
    if (report->textured) {
      const Eigen::Vector3f& gain = report->gain[i];
      std::printf("; exposure: %s, gain %.2f %.2f %.2f", RenderExposureName(report->exposure[i]), gain.x(), gain.y(),
                  gain.z());
    }
    std::printf(")\n");
  }
  return 0;
}

}  // namespace reconar::tools
