// `reconar reconstruct`: photos in, a metric 3D model out (core/pipeline/reconstruct.h).
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "core/base/atomic_file.h"
#include "core/io/image_write.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/simplify.h"
#include "core/pipeline/reconstruct.h"
#include "core/sfm/model_io.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tracker/photo_tags.h"
#ifdef RECONAR_HAVE_VIEW
#include "render/preview.h"
#endif

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar reconstruct IMAGES_DIR|IMAGE... PROJECT_DIR [options]\n"
    "\n"
    "The whole job: SIFT features, matching, AprilTags in the photos (with --tag-size), incremental\n"
    "structure from motion with the tag corners in bundle adjustment, registration in metres to the\n"
    "reference tag, dense multi-view stereo, Poisson meshing and exports. Writes into PROJECT_DIR:\n"
    "  features/ matches/ tags/ sparse/ dense/    each stage's outputs (see `reconar sfm --help`, `dense`)\n"
    "  mesh/mesh.{ply,obj,glb,wrl}                the model (metres in the world tag's frame with tags)\n"
    "  tags.json                                  every reconstructed tag: corners (m), views, edges\n"
    "  report.json                                paper Table 1, tags, seconds and peak memory per stage\n"
    "  preview.png                                the mesh seen from around it\n"
    "An interrupted run (even killed) re-run with the same options redoes only the unfinished stages\n"
    "and gives the same files. View the result with `reconar view --project PROJECT_DIR ...`.\n"
    "  --tag-size M          edge of the tags' black square in metres; enables tag registration\n"
    "  --tag-family F        tag36h11 (default), tag25h9, tag16h5, tagStandard41h12, tagCircle21h7\n"
    "  --world-tag ID        the tag whose frame is the world frame (default: the lowest id seen)\n"
    "  --no-tags-in-ba       only triangulate the tags from the final cameras (not as constraints)\n"
    "  --memory-budget SIZE  bound for every stage: MiB, or with a unit (1G, 1500M); default 2560M\n"
    "  --threads N           worker threads (default: one per core)\n"
    "  --stages LIST         comma-separated subset of sparse,dense,mesh (default all)\n"
    "  --level 0|1|2|auto    dense image resolution (default auto: the finest that fits the budget)\n"
    "  --depth N             finest Poisson depth (default 10; never finer than the points' spacing,\n"
    "                        lowered when the budget demands)\n"
    "  --trim T              Poisson density trim (default 7)\n"
    "  --max-faces N         simplify a larger mesh to N triangles (quadric edge collapse) before it is\n"
    "                        written, for rendering on a handheld (default 500000; 0: keep all)\n"
    "  --formats LIST        mesh formats among ply,obj,glb,wrl (default all four)\n"
    "  --no-preview          do not render preview.png\n"
    "  --contrast-threshold T, --max-features N, --first-octave O, --sift-memory-mib M   as `reconar features`\n"
    "  --force               redo every stage\n"
    "  --json                print report.json on stdout\n";

Result<size_t> ParseSize(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  std::string unit(end);
  double mib = value;
  if (unit == "G" || unit == "g" || unit == "GiB" || unit == "GB") {
    mib = value * 1024.0;
  } else if (!(unit.empty() || unit == "M" || unit == "m" || unit == "MiB" || unit == "MB")) {
    return InvalidArgument("--memory-budget: '" + text + "' is not a size (MiB, or a number with M or G)");
  }
  if (!(mib >= 64.0) || mib > 1e7)
    return InvalidArgument("--memory-budget must be at least 64 MiB, got '" + text + "'");
  return static_cast<size_t>(mib * (1 << 20));
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

// The mean of the registered cameras' up (-y) directions: people hold cameras upright.
Eigen::Vector3d UpFromCameras(const Project& project) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  if (auto model = ReadColmapTextModel(project.SparseDir()); model.ok()) {
    for (const SfmImage& image : model->images) {
      if (image.registered) up -= image.pose.cam_from_world_rotation.row(1).transpose();
    }
  }
  return up.norm() > 1e-9 ? Eigen::Vector3d(up.normalized()) : Eigen::Vector3d(-Eigen::Vector3d::UnitY());
}

Status WritePreview(const Project& project, const std::string& model_path, const std::string& out_path) {
#ifdef RECONAR_HAVE_VIEW
  RECONAR_ASSIGN_OR_RETURN(const Mesh mesh, ReadMeshFile(model_path));
  PreviewOptions preview;
  preview.width = 480;
  preview.height = 360;
  preview.up = UpFromCameras(project);
  preview.directions = PreviewOptions::Ring(5, 20.0);
  RECONAR_ASSIGN_OR_RETURN(const std::vector<Image<uint8_t>> views, RenderPreviewViews(mesh, preview));
  return WritePng(out_path, TileImages(views, 3).view(), 3);
#else
  (void)project;
  (void)model_path;
  (void)out_path;
  return Unsupported("preview: this build has no renderer (RECONAR_WITH_GLES=OFF)");
#endif
}

}  // namespace

