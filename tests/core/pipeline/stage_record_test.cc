// PROJECT/stages.txt (core/pipeline/stage_record.h): what a finished stage records, what recording
// a stage drops, and that a different setting means the stage is not finished.
#include "core/pipeline/stage_record.h"

#include <gtest/gtest.h>

#include "core/base/atomic_file.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

TEST(StageRecord, SettingsArePrintedByNameToTwelveDigits) {
  EXPECT_EQ(StageRecord::Settings({{"ratio", 0.8}, {"min_inliers", 30}, {"third", 1.0 / 3.0}}),
            "ratio=0.8 min_inliers=30 third=0.333333333333");
  EXPECT_EQ(StageRecord::Settings({}), "");
}

TEST(StageRecord, AStageIsFinishedOnlyWithTheSameSettingsAndSurvivesARestart) {
  const Project project(testing::MakeTestDirectory("reconar_stage_record_settings"));
  StageRecord record(project);
  EXPECT_FALSE(record.Finished("features", "a=1")) << "no stages.txt: nothing finished";
  ASSERT_TRUE(record.Record("features", "a=1").ok());
  EXPECT_TRUE(record.Finished("features", "a=1"));
  EXPECT_FALSE(record.Finished("features", "a=2")) << "other settings: the stage must run again";
  EXPECT_FALSE(record.Finished("matching", "a=1"));

  const StageRecord reread(project);  // a later run
  EXPECT_TRUE(reread.Finished("features", "a=1"));
  EXPECT_FALSE(reread.Finished("features", "a=2"));
  auto text = ReadFileToString(project.root() + "/stages.txt");
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text, "features a=1\n");
}

TEST(StageRecord, RecordingAStageDropsTheStagesAfterIt) {
  const Project project(testing::MakeTestDirectory("reconar_stage_record_order"));
  StageRecord record(project);
  for (const char* stage : {"features", "tags", "matching", "mapping", "dense", "mesh"}) {
    ASSERT_TRUE(record.Record(stage, "x=1").ok());
  }
  ASSERT_TRUE(record.Record("matching", "x=2").ok());  // matched again: the tags stand, the model goes
  EXPECT_TRUE(record.Finished("tags", "x=1"));
  EXPECT_FALSE(record.Finished("mapping", "x=1"));
  ASSERT_TRUE(record.Record("mapping", "x=2").ok());  // redone: dense and mesh read the old model
  EXPECT_TRUE(record.Finished("features", "x=1"));
  EXPECT_TRUE(record.Finished("matching", "x=2"));
  EXPECT_TRUE(record.Finished("tags", "x=1"));
  EXPECT_TRUE(record.Finished("mapping", "x=2"));
  EXPECT_FALSE(record.Finished("dense", "x=1"));
  EXPECT_FALSE(record.Finished("mesh", "x=1"));

  ASSERT_TRUE(record.Record("features", "x=3").ok());
  const StageRecord reread(project);
  EXPECT_TRUE(reread.Finished("features", "x=3"));
  for (const char* stage : {"tags", "matching", "mapping", "dense", "mesh"}) {
    EXPECT_FALSE(reread.Finished(stage, "x=1")) << stage;
    EXPECT_FALSE(reread.Finished(stage, "x=2")) << stage;
  }
}

// Tags and matching both read the photos' features, not each other: detecting the tags again
// (or for the first time, after a capture recorded its features and matches) keeps the matches.
TEST(StageRecord, TagsAndMatchingDoNotDropEachOther) {
  const Project project(testing::MakeTestDirectory("reconar_stage_record_tags"));
  StageRecord record(project);
  for (const char* stage : {"features", "matching", "mapping", "map"}) ASSERT_TRUE(record.Record(stage, "x=1").ok());
  ASSERT_TRUE(record.Record("tags", "x=1").ok());
  EXPECT_TRUE(record.Finished("matching", "x=1"));
  EXPECT_FALSE(record.Finished("mapping", "x=1")) << "mapping reads the tags";
  EXPECT_FALSE(record.Finished("map", "x=1")) << "the map reads the model mapping made";
  ASSERT_TRUE(record.Record("mapping", "x=1").ok());
  ASSERT_TRUE(record.Record("matching", "x=2").ok());
  EXPECT_TRUE(StageRecord(project).Finished("tags", "x=1"));
  EXPECT_FALSE(StageRecord(project).Finished("mapping", "x=1"));
}

// The map is a side stage: it reads the model and nothing reads it.
TEST(StageRecord, TheMapIsDroppedWithTheModelButNotWithTheDenseStages) {
  const Project project(testing::MakeTestDirectory("reconar_stage_record_side"));
  StageRecord record(project);
  for (const char* stage : {"features", "matching", "mapping", "map", "dense", "mesh"}) {
    ASSERT_TRUE(record.Record(stage, "x=1").ok());
  }
  ASSERT_TRUE(record.Record("dense", "x=2").ok());
  EXPECT_TRUE(record.Finished("map", "x=1")) << "the map does not read the dense points";
  EXPECT_FALSE(record.Finished("mesh", "x=1"));
  ASSERT_TRUE(record.Record("map", "x=2").ok());
  EXPECT_TRUE(record.Finished("dense", "x=2")) << "recording the map drops nothing";
  ASSERT_TRUE(record.Record("mapping", "x=2").ok());
  EXPECT_FALSE(record.Finished("map", "x=2")) << "a new model needs a new map";
  ASSERT_TRUE(record.Record("map", "x=3").ok());
  ASSERT_TRUE(record.Record("features", "x=2").ok());
  EXPECT_FALSE(StageRecord(project).Finished("map", "x=3"));
  EXPECT_TRUE(IsSideStage("map"));
  EXPECT_FALSE(IsSideStage("mapping"));
}

TEST(StageRecord, TwoRecordsOpenAtOnceKeepEachOthersLines) {
  // The stage runner's record, and the map stage's own while the runner's is open.
  const Project project(testing::MakeTestDirectory("reconar_stage_record_two"));
  StageRecord runner(project);
  ASSERT_TRUE(runner.Record("mapping", "x=1").ok());
  ASSERT_TRUE(StageRecord(project).Record("map", "x=1").ok());
  ASSERT_TRUE(runner.Record("dense", "x=1").ok());
  auto text = ReadFileToString(project.root() + "/stages.txt");
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text, "dense x=1\nmap x=1\nmapping x=1\n");
  EXPECT_TRUE(runner.Finished("map", "x=1"));
}

}  // namespace
}  // namespace reconar
