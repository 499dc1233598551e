// `reconar texture` and `reconar render` end to end on the temple (data/templeSparseRing, 16
// photos of a plaster temple on a dark floor): the textured model reconstruct leaves, the same
// files after a reconstruct killed in its texture stage is run again, a texture made again without
// photos, the errors for names that are no registered photo, a photo gone from
// disk (left out with a warning), a mesh no photo sees (an error, the untextured mesh kept), the
// model drawn from a photo's viewpoint against that photo, and `reconar export` keeping the texture.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/io/image_io.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_file.h"
#include "core/sfm/model_io.h"
#include "tests/support/json_number.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

// A number of the texture report (NaN when absent, failing every comparison).
TEST(TextureCli, TexturesRendersAndRefusesClearly) {
  const std::string data = std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing";
  const fs::path root = testing::MakeTestDirectory("reconar_texture_cli");
  const std::string project = (root / "temple").string();
  const CommandRun reconstruct =
      RunReconar("reconstruct " + data + " " + project + " --threads 2 --no-preview --formats ply");
  ASSERT_EQ(reconstruct.exit_code, 0) << reconstruct.output;
  for (const char* file : {"textured.glb", "textured.obj", "textured.mtl", "textured.png", "texture_report.json"}) {
    EXPECT_TRUE(fs::exists(fs::path(project) / "mesh" / file)) << file;
  }
  const Result<TexturedGlb> textured = ReadTexturedGlb(project + "/mesh/textured.glb");
  ASSERT_TRUE(textured.ok()) << textured.status().ToString();
  ASSERT_FALSE(textured->pages.empty());
  EXPECT_EQ(textured->mesh.texcoords.size(), textured->mesh.positions.size());
  const Result<JsonValue> report = ReadJsonFile(project + "/mesh/texture_report.json");
  ASSERT_TRUE(report.ok());
  EXPECT_GT(testing::JsonNumber(*report, "textured_faces"), 0.9 * testing::JsonNumber(*report, "faces"));
  EXPECT_LT(testing::JsonNumber(*report, "seam_step_after"), testing::JsonNumber(*report, "seam_step_before"));

  // A reconstruct killed in its texture stage (the stage's record gone, as a kill before it is
  // written leaves it) does the texture again when run again, reusing the rest, to the same files.
  const char* kTexturedFiles[] = {"textured.glb", "textured.obj", "textured.mtl", "textured.png"};
  std::map<std::string, std::string> reference;
  for (const char* file : kTexturedFiles) {
    Result<std::string> bytes = ReadFileToString(project + "/mesh/" + file);
    ASSERT_TRUE(bytes.ok()) << file;
    reference[file] = std::move(*bytes);
  }
  const std::string stages_path = project + "/stages.txt";
  Result<std::string> stages = ReadFileToString(stages_path);
  ASSERT_TRUE(stages.ok());
  const size_t texture_line = stages->find("texture ");
  ASSERT_NE(texture_line, std::string::npos) << *stages;
  const std::string without_texture = stages->substr(0, texture_line) + stages->substr(stages->find('\n', texture_line) + 1);
  ASSERT_TRUE(WriteFileAtomically(stages_path, without_texture).ok());
  const std::string again = "reconstruct " + data + " " + project + " --threads 2 --no-preview --formats ply";
  const auto texture_start = std::chrono::steady_clock::now();
  const CommandRun texture_only = RunReconar(again);
  ASSERT_EQ(texture_only.exit_code, 0) << texture_only.output;
  const double texture_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - texture_start).count();
  ASSERT_TRUE(WriteFileAtomically(stages_path, without_texture).ok());
  const pid_t pid = testing::SpawnCommand(std::string(RECONAR_BINARY) + " " + again);
  ASSERT_GT(pid, 0);
  std::this_thread::sleep_for(std::chrono::duration<double>(0.5 * texture_seconds));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status)) << "the run ended before it was killed (" << texture_seconds << " s uninterrupted)";
  const CommandRun resumed = RunReconar(again);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("reused"), std::string::npos) << resumed.output;
  for (const char* file : kTexturedFiles) {
    Result<std::string> bytes = ReadFileToString(project + "/mesh/" + file);
    ASSERT_TRUE(bytes.ok()) << file;
    EXPECT_TRUE(*bytes == reference[file]) << file << " differs after the killed texture stage was done again";
  }

  // Export keeps the texture into .obj (with its .mtl and .png) and .glb; .ply says it drops it.
  const std::string exported = (root / "exported").string();
  const CommandRun to_obj = RunReconar("export " + project + "/mesh/textured.glb " + exported + "/model.obj");
  ASSERT_EQ(to_obj.exit_code, 0) << to_obj.output;
  for (const char* file : {"model.obj", "model.mtl", "model.png"}) EXPECT_TRUE(fs::exists(fs::path(exported) / file));
  const CommandRun to_glb = RunReconar("export " + project + "/mesh/textured.glb " + exported + "/model.glb");
  ASSERT_EQ(to_glb.exit_code, 0) << to_glb.output;
  const Result<TexturedGlb> reexported = ReadTexturedGlb(exported + "/model.glb");
  ASSERT_TRUE(reexported.ok());
  ASSERT_EQ(reexported->pages.size(), textured->pages.size());
  for (size_t k = 0; k < textured->pages.size(); ++k) EXPECT_EQ(reexported->pages[k].image, textured->pages[k].image);
  const CommandRun to_ply = RunReconar("export " + project + "/mesh/textured.glb " + exported + "/model.ply");
  ASSERT_EQ(to_ply.exit_code, 0) << to_ply.output;
  EXPECT_NE(to_ply.output.find("texture was left out"), std::string::npos) << to_ply.output;

  // Small pages: the charts go on several, each its own file, primitive and material, and export
  // keeps them all.
  const CommandRun paged = RunReconar("texture " + project + " --atlas-size 256 --max-pages 16 --json");
  ASSERT_EQ(paged.exit_code, 0) << paged.output;
  const Result<JsonValue> paged_report = ParseJson(paged.output.substr(paged.output.find('{')), "report");
  ASSERT_TRUE(paged_report.ok()) << paged.output;
  const double pages = testing::JsonNumber(*paged_report, "atlas_pages");
  EXPECT_GE(pages, 2.0);
  EXPECT_TRUE(fs::exists(project + "/mesh/textured_1.png"));
  const Result<TexturedGlb> paged_glb = ReadTexturedGlb(project + "/mesh/textured.glb");
  ASSERT_TRUE(paged_glb.ok()) << paged_glb.status().ToString();
  EXPECT_EQ(static_cast<double>(paged_glb->pages.size()), pages);
  const CommandRun paged_obj = RunReconar("export " + project + "/mesh/textured.glb " + exported + "/paged.obj");
  ASSERT_EQ(paged_obj.exit_code, 0) << paged_obj.output;
  EXPECT_TRUE(fs::exists(exported + "/paged_1.png"));
  const Result<std::string> paged_mtl = ReadFileToString(exported + "/paged.mtl");
  ASSERT_TRUE(paged_mtl.ok());
  EXPECT_NE(paged_mtl->find("map_Kd paged_1.png"), std::string::npos) << *paged_mtl;

  // Again without two photos: they are named in the report and texture nothing.
  const CommandRun excluded = RunReconar("texture " + project + " --exclude templeSR0004.png,templeSR0009.png --json");
  ASSERT_EQ(excluded.exit_code, 0) << excluded.output;
  const Result<JsonValue> excluded_report = ParseJson(excluded.output.substr(excluded.output.find('{')), "report");
  ASSERT_TRUE(excluded_report.ok()) << excluded.output;
  EXPECT_EQ(excluded_report->Find("excluded")->size(), 2u);
  EXPECT_EQ(testing::JsonNumber(*excluded_report, "photos"), testing::JsonNumber(*report, "photos") - 2);
  EXPECT_FALSE(fs::exists(project + "/mesh/textured_1.png")) << "a page of the earlier texture left behind";

  // The textured model drawn from a held-out photo's pose covers the temple there. (How close it
  // is to the photo is measured on fountain, Herz-Jesu and the room in docs/texture.md; on this
  // temple, 16 small photos of white plaster, the geometry limits the texture and the vertex
  // colours alike, both about 16 dB.)
  const std::string out = (root / "render").string();
  const CommandRun render = RunReconar("render " + project + " templeSR0004.png templeSR0005.png --out " + out);
  ASSERT_EQ(render.exit_code, 0) << render.output;
  // The held-out photo at the texture's exposure (its PNG has no EXIF to predict its own); a photo
  // texturing used at its own gain.
  EXPECT_NE(render.output.find("templeSR0004.png.png (model covers"), std::string::npos) << render.output;
  EXPECT_NE(render.output.find("exposure: texture"), std::string::npos) << render.output;
  EXPECT_NE(render.output.find("exposure: photo's gain"), std::string::npos) << render.output;
  const auto mask = ReadImage(out + "/templeSR0004.png.mask.png");
  ASSERT_TRUE(mask.ok() && fs::exists(out + "/templeSR0004.png.png") && fs::exists(out + "/templeSR0004.png.photo.png"));
  size_t covered = 0;
  for (int y = 0; y < mask->rgb.height(); ++y) {
    for (int x = 0; x < mask->rgb.width(); ++x) covered += mask->rgb.row(y)[3 * x] > 127;
  }
  EXPECT_GT(covered, static_cast<size_t>(0.05 * mask->rgb.width() * mask->rgb.height()));

  // The AR view draws the textured model brought to each frame's exposure; a flag turns it off.
  const std::string overlays = (root / "overlays").string();
  const CommandRun view = RunReconar("view --project " + project + " --frames " + data + " --out " + overlays +
                                     " --max-frames 3");
  ASSERT_EQ(view.exit_code, 0) << view.output;
  EXPECT_NE(view.output.find("brought to the video's exposure"), std::string::npos) << view.output;
  EXPECT_TRUE(fs::exists(overlays + "/templeSR0001.png")) << view.output;
  const CommandRun plain_view = RunReconar("view --project " + project + " --frames " + data + " --out " + overlays +
                                           " --max-frames 1 --no-exposure-match");
  ASSERT_EQ(plain_view.exit_code, 0) << plain_view.output;
  EXPECT_EQ(plain_view.output.find("brought to the video's exposure"), std::string::npos) << plain_view.output;

  // Names that are no registered photo: usage errors naming them.
  const CommandRun unknown_exclude = RunReconar("texture " + project + " --exclude nothere.png");
  EXPECT_EQ(unknown_exclude.exit_code, 2);
  EXPECT_NE(unknown_exclude.output.find("nothere.png"), std::string::npos) << unknown_exclude.output;
  const CommandRun unknown_render = RunReconar("render " + project + " nothere.png --out " + out);
  EXPECT_EQ(unknown_render.exit_code, 2);
  EXPECT_NE(unknown_render.output.find("nothere.png"), std::string::npos) << unknown_render.output;

  // A photo gone from disk: left out with a warning naming it; the others texture the model.
  const fs::path copy = root / "photos";
  fs::copy(data, copy);
  const std::string moved = (root / "temple_moved").string();
  fs::copy(project, moved, fs::copy_options::recursive);
  const std::string list_path = moved + "/features/images.txt";
  Result<std::string> list = ReadFileToString(list_path);
  ASSERT_TRUE(list.ok());
  for (size_t at = list->find(data); at != std::string::npos; at = list->find(data, at)) {
    list->replace(at, data.size(), copy.string());
  }
  ASSERT_TRUE(WriteFileAtomically(list_path, *list).ok());
  fs::remove(copy / "templeSR0007.png");
  const CommandRun missing = RunReconar("texture " + moved);
  ASSERT_EQ(missing.exit_code, 0) << missing.output;
  EXPECT_NE(missing.output.find("templeSR0007.png left out"), std::string::npos) << missing.output;

  // A mesh no photo sees (moved far along the direction farthest from every camera's axis, out of
  // every frame): an error saying so; the mesh is kept.
  const Result<Reconstruction> model = ReadColmapTextModel(moved + "/sparse");
  ASSERT_TRUE(model.ok());
  Eigen::Vector3d away = Eigen::Vector3d::UnitX();
  double nearest_axis = 1.0;
  for (int i = 0; i < 27; ++i) {
    const Eigen::Vector3d direction = Eigen::Vector3d(i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1);
    if (direction.isZero()) continue;
    double cosine = -1.0;
    for (const SfmImage& image : model->images) {
      if (image.registered) cosine = std::max(cosine, image.cam_from_world.rotation.row(2).dot(direction.normalized()));
    }
    if (cosine < nearest_axis) {
      nearest_axis = cosine;
      away = direction.normalized();
    }
  }
  ASSERT_LT(nearest_axis, std::cos(50.0 * M_PI / 180.0));  // the temple's photos see about 20 degrees off their axes
  const Eigen::Vector3d up = away;
  Result<Mesh> mesh = ReadMeshFile(moved + "/mesh/mesh.ply");
  ASSERT_TRUE(mesh.ok());
  const Eigen::Vector3f lift = (1e4 * up.normalized()).cast<float>();
  for (Eigen::Vector3f& p : mesh->positions) p += lift;
  ASSERT_TRUE(WriteMeshFile(moved + "/mesh/mesh.ply", *mesh).ok());
  const CommandRun unseen = RunReconar("texture " + moved);
  EXPECT_EQ(unseen.exit_code, 1) << unseen.output;
  EXPECT_NE(unseen.output.find("no photo sees"), std::string::npos) << unseen.output;
  EXPECT_TRUE(fs::exists(moved + "/mesh/mesh.ply"));
  fs::remove_all(root);
}

}  // namespace
}  // namespace reconar
