// `reconar sfm`: the sparse stages of `reconar reconstruct` (features, matching, mapping).
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar sfm IMAGES_DIR|IMAGE... PROJECT_DIR [options]\n"
    "\n"
    "Structure from motion: SIFT features, kd-forest matching with two-view verification, then\n"
    "incremental mapping with bundle adjustment (focal, k1, k2 per camera: images of one size\n"
    "without EXIF, or with the same EXIF focal, share a camera; the principal point and the\n"
    "distortion are refined in the final adjustment when the data supports it). This is\n"
    "`reconar reconstruct --stages sparse --no-preview`: the same stages and settings, so either\n"
    "command continues a project the other started. Writes into PROJECT_DIR:\n"
    "  features/ matches/                      the earlier stages (reused when up to date)\n"
    "  sparse/cameras.txt images.txt points3D.txt   COLMAP text model\n"
    "  sparse/bundle.out list.txt              Bundler v0.3\n"
    "  sparse/points.ply                       coloured sparse points\n"
    "  sparse/report.json                      counts, focal statistics, bundle adjustment\n"
    "  report.json                             as `reconar reconstruct`: Table 1, seconds per stage\n"
    "Re-running reuses every stage finished with the same settings (PROJECT_DIR/stages.txt);\n"
    "--force redoes all of them.\n"
    "  --principal-point fixed|auto|refine   (default auto)\n"
    "  --fixed-distortion    keep k1 = k2 = 0 (for photos that are already undistorted)\n"
    "What adapts to the photos by itself (docs/reconstruct.md, \"Captures as people make them\"):\n"
    "photos that match poorly, or that mapping registers only weakly, are extracted again at a lower\n"
    "contrast threshold and matched again (matches/report.json says which and why); an image seen by\n"
    "too few points for 30 inliers registers provisionally from fewer, or from a neighbour's\n"
    "two-view geometry, when the pose verifies, and is taken out again if a later adjustment no\n"
    "longer holds it; models that end apart are joined when their shared points or verified\n"
    "two-view geometries align them and the joined model verifies. To turn parts off:\n"
    "  --strict-registration register only poses with 30 inliers (no provisional registrations)\n"
    "  --separate-models     keep the models mapping ends with apart (sparse/model2, ...)\n"
    "  --no-reextraction     keep every photo's first features\n"
    "  --max-error PX        reprojection error bound for triangulation and filtering (default 4)\n"
    "  --ratio R             Lowe ratio (default 0.8 here)\n"
    "  --min-inliers N       inliers a pair needs (default 30 here)\n"
    "  --tag-size M          register in metres by AprilTags (see `reconar reconstruct --help`)\n"
    "  --memory-budget SIZE  bound for every stage (default 2560M)\n"
    "  --threads N           worker threads (default: one per core)\n"
    "  --force               recompute every stage\n"
    "  --json                print report.json on stdout\n"
    "  plus the options of `reconar features` and `reconar match`\n";

}  // namespace

int RunSfm(int argc, char** argv, int first) {
  return RunReconstructCommand(argc, argv, first, kHelp, /*sparse_only=*/true);
}

}  // namespace reconar::tools
