// The dense-accuracy figures, printed: the rendered bunny (dense points and their Poisson mesh
// against bun_zipper.ply, Middlebury accuracy at 90 % and completeness at 1.25 mm) and templeRing
// with its ground-truth cameras (point count, share inside the README's bounding box).
// run_dense_figures.sh wraps each scene in /usr/bin/time -v for the peak RSS.
//
// Usage: bench_dense_figures bunny|templering [--method pmvs|patchmatch] [--level L] [--threads N]
//                            [--depth D] [--trim T] [--stride S] [--project DIR] [--keep-outliers]
//                            [--visibility-angle DEG] [--no-fill] [shared_data_dir]
// --keep-outliers runs the dense stage without its outlier filter, then applies the filter here and
// says how many of the points each of its two tests removes, and keeps, are wrong by the scene's
// truth: farther than two pixel footprints from bun_zipper's surface, or outside templeRing's box.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/mesh/mesh_io.h"
#include "core/mesh/poisson/point_outliers.h"
#include "platform/egl/egl_context.h"
#include "tests/dense/bunny_dense.h"
#include "tests/dense/dense_runs.h"

namespace reconar {
namespace {

struct Args {
  std::string scene;
  DenseMethod method = DenseMethod::kPmvs;
  PatchMatchOptions patchmatch;  // --no-fill: PatchMatchOptions::fill_min_support 0
  bool keep_outliers = false;
  int level = -2;  // -2: the scene's default (bunny 0, templeRing 1)
  int threads = 0;
  int depth = 8;
  double trim = 7.0;
  int stride = 1;
  double visibility_angle_deg = 60.0;  // bunny: the angle within which a view counts as seeing a vertex
  std::string project;
  std::string data_dir = RECONAR_SHARED_DATA_DIR;
};

int Usage(const char* message) {
  std::fprintf(stderr,
               "bench_dense_figures: %s\n"
               "usage: bench_dense_figures bunny|templering [--method pmvs|patchmatch] [--level L] [--threads N]\n"
               "                           [--depth D] [--trim T] [--stride S] [--project DIR] [--keep-outliers]\n"
               "                           [--visibility-angle DEG] [--no-fill] [shared_data_dir]\n",
               message);
  return 2;
}

void PrintDense(const DenseStageReport& dense) {
  std::printf("dense: level %d, %d images (%d kept), %d clusters, %zu points (%zu before merge)\n", dense.level,
              dense.images, dense.kept_images, dense.clusters, dense.points, dense.points_before_merge);
  std::printf("dense phases s: load %.1f clustering %.1f undistort %.1f mvs %.1f merge %.1f outliers %.1f write %.1f\n",
              dense.load.seconds, dense.clustering.seconds, dense.undistort.seconds, dense.mvs.seconds,
              dense.merge.seconds, dense.outlier_filter.seconds, dense.write.seconds);
  if (dense.method == DenseMethod::kPatchMatch) {
    const PatchMatchReport& m = dense.patchmatch;
    std::printf(
        "patchmatch: %zu depth maps, %zu depth pixels, %zu fused; s: selection %.1f propagation %.1f "
        "consistency %.1f fusion %.1f\n",
        m.views, m.depth_pixels, m.fused_points, m.seconds_selection, m.seconds_propagation, m.seconds_consistency,
        m.seconds_fusion);
  } else {
    std::printf("pmvs: %zu features, %zu initial, %zu expanded, %zu final patches\n", dense.pmvs.features,
                dense.pmvs.initial_patches, dense.pmvs.expanded_patches, dense.pmvs.final_patches);
  }
  std::printf("outliers: %zu isolated, %zu in small pieces removed\n", dense.outliers.isolated_removed,
              dense.outliers.small_piece_removed);
}

// The outlier filter's two tests (core/mesh/poisson/point_outliers.h) on the unfiltered points,
// against `wrong` (the scene's truth): how many wrong and right points each removes and keeps.
void PrintFilterAgainstTruth(const std::vector<Eigen::Vector3f>& points, const std::vector<uint8_t>& wrong) {
  OutlierFilterOptions isolated_only;
  isolated_only.min_component_fraction = 0.0;
  auto first = FindInlierPoints(points, isolated_only);
  auto both = FindInlierPoints(points, OutlierFilterOptions());
  if (!first.ok() || !both.ok()) {
    std::fprintf(stderr, "bench_dense_figures: outlier filter: %s\n",
                 (first.ok() ? both.status() : first.status()).ToString().c_str());
    return;
  }
  size_t counts[3][2] = {};  // [isolated removed, small piece removed, kept][right, wrong]
  for (size_t i = 0; i < points.size(); ++i) {
    const int verdict = !(*first)[i] ? 0 : !(*both)[i] ? 1 : 2;
    ++counts[verdict][wrong[i] ? 1 : 0];
  }
  const char* names[3] = {"isolated, removed", "small pieces, removed", "kept"};
  for (int v = 0; v < 3; ++v) {
    std::printf(
        "FILTER %-22s %8zu points: %8zu right, %8zu wrong (%.3f wrong)\n", names[v], counts[v][0] + counts[v][1],
        counts[v][0], counts[v][1],
        counts[v][0] + counts[v][1] == 0 ? 0.0 : static_cast<double>(counts[v][1]) / (counts[v][0] + counts[v][1]));
  }
}

int RunBunny(const Args& args, const std::string& project) {
  auto context = EglContext::Create([] {
    EglContextOptions options;
    options.kind = EglContextKind::kSurfaceless;
    return options;
  }());
  if (!context.ok()) return Usage(context.status().ToString().c_str());
  auto bunny = ReadPly(args.data_dir + "/stanford_bunny/reconstruction/bun_zipper.ply");
  if (!bunny.ok()) return Usage(bunny.status().ToString().c_str());
  testing::BunnyDenseOptions options;
  options.method = args.method;
  options.remove_outliers = !args.keep_outliers;
  options.patchmatch = args.patchmatch;
  options.level = args.level == -2 ? 0 : args.level;
  options.num_threads = args.threads;
  options.poisson.depth = args.depth;
  options.poisson.trim = args.trim;
  options.project.visibility_max_angle_deg = args.visibility_angle_deg;
  auto figures = testing::RunBunnyDense(*bunny, project, options);
  if (!figures.ok()) {
    std::fprintf(stderr, "bench_dense_figures: %s\n", figures.status().ToString().c_str());
    return 1;
  }
  const testing::BunnySceneReport& scene = figures->scene;
  std::printf(
      "bunny scene: %d views %dx%d, foreground %.3f, seen by >= 2 / >= 3 views within %.0f deg %.3f / %.3f, "
      "footprint %.3f mm; render %.1f s\n",
      scene.views, options.project.scene.width, options.project.scene.height, scene.mean_foreground_fraction,
      args.visibility_angle_deg, scene.visibility.seen_by_2_fraction, scene.visibility.seen_by_3_fraction,
      1e3 * scene.pixel_footprint_at_center_m, figures->seconds_render);
  PrintDense(figures->dense);
  std::printf("dense wall %.1f s\n", figures->seconds_dense);
  std::printf("POINTS  accuracy(90%%) %.3f mm  completeness(1.25 mm) %.3f  (%zu points)\n",
              1e3 * figures->points.accuracy, figures->points.completeness, figures->points.points);
  std::printf("POISSON depth %d trim %.1f: %zu vertices %zu triangles, %.1f s; accuracy(90%%) %.3f mm  "
              "completeness %.3f\n",
              args.depth, args.trim, figures->mesh_vertices, figures->mesh_triangles, figures->seconds_poisson,
              1e3 * figures->mesh.accuracy, figures->mesh.completeness);
  const testing::MeshComparison& c = figures->mesh_to_reference;
  std::printf("MESH vs bun_zipper: mesh->ref mean %.3f median %.3f p90 %.3f max %.3f mm; ref->mesh mean %.3f "
              "median %.3f p90 %.3f max %.3f mm\n",
              1e3 * c.mean_mesh_to_reference, 1e3 * c.median_mesh_to_reference, 1e3 * c.p90_mesh_to_reference,
              1e3 * c.max_mesh_to_reference, 1e3 * c.mean_reference_to_mesh, 1e3 * c.median_reference_to_mesh,
              1e3 * c.p90_reference_to_mesh, 1e3 * c.max_reference_to_mesh);
  std::printf("scoring %.1f s; project in %s\n", figures->seconds_scoring, project.c_str());
  if (args.keep_outliers) {
    auto points = testing::ReadDensePoints(project);
    if (!points.ok()) return Usage(points.status().ToString().c_str());
    const double wrong_beyond = 2.0 * scene.pixel_footprint_at_center_m * (1 << figures->dense.level);
    const testing::MeshDistanceField surface(*bunny);
    std::vector<uint8_t> wrong(points->size());
    for (size_t i = 0; i < points->size(); ++i) wrong[i] = surface.Distance((*points)[i]) > wrong_beyond ? 1 : 0;
    std::printf("wrong: farther than %.3f mm from bun_zipper\n", 1e3 * wrong_beyond);
    PrintFilterAgainstTruth(*points, wrong);
  }
  return 0;
}

int RunTempleRing(const Args& args, const std::string& project) {
  testing::TempleRingDenseOptions options;
  options.method = args.method;
  options.remove_outliers = !args.keep_outliers;
  options.patchmatch = args.patchmatch;
  options.level = args.level == -2 ? 1 : args.level;
  options.num_threads = args.threads;
  options.import.view_stride = args.stride;
  auto figures =
      testing::RunTempleRingDense(args.data_dir + "/middlebury_templeRing/templeR_par.txt", project, options);
  if (!figures.ok()) {
    std::fprintf(stderr, "bench_dense_figures: %s\n", figures.status().ToString().c_str());
    return 1;
  }
  std::printf("templeRing: %d views (stride %d)\n", figures->import.views, args.stride);
  PrintDense(figures->dense);
  std::printf("dense wall %.1f s\n", figures->seconds_dense);
  std::printf("POINTS %zu, in the README box (+%.1f mm) %zu = %.4f\n", figures->points, 1e3 * options.box_margin_m,
              figures->points_in_box, figures->in_box_fraction);
  std::printf("project in %s\n", project.c_str());
  if (args.keep_outliers) {
    auto points = testing::ReadDensePoints(project);
    if (!points.ok()) return Usage(points.status().ToString().c_str());
    const testing::Box3 box = testing::TempleRingBoundingBox();
    std::vector<uint8_t> wrong(points->size());
    for (size_t i = 0; i < points->size(); ++i) wrong[i] = box.Contains((*points)[i], options.box_margin_m) ? 0 : 1;
    std::printf("wrong: outside the README's box (+%.1f mm)\n", 1e3 * options.box_margin_m);
    PrintFilterAgainstTruth(*points, wrong);
  }
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  reconar::Args args;
  std::string positional[2];
  int positional_count = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--help" || arg == "-h") {
      reconar::Usage("dense-accuracy figures of one scene");
      return 0;
    } else if (arg == "--keep-outliers") {
      args.keep_outliers = true;
    } else if (arg == "--no-fill") {
      args.patchmatch.fill_min_support = 0;
    } else if (arg == "--method" && has_value) {
      auto method = reconar::ParseDenseMethod(argv[++i]);
      if (!method.ok()) return reconar::Usage(method.status().ToString().c_str());
      args.method = *method;
    } else if (arg == "--level" && has_value) {
      args.level = std::atoi(argv[++i]);
    } else if (arg == "--threads" && has_value) {
      args.threads = std::atoi(argv[++i]);
    } else if (arg == "--depth" && has_value) {
      args.depth = std::atoi(argv[++i]);
    } else if (arg == "--trim" && has_value) {
      args.trim = std::atof(argv[++i]);
    } else if (arg == "--visibility-angle" && has_value) {
      args.visibility_angle_deg = std::atof(argv[++i]);
    } else if (arg == "--stride" && has_value) {
      args.stride = std::atoi(argv[++i]);
    } else if (arg == "--project" && has_value) {
      args.project = argv[++i];
    } else if (arg.rfind("--", 0) == 0) {
      return reconar::Usage(("unknown or incomplete option " + arg).c_str());
    } else if (positional_count < 2) {
      positional[positional_count++] = arg;
    } else {
      return reconar::Usage("too many arguments");
    }
  }
  if (positional_count < 1) return reconar::Usage("expected a scene");
  args.scene = positional[0];
  if (positional_count == 2) args.data_dir = positional[1];
  const std::string project =
      args.project.empty() ? "/tmp/reconar_dense_" + args.scene + "_" + std::to_string(::getpid()) : args.project;
  if (args.scene == "bunny") return reconar::RunBunny(args, project);
  if (args.scene == "templering") return reconar::RunTempleRing(args, project);
  return reconar::Usage("the scene must be bunny or templering");
}
