// render_capture: rendered photo sets with exact cameras, written to disk for the mapper's tests and
// benches (the renderers are test support: tests/support/corridor_walk.h, object_capture.h).
//
//   render_capture corridor-walk|corridor-turn|bunny-hemisphere OUT_DIR [options]
//
// Writes OUT_DIR/images/*.png and the true cameras as a COLMAP text model without points in
// OUT_DIR/truth/ (both replaced), then prints what it rendered and how long it took. Score a
// reconstruction with: evaluate_sfm PROJECT/sparse --colmap-truth OUT_DIR/truth.
// Exit codes: 0 ok, 1 failed run, 2 bad usage or input.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "core/mesh/mesh_io.h"
#include "tests/support/corridor_walk.h"
#include "tests/support/ground_truth.h"
#include "tests/support/object_capture.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

constexpr char kUsage[] =
    "usage: render_capture corridor-walk|corridor-turn|bunny-hemisphere OUT_DIR [options]\n"
    "  writes OUT_DIR/images/*.png and OUT_DIR/truth/ (the true cameras, COLMAP text)\n"
    "  every set:  --size WxH (640x480)  --focal PX (520)  --seed N (1)  --supersampling N (2)\n"
    "              --threads N (0: one per core)\n"
    "  corridor-walk, corridor-turn (tests/support/corridor_walk.h):\n"
    "              --frames N (29)  --step M (0.4)  --texture-contrast GREY (30)  --length M (24)\n"
    "  corridor-turn: --turn-deg D (90, positive right)  --turn-frame K (frames / 2)  --turn-steps N (4)\n"
    "  bunny-hemisphere (tests/support/object_capture.h):\n"
    "              --mesh PLY (the Stanford bunny, ../shared/data)  --views N (320)  --revolutions R (4)\n"
    "              --elevation MIN,MAX (15,60 degrees)  --distance M (0.35)  --texture-contrast GREY (4)\n"
    "              --background-level GREY (28)  --background-contrast GREY (1)  --noise SIGMA (1)\n";

int Usage(const std::string& message) {
  std::fprintf(stderr, "render_capture: %s\n%s", message.c_str(), kUsage);
  return 2;
}

// "--name value" pairs, each name one of `known`.
class Flags {
 public:
  Status Parse(int argc, char** argv, int first, const std::set<std::string>& known) {
    for (int i = first; i < argc; i += 2) {
      const std::string name = argv[i];
      if (name.rfind("--", 0) != 0 || known.count(name.substr(2)) == 0)
        return InvalidArgument("unknown option " + name);
      if (i + 1 >= argc) return InvalidArgument(name + " needs a value");
      values_[name.substr(2)] = argv[i + 1];
    }
    return Status::Ok();
  }
  bool Has(const std::string& name) const { return values_.count(name) > 0; }
  const std::string& Text(const std::string& name) const { return values_.at(name); }
  Status Int(const std::string& name, int* value) const {
    if (!Has(name)) return Status::Ok();
    char* end = nullptr;
    const long parsed = std::strtol(Text(name).c_str(), &end, 10);
    if (*end != '\0' || end == Text(name).c_str()) return InvalidArgument("--" + name + " must be an integer");
    *value = static_cast<int>(parsed);
    return Status::Ok();
  }
  Status Double(const std::string& name, double* value) const {
    if (!Has(name)) return Status::Ok();
    char* end = nullptr;
    const double parsed = std::strtod(Text(name).c_str(), &end);
    if (*end != '\0' || end == Text(name).c_str()) return InvalidArgument("--" + name + " must be a number");
    *value = parsed;
    return Status::Ok();
  }
  Status Pair(const std::string& name, const char* format, double* first, double* second) const {
    if (!Has(name)) return Status::Ok();
    if (std::sscanf(Text(name).c_str(), format, first, second) != 2) {
      return InvalidArgument("--" + name + " must look like " + std::string(format));
    }
    return Status::Ok();
  }

 private:
  std::map<std::string, std::string> values_;
};

Status ParseCommon(const Flags& flags, int* width, int* height, double* focal, uint32_t* seed, int* supersampling,
                   int* threads) {
  double w = *width, h = *height;
  RECONAR_RETURN_IF_ERROR(flags.Pair("size", "%lfx%lf", &w, &h));
  *width = static_cast<int>(w);
  *height = static_cast<int>(h);
  RECONAR_RETURN_IF_ERROR(flags.Double("focal", focal));
  int seed_value = static_cast<int>(*seed);
  RECONAR_RETURN_IF_ERROR(flags.Int("seed", &seed_value));
  *seed = static_cast<uint32_t>(seed_value);
  RECONAR_RETURN_IF_ERROR(flags.Int("supersampling", supersampling));
  return flags.Int("threads", threads);
}

Status ParseWalk(const Flags& flags, testing::CorridorWalkOptions* walk) {
  walk->threads = 0;
  RECONAR_RETURN_IF_ERROR(ParseCommon(flags, &walk->width, &walk->height, &walk->focal_px, &walk->seed,
                                      &walk->supersampling, &walk->threads));
  RECONAR_RETURN_IF_ERROR(flags.Int("frames", &walk->frames));
  RECONAR_RETURN_IF_ERROR(flags.Double("step", &walk->step_m));
  RECONAR_RETURN_IF_ERROR(flags.Double("length", &walk->length_m));
  return flags.Double("texture-contrast", &walk->texture_contrast);
}

