// RunReconstruct (core/pipeline/reconstruct.h) on four photos of the bundled templeSparseRing, sparse
// stages only: a second run reuses every stage and leaves the files as they were; a changed
// matching setting redoes matching and mapping but keeps the features; the preview is asked of
// what the run made; bad options are refused before anything runs. Also the photo paths a project
// keeps and the removal of a textured model.
#include "core/pipeline/reconstruct.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/pipeline/map_stage.h"
#include "core/pipeline/stage_record.h"
#include "core/sfm/localization_map.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

std::vector<std::string> TemplePhotos() {
  std::vector<std::string> paths;
  for (const char* name : {"templeSR0001.png", "templeSR0002.png", "templeSR0003.png", "templeSR0004.png"}) {
    paths.push_back(std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing/" + name);
  }
  return paths;
}

ReconstructOptions SparseOptions() {
  ReconstructOptions options;
  options.run_dense = options.run_mesh = false;
  options.features.sift.first_octave = 0;  // small and fast; the reuse logic is what is tested
  options.features.sift.max_features = 3000;
  options.num_threads = 2;
  options.show_progress = false;
  return options;
}

std::map<std::string, bool> Reused(const ReconstructReport& report) {
  std::map<std::string, bool> reused;
  for (const StageSummary& stage : report.stages) reused[stage.name] = stage.reused;
  return reused;
}

std::string Contents(const std::string& path) {
  auto text = ReadFileToString(path);
  EXPECT_TRUE(text.ok()) << text.status().ToString();
  return text.ok() ? *text : std::string();
}

// A folder's photos are taken in their numbers' order: the sequential pair rule relies on it.
TEST(CollectImagePaths, AFolderIsListedInItsNumbersOrder) {
  const std::string folder = testing::MakeTestDirectory("reconar_collect_numbered");
  for (const char* name : {"img10.png", "img9.png", "img100.PNG", "notes.txt", "img1.jpg"}) {
    ASSERT_TRUE(WriteFileAtomically(folder + "/" + name, "x").ok());
  }
  auto paths = CollectImagePaths({folder});
  ASSERT_TRUE(paths.ok()) << paths.status().ToString();
  EXPECT_EQ(*paths, (std::vector<std::string>{folder + "/img1.jpg", folder + "/img9.png", folder + "/img10.png",
                                              folder + "/img100.PNG"}));
}

// A project lists its photos by absolute path, so that its later stages (texture, render) find
// them from any directory.
TEST(CollectImagePaths, ARelativeArgumentComesBackAbsolute) {
  const std::string folder = testing::MakeTestDirectory("reconar_collect_relative");
  ASSERT_TRUE(CreateDirectories(folder + "/photos").ok());
  ASSERT_TRUE(WriteFileAtomically(folder + "/photos/a.jpg", "x").ok());
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(folder);
  auto paths = CollectImagePaths({"photos/../photos"});
  std::filesystem::current_path(before);
  ASSERT_TRUE(paths.ok()) << paths.status().ToString();
  EXPECT_EQ(*paths, (std::vector<std::string>{folder + "/photos/a.jpg"}));
}

// What the texture stage made of a mesh goes with it; the mesh stays.
TEST(RemoveTexturedModel, TakesTheTextureStagesFilesAndLeavesTheMesh) {
  const Project project(testing::MakeTestDirectory("reconar_remove_textured") + "/project");
  ASSERT_TRUE(CreateDirectories(project.MeshDir()).ok());
  for (const char* name : {"mesh.ply", "textured.glb", "textured.obj", "textured.mtl", "textured.png",
                           "texture_report.json"}) {
    ASSERT_TRUE(WriteFileAtomically(project.MeshDir() + "/" + name, "x").ok());
  }
  ASSERT_TRUE(RemoveTexturedModel(project).ok());
  EXPECT_TRUE(std::filesystem::exists(project.MeshDir() + "/mesh.ply"));
  for (const char* name : {"textured.glb", "textured.obj", "textured.mtl", "textured.png", "texture_report.json"}) {
    EXPECT_FALSE(std::filesystem::exists(project.MeshDir() + "/" + name)) << name;
  }
  EXPECT_TRUE(RemoveTexturedModel(project).ok());  // nothing left to remove is no error
}

TEST(RunReconstruct, ProductDefaultsDifferFromTheStagesOwn) {
  const ReconstructOptions options;
  EXPECT_EQ(options.matching.match.max_ratio, 0.8);
  EXPECT_EQ(options.matching.two_view.min_inliers, 30);
  EXPECT_EQ(options.mesh.poisson.depth, 10);
  EXPECT_EQ(options.mesh.poisson.trim, 7.0);
  EXPECT_EQ(options.mesh.max_faces, kHandheldMaxFaces);
  EXPECT_EQ(options.memory_budget_bytes, kDefaultMemoryBudgetBytes);
  EXPECT_TRUE(options.Check().ok());
}

TEST(RunReconstruct, ASecondRunReusesEveryStageAndAChangedSettingRedoesTheStagesFromIt) {
  const Project project(testing::MakeTestDirectory("reconar_run_reconstruct") + "/project");
  ReconstructOptions options = SparseOptions();
  std::vector<std::string> previewed;
  options.render_preview = [&](const std::string& model, const Eigen::Vector3d& up, const std::string& png) {
    previewed.push_back(model);
    EXPECT_NEAR(up.norm(), 1.0, 1e-9);
    return WriteFileAtomically(png, "not a picture");
  };
  auto first = RunReconstruct(TemplePhotos(), project, options);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  const std::map<std::string, bool> all_run = {{"features", false}, {"matching", false}, {"mapping", false}, {"map", false}};
  EXPECT_EQ(Reused(*first), all_run);
  EXPECT_GE(first->table1.registered, 2) << "of 4 photos";
  EXPECT_EQ(first->table1.images, 4);
  ASSERT_EQ(previewed.size(), 1u);
  EXPECT_EQ(previewed[0], project.SparseDir() + "/points.ply") << "the sparse points: what this run made";
  EXPECT_EQ(first->preview_path, project.root() + "/preview.png");
  const std::string model = Contents(project.SparseDir() + "/points3D.txt");
  const std::string matches = Contents(project.MatchesPath());
  ASSERT_FALSE(model.empty());

  auto second = RunReconstruct(TemplePhotos(), project, options);
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  const std::map<std::string, bool> all_reused = {{"features", true}, {"matching", true}, {"mapping", true}, {"map", true}};
  EXPECT_EQ(Reused(*second), all_reused);
  EXPECT_EQ(second->table1.registered, first->table1.registered) << "Table 1 of the reused model";
  EXPECT_EQ(Contents(project.SparseDir() + "/points3D.txt"), model);
  EXPECT_TRUE(ReadLocalizationMap(project.MapPath()).ok()) << "the sparse stages end with the localisation map";

  // The map stage alone (`reconar map`) records itself: the next run reuses its map.
  ASSERT_TRUE(StageRecord(project).Record("map", "stale=1").ok());
  ASSERT_TRUE(RunMapStage(project, options.map).ok());
  auto after_map = RunReconstruct(TemplePhotos(), project, options);
  ASSERT_TRUE(after_map.ok()) << after_map.status().ToString();
  EXPECT_EQ(Reused(*after_map), all_reused);

  options.matching.two_view.min_inliers = 31;
  auto third = RunReconstruct(TemplePhotos(), project, options);
  ASSERT_TRUE(third.ok()) << third.status().ToString();
  const std::map<std::string, bool> from_matching = {{"features", true}, {"matching", false}, {"mapping", false}, {"map", false}};
  EXPECT_EQ(Reused(*third), from_matching);
  const std::string third_model = Contents(project.SparseDir() + "/points3D.txt");

  options.force = true;
  auto forced = RunReconstruct(TemplePhotos(), project, options);
  ASSERT_TRUE(forced.ok()) << forced.status().ToString();
  EXPECT_EQ(Reused(*forced), all_run);
  EXPECT_EQ(Contents(project.SparseDir() + "/points3D.txt"), third_model) << "same settings, same model";
}

TEST(RunReconstruct, BadOptionsAreRefusedBeforeAnyStage) {
  const Project project(testing::MakeTestDirectory("reconar_run_reconstruct_bad") + "/project");
  ReconstructOptions options = SparseOptions();
  options.tag_size_m = 0.1;  // no detector given
  auto no_detector = RunReconstruct(TemplePhotos(), project, options);
  EXPECT_EQ(no_detector.status().code(), StatusCode::kInvalidArgument);
  options = SparseOptions();
  options.memory_budget_bytes = 1 << 20;
  EXPECT_EQ(RunReconstruct(TemplePhotos(), project, options).status().code(), StatusCode::kInvalidArgument);
  options = SparseOptions();
  auto one = RunReconstruct({TemplePhotos()[0]}, project, options);
  EXPECT_EQ(one.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(one.status().ToString().find("at least 2 photos"), std::string::npos) << one.status().ToString();
  EXPECT_NE(::access((project.root() + "/stages.txt").c_str(), F_OK), 0) << "nothing ran";
}

}  // namespace
}  // namespace reconar