int RunReconstruct(int argc, char** argv, int first) {
  std::set<std::string> valued = kSiftValuedOptions;
  valued.insert({"tag-size", "tag-family", "world-tag", "memory-budget", "threads", "stages", "level", "depth", "trim",
                 "max-faces", "formats"});
  Args args(valued, {"no-tags-in-ba", "no-preview", "force", "json"});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (args.positionals().size() < 2) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  std::vector<std::string> inputs = args.positionals();
  const Project project(inputs.back());
  inputs.pop_back();

  ReconstructOptions options;
  auto sift = SiftOptionsFromArgs(args);
  if (!sift.ok()) return Fail(sift.status());
  options.features.sift = *sift;
  auto tag_size = args.GetDouble("tag-size", 0.0, 0.0, 100.0);
  auto world_tag = args.GetInt("world-tag", -1, -1, 1 << 20);
  auto threads = args.GetInt("threads", 0, 0, 1024);
  auto depth = args.GetInt("depth", 10, 5, 11);
  auto trim = args.GetDouble("trim", 7.0, 0.0, 20.0);
  auto max_faces = args.GetInt("max-faces", static_cast<int>(kHandheldMaxFaces), 0, 1 << 30);
  for (const Status& s :
       {tag_size.status(), world_tag.status(), threads.status(), depth.status(), trim.status(), max_faces.status()}) {
    if (!s.ok()) return Fail(s);
  }
  if (args.Has("tag-size") && !(*tag_size > 0.0)) return Fail(InvalidArgument("--tag-size must be positive"));
  options.tag_size_m = *tag_size;
  options.tag_family = args.Get("tag-family", "tag36h11");
  auto family = ParseTagFamily(options.tag_family);
  if (!family.ok()) return Fail(family.status());
  options.sfm.tags.registration.world_tag = *world_tag;
  options.sfm.tags.in_adjustment = !args.Has("no-tags-in-ba");
  options.num_threads = *threads;
  if (args.Has("memory-budget")) {
    auto budget = ParseSize(args.Get("memory-budget"));
    if (!budget.ok()) return Fail(budget.status());
    options.memory_budget_bytes = *budget;
  }
  // The sfm command's matching defaults (see `reconar sfm --help`).
  options.matching.match.max_ratio = 0.8;
  options.matching.two_view.min_inliers = 30;
  const std::string level = args.Get("level", "auto");
  if (level == "auto") {
    options.dense.level = -1;
  } else if (level == "0" || level == "1" || level == "2") {
    options.dense.level = level[0] - '0';
  } else {
    return Fail(InvalidArgument("--level must be 0, 1, 2 or auto, got '" + level + "'"));
  }
  options.mesh.poisson.depth = *depth;
  options.mesh.poisson.trim = *trim;
  options.mesh.max_faces = static_cast<size_t>(*max_faces);
  if (args.Has("formats")) options.mesh.formats = SplitCommas(args.Get("formats"));
  if (args.Has("stages")) {
    options.run_sparse = options.run_dense = options.run_mesh = false;
    for (const std::string& stage : SplitCommas(args.Get("stages"))) {
      if (stage == "sparse") {
        options.run_sparse = true;
      } else if (stage == "dense") {
        options.run_dense = true;
      } else if (stage == "mesh") {
        options.run_mesh = true;
      } else {
        return Fail(InvalidArgument("--stages: unknown stage '" + stage + "' (sparse, dense, mesh)"));
      }
    }
  }
  options.force = args.Has("force");
  PhotoTagOptions tag_options;
  tag_options.family = *family;
  tag_options.num_threads = options.num_threads;
  options.detect_tags = [tag_options](const std::vector<std::string>& paths) {
    return DetectTagsInPhotos(paths, tag_options);
  };

  auto paths = CollectImagePaths(inputs);
  if (!paths.ok()) return Fail(paths.status());
  if (paths->size() < 2) {
    return Fail(InvalidArgument("reconstruct needs at least 2 photos, got " + std::to_string(paths->size())));
  }
  auto report = RunReconstruct(*paths, project, options);
  if (!report.ok()) return Fail(report.status());

  const std::string preview_path = project.root() + "/preview.png";
  if (!args.Has("no-preview")) {
    const std::string mesh_path = project.MeshDir() + "/mesh.ply";
    std::error_code error;
    const std::string model = std::filesystem::exists(mesh_path, error) ? mesh_path : project.DensePointsPath();
    if (Status s = WritePreview(project, model, preview_path); !s.ok()) {
      std::fprintf(stderr, "warning: no preview: %s\n", s.ToString().c_str());
    }
  }
  if (args.Has("json")) {
    auto text = ReadFileToString(report->report_path);
    if (text.ok()) std::fputs(text->c_str(), stdout);
    return 0;
  }
  for (const StageSummary& stage : report->stages) {
    std::printf("%-9s %s %7.1fs  peak %6.0f MiB%s%s\n", stage.name.c_str(), stage.reused ? "reused " : "done   ",
                stage.seconds, static_cast<double>(stage.peak_rss_bytes) / (1 << 20), stage.note.empty() ? "" : "  ",
                stage.note.c_str());
  }
  std::printf("scale: %s\n", report->metric ? "metres (tags.json)" : report->scale_note.c_str());
  std::printf("written to %s (report.json%s)\n", project.root().c_str(), args.Has("no-preview") ? "" : ", preview.png");
  return 0;
}

}  // namespace reconar::tools