// Renders the chosen set into `images_dir`; its true cameras.
Result<testing::GroundTruthByName> Render(const std::string& set, const Flags& flags, const std::string& images_dir) {
  if (set == "corridor-walk") {
    testing::CorridorWalkOptions walk;
    RECONAR_RETURN_IF_ERROR(ParseWalk(flags, &walk));
    std::printf("corridor-walk: %d frames %.2f m apart, %dx%d, focal %.0f px\n", walk.frames, walk.step_m, walk.width,
                walk.height, walk.focal_px);
    return testing::RenderCorridorWalk(images_dir, walk);
  }
  if (set == "corridor-turn") {
    testing::CorridorTurnOptions turn;
    RECONAR_RETURN_IF_ERROR(ParseWalk(flags, &turn.walk));
    RECONAR_RETURN_IF_ERROR(flags.Double("turn-deg", &turn.turn_deg));
    RECONAR_RETURN_IF_ERROR(flags.Int("turn-frame", &turn.turn_frame));
    RECONAR_RETURN_IF_ERROR(flags.Int("turn-steps", &turn.turn_steps));
    std::printf(
        "corridor-turn: %d frames %.2f m apart, turning %.0f deg over %d steps at frame %d, %dx%d, focal %.0f px\n",
        turn.walk.frames, turn.walk.step_m, turn.turn_deg, turn.turn_steps,
        turn.turn_frame < 0 ? turn.walk.frames / 2 : turn.turn_frame, turn.walk.width, turn.walk.height,
        turn.walk.focal_px);
    return testing::RenderCorridorTurn(images_dir, turn);
  }
  testing::ObjectCaptureOptions capture;
  capture.threads = 0;
  RECONAR_RETURN_IF_ERROR(ParseCommon(flags, &capture.width, &capture.height, &capture.focal_px, &capture.seed,
                                      &capture.supersampling, &capture.threads));
  RECONAR_RETURN_IF_ERROR(flags.Int("views", &capture.views));
  RECONAR_RETURN_IF_ERROR(flags.Double("revolutions", &capture.revolutions));
  RECONAR_RETURN_IF_ERROR(flags.Pair("elevation", "%lf,%lf", &capture.min_elevation_deg, &capture.max_elevation_deg));
  RECONAR_RETURN_IF_ERROR(flags.Double("distance", &capture.distance_m));
  RECONAR_RETURN_IF_ERROR(flags.Double("texture-contrast", &capture.texture_contrast));
  RECONAR_RETURN_IF_ERROR(flags.Double("background-level", &capture.background_level));
  RECONAR_RETURN_IF_ERROR(flags.Double("background-contrast", &capture.background_contrast));
  RECONAR_RETURN_IF_ERROR(flags.Double("noise", &capture.noise_sigma));
  const std::string mesh_path =
      flags.Has("mesh") ? flags.Text("mesh") : testing::SharedDataPath("stanford_bunny/reconstruction/bun_zipper.ply");
  RECONAR_ASSIGN_OR_RETURN(Mesh mesh, ReadPly(mesh_path));
  RECONAR_ASSIGN_OR_RETURN(const testing::ObjectCaptureScene scene,
                           testing::ObjectCaptureScene::Create(std::move(mesh), capture));
  std::printf(
      "bunny-hemisphere: %s, %d views on %.1f revolutions from %.0f to %.0f deg elevation at %.2f m, %dx%d, "
      "focal %.0f px\n",
      mesh_path.c_str(), capture.views, capture.revolutions, capture.min_elevation_deg, capture.max_elevation_deg,
      capture.distance_m, capture.width, capture.height, capture.focal_px);
  return testing::WriteObjectCapture(scene, images_dir);
}

int Run(int argc, char** argv) {
  if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (argc < 3) return Usage("needs a set and OUT_DIR");
  const std::string set = argv[1];
  const fs::path out = argv[2];
  std::set<std::string> known = {"size", "focal", "seed", "supersampling", "threads"};
  if (set == "corridor-walk" || set == "corridor-turn") {
    known.insert({"frames", "step", "texture-contrast", "length"});
    if (set == "corridor-turn") known.insert({"turn-deg", "turn-frame", "turn-steps"});
  } else if (set == "bunny-hemisphere") {
    known.insert({"mesh", "views", "revolutions", "elevation", "distance", "texture-contrast", "background-level",
                  "background-contrast", "noise"});
  } else {
    return Usage("unknown set " + set);
  }
  Flags flags;
  if (const Status parsed = flags.Parse(argc, argv, 3, known); !parsed.ok()) return Usage(parsed.message());

  std::error_code error;
  for (const char* sub : {"images", "truth"}) fs::remove_all(out / sub, error);
  fs::create_directories(out / "images", error);
  if (error) {
    std::fprintf(stderr, "render_capture: %s: cannot create the directory: %s\n", (out / "images").c_str(),
                 error.message().c_str());
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  const Result<testing::GroundTruthByName> truth = Render(set, flags, (out / "images").string());
  if (!truth.ok()) {
    std::fprintf(stderr, "render_capture: %s\n", truth.status().ToString().c_str());
    return truth.status().code() == StatusCode::kInvalidArgument || truth.status().code() == StatusCode::kNotFound ||
                   truth.status().code() == StatusCode::kCorruptData
               ? 2
               : 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (const Status written = testing::WriteGroundTruthModel(*truth, (out / "truth").string()); !written.ok()) {
    std::fprintf(stderr, "render_capture: %s\n", written.ToString().c_str());
    return 1;
  }
  std::printf("%zu images in %s (%.1f s, %.3f s each), truth in %s\n", truth->size(), (out / "images").c_str(), seconds,
              seconds / truth->size(), (out / "truth").c_str());
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
