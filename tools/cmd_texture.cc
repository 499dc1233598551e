#include <cstdio>
#include <set>
#include <string>

#include "core/base/memory_usage.h"
#include "core/pipeline/texture_stage.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar texture PROJECT_DIR [options]\n"
    "\n"
    "Textures the project's mesh (mesh/mesh.ply, made by `reconar reconstruct`) from its registered\n"
    "photos: the mesh is simplified to a face budget, each face takes the photo that sees it\n"
    "sharpest and closest while its neighbours keep the same photo where they can (photos whose\n"
    "colour disagrees with the others', e.g. a passer-by, lose the face), the colours are levelled\n"
    "across the seams between photos, and the pieces are packed into a texture (more pages when one\n"
    "does not hold them at the photos' resolution). Writes:\n"
    "  mesh/textured.glb          glTF 2.0 with the texture embedded (what `reconar view` draws)\n"
    "  mesh/textured.obj, .mtl, .png   the same for modellers (textured_1.png, ...: further pages)\n"
    "  mesh/texture_report.json   photos used, patches, seam colour steps, atlas, seconds\n"
    "  --max-faces N           face budget of the textured mesh (default 160000; 0: as it is)\n"
    "  --atlas-size PX         largest side of a texture page, a power of two (default 4096)\n"
    "  --max-pages N           texture pages at most (default 4, fewer when half the memory budget\n"
    "                          does not hold them); the photos' detail is scaled down to fit when\n"
    "                          they do not hold it\n"
    "  --exclude NAMES         photos (comma-separated file names) not to texture from, e.g. one\n"
    "                          with a passer-by, or photos kept aside to check the texture against\n"
    "  --memory-budget SIZE    memory the run may use: MiB, or 512K, 1500M, 1G (default 2560M)\n"
    "  --threads N             worker threads (default: one per core)\n"
    "  --json                  print the report as JSON instead of a summary\n";

void PrintSummary(const TextureStageReport& r) {
  const TextureReport& t = r.texture;
  std::printf("texture: %zu faces%s, %zu of %zu photos used, %zu patches; %zu faces no photo sees\n", t.faces,
              r.simplified ? (" (simplified from " + std::to_string(r.faces_in) + ")").c_str() : "", t.photos_used,
              t.photos, t.patches, t.untextured_faces);
  std::printf("texture: %zu of %zu candidate views dropped as inconsistent; seam colour step %.1f -> %.1f (of 255)\n",
              t.inconsistent_candidates, t.candidates, t.seam_step_before, t.seam_step_after);
  std::printf("texture: atlas %zu page(s), the first %d x %d, %.2f texels per photo pixel, %.0f%% covered\n",
              t.atlas_pages, t.atlas_width, t.atlas_height, t.texels_per_pixel, 100.0 * t.atlas_fill);
  std::printf("texture: %.1fs (views %.1fs, labels %.1fs, seams %.1fs, atlas %.1fs), peak %.0f MiB\n", r.seconds,
              t.seconds_candidates, t.seconds_labelling, t.seconds_seams, t.seconds_atlas,
              Mib(r.peak_rss_bytes));
  std::printf("texture: written %s and %s\n", r.paths.empty() ? "" : r.paths[0].c_str(), r.report_path.c_str());
}

Status ReadTextureArgs(const Args& args, TextureStageOptions* options) {
  RECONAR_ASSIGN_OR_RETURN(const int max_faces, args.GetInt("max-faces", static_cast<int>(options->max_faces), 0, 1 << 30));
  options->max_faces = static_cast<size_t>(max_faces);
  RECONAR_ASSIGN_OR_RETURN(options->texture.atlas_size, args.GetInt("atlas-size", options->texture.atlas_size, 64, 16384));
  RECONAR_ASSIGN_OR_RETURN(options->texture.max_pages, args.GetInt("max-pages", options->texture.max_pages, 1, 64));
  if (args.Has("exclude")) options->exclude = SplitCommas(args.Get("exclude"));
  RECONAR_ASSIGN_OR_RETURN(options->num_threads, args.GetThreads());
  RECONAR_ASSIGN_OR_RETURN(options->memory_budget_bytes, args.GetMemoryBudget(options->memory_budget_bytes));
  options->show_progress = true;
  return Status::Ok();
}

}  // namespace

int RunTexture(int argc, char** argv, int first) {
  Args args({"max-faces", "atlas-size", "max-pages", "exclude", "memory-budget", "threads"}, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 1, 1)) return *exit_code;
  TextureStageOptions options;
  if (const Status status = ReadTextureArgs(args, &options); !status.ok()) return Fail(status);
  auto report = RunTextureStage(Project(args.positionals()[0]), options);
  if (!report.ok()) return Fail(report.status());
  if (args.Has("json")) {
    std::fputs(TextureReportJson(*report).c_str(), stdout);
  } else {
    PrintSummary(*report);
  }
  return 0;
}

}  // namespace reconar::tools
