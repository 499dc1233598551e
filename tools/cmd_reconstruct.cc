// `reconar reconstruct`: photos in, a metric 3D model out (core/pipeline/reconstruct.h).
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar reconstruct IMAGES_DIR|IMAGE... PROJECT_DIR [options]\n"
    "\n"
    "The whole job: SIFT features, matching, AprilTags in the photos (with --tag-size), incremental\n"
    "structure from motion with the tag corners in bundle adjustment, registration in metres to the\n"
    "reference tag, dense multi-view stereo, Poisson meshing and exports, and the mesh textured from\n"
    "the photos. Writes into PROJECT_DIR:\n"
    "  features/ matches/ tags/ sparse/ dense/    each stage's outputs (see `reconar sfm --help`, `dense`)\n"
    "  mesh/mesh.{ply,obj,glb,wrl}                the model (metres in the world tag's frame with tags)\n"
    "  mesh/textured.{glb,obj,mtl,png}            the model textured from the photos (`reconar texture`)\n"
    "  tags.json                                  every reconstructed tag: corners (m), views, edges\n"
    "  report.json                                paper Table 1, tags, seconds and peak memory per stage\n"
    "  preview.png                                what the run made (mesh, else points) seen from around it\n"
    "An interrupted run (even killed) re-run with the same options redoes only the unfinished stages\n"
    "and gives the same files; `reconar sfm` is the sparse stages of this command and shares them.\n"
    "View the result with `reconar view --project PROJECT_DIR ...`.\n"
    "  --tag-size M          edge of the tags' black square in metres; enables tag registration\n"
    "  --tag-family F        tag36h11 (default), tag25h9, tag16h5, tagStandard41h12, tagCircle21h7\n"
    "  --world-tag ID        the tag whose frame is the world frame (default: the lowest id seen)\n"
    "  --layout FILE         the world frame of a tag layout (tags.layout format, e.g. another\n"
    "                        project's): fitted to every reconstructed tag it holds\n"
    "  --scale-tags IDS      only these tags' size sets the scale, e.g. 0-9,12 (default: every tag);\n"
    "                        the others still register and check it (tags.json held_out_*)\n"
    "  --no-tags-in-ba       only triangulate the tags from the final cameras (not as constraints)\n"
    "  --memory-budget SIZE  bound for every stage: MiB, or with a unit (512K, 1500M, 1G); default 2560M\n"
    "  --threads N           worker threads (default: one per core)\n"
    "  --stages LIST         comma-separated subset of sparse,dense,mesh,texture (default all)\n"
    "  --principal-point fixed|auto|refine, --fixed-distortion, --max-error PX,\n"
    "  --strict-registration, --separate-models, --no-reextraction\n"
    "                        as `reconar sfm`\n"
    "  --ratio R, --min-inliers N, --checks N, --f-threshold T   matching (defaults 0.8, 30, 200, 0.006)\n"
    "  --exhaustive-up-to N, --window W, --retrieved R   the pairs matched, as `reconar match`\n"
    "                        (defaults 50, 10, 40)\n"
    "  --level 0|1|2|auto    dense image resolution (default auto: the finest that fits the budget\n"
    "                        with the longest side at most --max-image-size)\n"
    "  --max-image-size N    dense: longest image side of the auto level (default 2400; 0: no limit)\n"
    "  --method patchmatch|pmvs  dense multi-view stereo (default patchmatch), as `reconar dense`\n"
    "  --no-fill             PatchMatch: leave texture-poor pixels empty, as `reconar dense`\n"
    "  --depth N             finest Poisson depth (default 10; never finer than the points' spacing,\n"
    "                        lowered when the budget demands)\n"
    "  --trim T              Poisson density trim (default 7)\n"
    "  --max-faces N         simplify a larger mesh to N triangles (quadric edge collapse) before it is\n"
    "                        written, for rendering on a handheld (default 500000; 0: keep all)\n"
    "  --formats LIST        mesh formats among ply,obj,glb,wrl (default all four)\n"
    "  --no-preview          do not render preview.png\n"
    "  --contrast-threshold T, --max-features N, --first-octave O, --sift-memory-mib M\n"
    "                        as `reconar features`\n"
    "  --force               redo every stage\n"
    "  --json                print report.json on stdout\n";

}  // namespace

int RunReconstruct(int argc, char** argv, int first) {
  return RunReconstructCommand(argc, argv, first, kHelp, /*sparse_only=*/false);
}

}  // namespace reconar::tools
