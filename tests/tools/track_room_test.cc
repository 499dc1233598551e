// `reconar track --layout` over the swatbotics room's 72 photos as one sequence (issue 15, "Tags
// found while tracking"): the tags of the room's layout are predicted from each frame's pose and
// searched where they should appear, so the tracker finds at least as many of the tag instances
// groundtruth.txt lists (236, human-made upstream) as full-frame detection at decimation 1 does
// (228, SOURCE.txt of the dataset), with the default decimation and with --decimate 1, and no id
// that the list does not give. The layout is the fixture data/swatbotics_room.layout (README.txt
// there); the photos in name order.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "core/base/json_reader.h"
#include "tests/support/ground_truth.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

const std::string kData = testing::SharedDataPath("apriltag_swatbotics_mapping");
const std::string kLayout = std::string(RECONAR_SOURCE_DIR) + "/tests/tools/data/swatbotics_room.layout";
// The camera of the project the layout comes from (data/README.txt).
const std::string kCamera =
    "--intrinsics 764.2655238584713,764.2655238584713,397.35271562486867,308.09664930117196,"
    "0.12598508305480108,-0.26366177412089753 --tag-size 0.127";

struct Count {
  int found = 0;  // listed instances found
  int listed = 0;
  int false_ids = 0;
  int by_prediction = 0;
  int frames = 0;
};

Count TrackRoom(const std::string& extra) {
  const testing::CommandRun run = testing::RunReconar(
      "track " + kData + " --layout " + kLayout + " " + kCamera + " --json " + extra, testing::StderrMode::kSeparate);
  EXPECT_EQ(run.exit_code, 0) << run.error;
  const auto read = testing::ReadListedTagIds(kData + "/groundtruth.txt");
  EXPECT_TRUE(read.ok()) << read.status().ToString();
  const std::map<std::string, std::set<int>> listed = read.ok() ? *read : std::map<std::string, std::set<int>>();
  Count count;
  for (const auto& [image, ids] : listed) count.listed += static_cast<int>(ids.size());
  std::istringstream lines(run.output);
  std::string line;
  while (std::getline(lines, line)) {
    auto frame = ParseJson(line, "track --json line");
    if (!frame.ok()) {
      ADD_FAILURE() << frame.status().ToString();
      continue;
    }
    ++count.frames;
    const std::string image = frame->Find("frame")->string();
    const auto it = listed.find(image);
    const JsonValue& tags = *frame->Find("tags");
    for (size_t i = 0; i < tags.size(); ++i) {
      const int id = static_cast<int>(tags[i].Find("id")->number());
      const bool is_listed = it != listed.end() && it->second.count(id) > 0;
      count.found += is_listed ? 1 : 0;
      count.false_ids += is_listed ? 0 : 1;
      if (!is_listed) ADD_FAILURE() << "id " << id << " in " << image << " is not listed";
    }
    count.by_prediction += static_cast<int>(frame->Find("predicted")->Find("found")->number());
  }
  std::printf("track --layout %s: %d of %d listed tag instances in %d frames (%d found by prediction), %d false ids\n",
              extra.c_str(), count.found, count.listed, count.frames, count.by_prediction, count.false_ids);
  return count;
}

TEST(TrackRoom, LayoutTagsPredictedFindAsManyAsFullFrameDetection) {
  for (const std::string extra : {"", "--decimate 1"}) {
    const Count count = TrackRoom(extra);
    EXPECT_EQ(count.frames, 72) << extra;
    EXPECT_EQ(count.listed, 236);
    EXPECT_GE(count.found, 228) << extra;
    EXPECT_EQ(count.false_ids, 0) << extra;
  }
}

}  // namespace
}  // namespace reconar
