// reconar: photos to a metric 3D model, shown in AR. Thin subcommands over the libraries.
#include <cstdio>
#include <cstring>
#include <string>

#include "core/base/build_info.h"
#include "core/base/cpu_features.h"
#include "core/pipeline/simd_kernels.h"
#include "tools/commands.h"

namespace {

constexpr char kUsage[] =
    "usage: reconar COMMAND [ARGS] [--help]\n"
    "       reconar --version                              version, build type and the SIMD kernels this CPU runs\n"
    "                                                      (RECONAR_<DISPATCHER>_KERNEL=<kernel> forces one)\n"
    "\n"
    "commands:\n"
    "  reconstruct IMAGES_DIR PROJECT_DIR [--tag-size M]   the whole job: photos to a metric mesh (+ preview)\n"
    "  features IMAGE|DIR... [--project DIR] [--key OUT]   SIFT keypoints and descriptors\n"
    "  match IMAGE_A IMAGE_B [--pairs OUT.txt]             verified matches between two photos\n"
    "  match --project DIR                                 verified matches between all pairs of a project\n"
    "  sfm IMAGES_DIR PROJECT_DIR                          cameras and sparse points (structure from motion)\n"
    "  map PROJECT_DIR                                     localisation map for markerless AR (rebuild)\n"
    "  localize PROJECT_DIR IMAGE|DIR... [--json]          camera poses of photos against the map\n"
    "  measure PROJECT_DIR --distance A B [--json]        distances, areas, heights with their +- (sigma)\n"
    "  compare PROJECT_DIR DESIGN [--control FILE]         as built against its design, element by element\n"
    "  dense PROJECT_DIR                                   dense oriented points (multi-view stereo)\n"
    "  texture PROJECT_DIR [--exclude NAMES]               the mesh textured from the photos (textured.glb)\n"
    "  mesh POINTS.ply OUT.{ply,obj,glb,wrl} [--depth N]   Poisson surface from oriented points\n"
    "  export IN.{ply,glb,obj} OUT.{ply,obj,glb,wrl}       convert a mesh or point cloud between formats\n"
    "  bundle-adjust --bal FILE [--json]                   solve a BAL bundle adjustment problem\n"
    "  tags --ids LIST --size METRES --out FILE.{svg,pdf}  printable AprilTag sheet\n"
    "  tags IMAGES_DIR|IMAGE... [--json]                   the AprilTags in photos\n"
    "  track SOURCE --intrinsics K --tag-size M [--json]   6-DoF tag tracking, one line per frame\n"
    "  capture SOURCE PROJECT_DIR [--max-keyframes N]      keyframes from a camera, with advice\n"
    "  view --model M (--camera DEV | --frames DIR) ...    AR overlay: live window or PNGs (--out)\n"
    "  render PROJECT_DIR IMAGE_NAME... --out DIR          the model drawn from photos' viewpoints\n"
    "  calibrate IMAGES... --tag-size M --out FILE         camera intrinsics from photos of tags\n"
    "\n"
    "exit codes: 0 ok, 1 failed run, 2 bad usage or input\n";

// "reconar 0.1.0 (Release)", the CPU's SIMD features and the kernel each dispatcher selected,
// among which, and whether its RECONAR_<DISPATCHER>_KERNEL variable set it.
int PrintVersion() {
  std::printf("reconar %s (%s)\ncpu: %s\n", reconar::ReconarVersion(), reconar::ReconarBuildType(),
              reconar::CpuFeatureNames(reconar::HostCpuFeatures()).c_str());
  for (const reconar::KernelChoice& choice : reconar::SimdKernelReport()) {
    std::string available;
    for (const std::string& name : choice.available) available += " " + name;
    const std::string set_by =
        choice.overridden ? "; set by " + reconar::KernelOverrideVariable(choice.dispatcher) : "";
    std::printf("kernel %s: %s (of%s%s)\n", choice.dispatcher.c_str(), choice.kernel().c_str(), available.c_str(),
                set_by.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  if (command == "--version") return PrintVersion();
  if (command == "features") return reconar::tools::RunFeatures(argc, argv, 2);
  if (command == "match") return reconar::tools::RunMatch(argc, argv, 2);
  if (command == "sfm") return reconar::tools::RunSfm(argc, argv, 2);
  if (command == "bundle-adjust") return reconar::tools::RunBundleAdjust(argc, argv, 2);
  if (command == "tags") return reconar::tools::RunTags(argc, argv, 2);
  if (command == "track") return reconar::tools::RunTrack(argc, argv, 2);
  if (command == "calibrate") return reconar::tools::RunCalibrate(argc, argv, 2);
  if (command == "export") return reconar::tools::RunExport(argc, argv, 2);
  if (command == "mesh") return reconar::tools::RunMesh(argc, argv, 2);
  if (command == "measure") return reconar::tools::RunMeasure(argc, argv, 2);
  if (command == "compare") return reconar::tools::RunCompare(argc, argv, 2);
  if (command == "dense") return reconar::tools::RunDense(argc, argv, 2);
  if (command == "texture") return reconar::tools::RunTexture(argc, argv, 2);
  if (command == "reconstruct") return reconar::tools::RunReconstruct(argc, argv, 2);
  if (command == "map") return reconar::tools::RunMap(argc, argv, 2);
  if (command == "localize") return reconar::tools::RunLocalize(argc, argv, 2);
  if (command == "capture") return reconar::tools::RunCapture(argc, argv, 2);
  if (command == "view" || command == "render") {
#ifdef RECONAR_HAVE_VIEW
    return command == "view" ? reconar::tools::RunView(argc, argv, 2) : reconar::tools::RunRender(argc, argv, 2);
#else
    std::fprintf(stderr, "reconar: %s needs the GLES renderer; this build has RECONAR_WITH_GLES=OFF\n", command.c_str());
    return 2;
#endif
  }
  std::fprintf(stderr, "reconar: unknown command '%s'\n\n%s", command.c_str(), kUsage);
  return 2;
}
