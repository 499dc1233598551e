#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/base/atomic_file.h"
#include "core/sfm/localization_map.h"
#include "tests/core/sfm/sample_localization_map.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::RepairMapHeader;
using testing::SampleLocalizationMap;

std::string ReadBytes(const fs::path& path) {
  Result<std::string> bytes = ReadFileToString(path.string());
  EXPECT_TRUE(bytes.ok()) << bytes.status().ToString();
  return bytes.ok() ? *bytes : std::string();
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void ExpectMapsEqual(const LocalizationMap& a, const LocalizationMap& b) {
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.metric, b.metric);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(a.points[i], b.points[i]) << "point " << i;
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_EQ(a.point_descriptors, b.point_descriptors);
  ASSERT_EQ(a.keyframes.size(), b.keyframes.size());
  for (size_t k = 0; k < a.keyframes.size(); ++k) {
    SCOPED_TRACE("keyframe " + std::to_string(k));
    const MapKeyframe& x = a.keyframes[k];
    const MapKeyframe& y = b.keyframes[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    EXPECT_EQ(x.camera.focal, y.camera.focal);
    EXPECT_EQ(x.camera.cx, y.camera.cx);
    EXPECT_EQ(x.camera.cy, y.camera.cy);
    EXPECT_EQ(x.camera.k1, y.camera.k1);
    EXPECT_EQ(x.camera.k2, y.camera.k2);
    EXPECT_EQ(x.camera.aspect, y.camera.aspect);
    EXPECT_EQ(x.cam_from_world.rotation, y.cam_from_world.rotation);
    EXPECT_EQ(x.cam_from_world.translation, y.cam_from_world.translation);
    ASSERT_EQ(x.keypoints.size(), y.keypoints.size());
    for (size_t j = 0; j < x.keypoints.size(); ++j) EXPECT_EQ(x.keypoints[j], y.keypoints[j]) << "keypoint " << j;
    EXPECT_EQ(x.point_ids, y.point_ids);
    EXPECT_EQ(x.descriptors, y.descriptors);
  }
  // The vocabulary and the index: their records are compared byte for byte by
  // WritesTheSameBytesEveryTime (a map read back writes the file it came from), their answers by
  // ExpectSameRetrieval.
  EXPECT_EQ(a.vocabulary.num_words(), b.vocabulary.num_words());
  EXPECT_EQ(a.vocabulary.num_nodes(), b.vocabulary.num_nodes());
  EXPECT_EQ(a.vocabulary.branching(), b.vocabulary.branching());
  EXPECT_EQ(a.keyframe_index.num_images(), b.keyframe_index.num_images());
  EXPECT_EQ(a.keyframe_index.num_words(), b.keyframe_index.num_words());
}

// The vocabulary and the index read back answer like the ones written: every descriptor falls in
// the same word and every keyframe's query ranks the keyframes the same way.
void ExpectSameRetrieval(const LocalizationMap& a, const LocalizationMap& b) {
  const int num_images = a.keyframe_index.num_images();
  RetrievalScratch scratch_a;
  RetrievalScratch scratch_b;
  for (const MapKeyframe& keyframe : a.keyframes) {
    std::vector<int32_t> words_a;
    std::vector<int32_t> words_b;
    for (size_t j = 0; j < keyframe.descriptors.size(); j += 128) {
      words_a.push_back(a.vocabulary.Quantize(&keyframe.descriptors[j]));
      words_b.push_back(b.vocabulary.Quantize(&keyframe.descriptors[j]));
    }
    ASSERT_EQ(words_a, words_b) << keyframe.name;
    scratch_a.Reserve(static_cast<int>(words_a.size()), num_images);
    scratch_b.Reserve(static_cast<int>(words_b.size()), num_images);
    std::vector<RetrievalCandidate> ranked_a;
    std::vector<RetrievalCandidate> ranked_b;
    ranked_a.reserve(num_images);
    ranked_b.reserve(num_images);
    a.keyframe_index.Query(words_a.data(), static_cast<int>(words_a.size()), num_images, &scratch_a, &ranked_a);
    b.keyframe_index.Query(words_b.data(), static_cast<int>(words_b.size()), num_images, &scratch_b, &ranked_b);
    ASSERT_EQ(ranked_a.size(), ranked_b.size()) << keyframe.name;
    ASSERT_FALSE(ranked_a.empty()) << keyframe.name;
    for (size_t i = 0; i < ranked_a.size(); ++i) {
      EXPECT_EQ(ranked_a[i].image, ranked_b[i].image);
      EXPECT_EQ(ranked_a[i].score, ranked_b[i].score);
    }
  }
}

// The message of a refused parse, or "" (with a test failure) when it was accepted.
std::string Refusal(const std::string& bytes, const std::string& what = "map.rmap") {
  Result<LocalizationMap> map = ParseLocalizationMap(bytes, what);
  EXPECT_FALSE(map.ok());
  if (map.ok()) return "";
  EXPECT_EQ(map.status().code(), StatusCode::kInvalidArgument) << map.status().ToString();
  return map.status().message();
}

class LocalizationMapIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = SampleLocalizationMap(40, 2, 7);
    dir_ = testing::MakeTestDirectory(std::string("reconar_map_io_") +
                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
    path_ = (dir_ / "map.rmap").string();
    ASSERT_TRUE(WriteLocalizationMap(path_, map_).ok());
    bytes_ = ReadBytes(path_);
  }

  // The map file of `map` (written and read back as bytes).
  std::string BytesOf(const LocalizationMap& map) {
    const std::string path = (dir_ / "other.rmap").string();
    const Status status = WriteLocalizationMap(path, map);
    EXPECT_TRUE(status.ok()) << status.ToString();
    return ReadBytes(path);
  }

  LocalizationMap map_;
  fs::path dir_;
  std::string path_;
  std::string bytes_;
};

TEST_F(LocalizationMapIoTest, RoundTripIsExact) {
  ASSERT_EQ(map_.keyframes.size(), 2u);
  ASSERT_GT(map_.vocabulary.num_words(), 1);
  ASSERT_GT(map_.keyframes[0].num_observations(), 10);
  Result<LocalizationMap> read = ReadLocalizationMap(path_);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ExpectMapsEqual(map_, *read);
  ExpectSameRetrieval(map_, *read);
  EXPECT_EQ(bytes_.compare(0, 8, std::string("RCNRMAP\0", 8)), 0);
}

TEST_F(LocalizationMapIoTest, WritesTheSameBytesEveryTime) {
  EXPECT_EQ(BytesOf(map_), bytes_);
  ASSERT_TRUE(WriteLocalizationMap(path_, map_).ok());
  EXPECT_EQ(ReadBytes(path_), bytes_);
  // And a map read back writes the bytes it was read from.
  Result<LocalizationMap> read = ParseLocalizationMap(bytes_, path_);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(BytesOf(*read), bytes_);
}

TEST_F(LocalizationMapIoTest, EmptyMapRoundTrips) {
  LocalizationMap empty;
  empty.frame = "arbitrary";
  Result<LocalizationMap> read = ParseLocalizationMap(BytesOf(empty), "empty.rmap");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ExpectMapsEqual(empty, *read);
}

TEST_F(LocalizationMapIoTest, RefusesForeignFiles) {
  const std::string jpeg_path = std::string(RECONAR_SOURCE_DIR) + "/data/swatbotics_room/IMG_1369.JPG";
  Result<LocalizationMap> jpeg = ReadLocalizationMap(jpeg_path);
  ASSERT_FALSE(jpeg.ok());
  EXPECT_EQ(jpeg.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(jpeg.status().message(), jpeg_path + ": not a reconar map file (bad magic)");

  const fs::path text = dir_ / "notes.txt";
  WriteBytes(text, "RCNR is not a map\n");
  Result<LocalizationMap> from_text = ReadLocalizationMap(text.string());
  ASSERT_FALSE(from_text.ok());
  EXPECT_EQ(from_text.status().message(), text.string() + ": not a reconar map file (bad magic)");
}

TEST_F(LocalizationMapIoTest, RefusesAnEmptyFile) {
  const fs::path empty = dir_ / "empty.rmap";
  WriteBytes(empty, "");
  Result<LocalizationMap> read = ReadLocalizationMap(empty.string());
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(read.status().message(), empty.string() + ": not a reconar map file (empty file)");
}

TEST_F(LocalizationMapIoTest, RefusesAnotherVersion) {
  std::string bytes = bytes_;
  const uint32_t version = 2;
  std::memcpy(&bytes[8], &version, sizeof(version));
  EXPECT_EQ(Refusal(bytes), "map.rmap: map version 2, this build reads 1");
}

TEST_F(LocalizationMapIoTest, RefusesAFlippedPayloadByte) {
  for (const size_t at : {size_t{24}, bytes_.size() / 2, bytes_.size() - 1}) {
    std::string bytes = bytes_;
    bytes[at] = static_cast<char>(bytes[at] ^ 0x10);
    EXPECT_EQ(Refusal(bytes), "map.rmap: checksum mismatch (damaged file)") << "byte " << at;
  }
  std::string bytes = bytes_;
  bytes[20] = static_cast<char>(bytes[20] ^ 1);  // the stored checksum itself
  EXPECT_EQ(Refusal(bytes), "map.rmap: checksum mismatch (damaged file)");
}

TEST_F(LocalizationMapIoTest, RefusesEveryTruncation) {
  for (size_t size = 0; size < bytes_.size(); ++size) {
    const std::string message = Refusal(bytes_.substr(0, size));
    if (size == 0) {
      EXPECT_EQ(message, "map.rmap: not a reconar map file (empty file)");
    } else if (size < 24) {
      EXPECT_EQ(message, "map.rmap: truncated (" + std::to_string(size) + " bytes, the header alone has 24)");
    } else {
      EXPECT_EQ(message, "map.rmap: truncated (" + std::to_string(size - 24) + " of " +
                             std::to_string(bytes_.size() - 24) + " payload bytes)");
    }
    if (HasFailure()) break;
  }
}

TEST_F(LocalizationMapIoTest, RefusesTrailingBytes) {
  EXPECT_EQ(Refusal(bytes_ + "x"), "map.rmap: 1 trailing bytes after the payload");
  // Extra bytes inside a payload whose size and checksum agree.
  std::string bytes = bytes_ + "xyz";
  RepairMapHeader(&bytes);
  EXPECT_EQ(Refusal(bytes), "map.rmap: 3 unparsed bytes at the end of the payload");
}

TEST_F(LocalizationMapIoTest, RefusesEveryTruncatedPayloadBehindAValidChecksum) {
  // Every cut of the payload, with the header repaired: the structural parser must refuse it.
  for (size_t size = 24; size < bytes_.size(); ++size) {
    std::string bytes = bytes_.substr(0, size);
    RepairMapHeader(&bytes);
    const std::string message = Refusal(bytes);
    EXPECT_EQ(message.rfind("map.rmap: ", 0), 0u) << message;
    if (HasFailure()) break;
  }
}

TEST_F(LocalizationMapIoTest, MissingFileNamesThePath) {
  const std::string missing = (dir_ / "no_such.rmap").string();
  Result<LocalizationMap> read = ReadLocalizationMap(missing);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find(missing), std::string::npos) << read.status().ToString();
}

TEST_F(LocalizationMapIoTest, WriteErrorsNameThePath) {
  const std::string unwritable = (dir_ / "no_such_dir" / "map.rmap").string();
  const Status status = WriteLocalizationMap(unwritable, map_);
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find(unwritable), std::string::npos) << status.ToString();

  LocalizationMap bad = map_;
  bad.keyframes[1].descriptors.pop_back();
  const std::string path = (dir_ / "bad.rmap").string();
  const Status refused = WriteLocalizationMap(path, bad);
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(refused.message().find(path), std::string::npos) << refused.ToString();
  EXPECT_FALSE(fs::exists(path));
}

// Content the format can hold but a map must not: written (the writer checks only that the arrays
// agree in size), then refused by the reader with the reason.
TEST_F(LocalizationMapIoTest, RefusesInvalidContentBehindAValidChecksum) {
  const auto refusal_of = [&](const LocalizationMap& map) { return Refusal(BytesOf(map)); };
  const std::string kf1 = "map.rmap: keyframe 1 (IMG_1001.JPG): ";
  {
    LocalizationMap map = map_;
    map.keyframes[1].point_ids[3] = map.num_points();
    EXPECT_EQ(refusal_of(map), kf1 + "observation 3 refers to point 40 of 40");
    map.keyframes[1].point_ids[3] = -1;
    EXPECT_EQ(refusal_of(map), kf1 + "observation 3 refers to point -1 of 40");
  }
  {
    LocalizationMap map = map_;
    map.points[5].y() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(refusal_of(map), "map.rmap: point 5 is not finite");
  }
  {
    LocalizationMap map = map_;
    map.keyframes[1].keypoints[0].x() = std::numeric_limits<float>::infinity();
    EXPECT_EQ(refusal_of(map), kf1 + "keypoint 0 is not finite");
  }
  {
    LocalizationMap map = map_;
    map.keyframes[1].camera.focal = 0.0;
    EXPECT_EQ(refusal_of(map), kf1 + "camera not finite or focal/aspect not positive");
    map.keyframes[1].camera.focal = 500.0;
    map.keyframes[1].camera.aspect = -1.0;
    EXPECT_EQ(refusal_of(map), kf1 + "camera not finite or focal/aspect not positive");
    map.keyframes[1].camera.aspect = 1.0;
    map.keyframes[1].camera.k1 = std::numeric_limits<double>::infinity();
    EXPECT_EQ(refusal_of(map), kf1 + "camera not finite or focal/aspect not positive");
  }
  {
    LocalizationMap map = map_;
    map.keyframes[1].height = 0;
    EXPECT_EQ(refusal_of(map), kf1 + "image size 640 x 0");
  }
  {
    LocalizationMap map = map_;
    map.keyframes[1].cam_from_world.rotation(0, 1) += 1e-5;
    EXPECT_EQ(refusal_of(map).rfind(kf1 + "the rotation is not a rotation", 0), 0u);
    map.keyframes[1].cam_from_world.rotation = -map_.keyframes[1].cam_from_world.rotation;  // a reflection
    EXPECT_EQ(refusal_of(map).rfind(kf1 + "the rotation is not a rotation", 0), 0u);
    map.keyframes[1].cam_from_world.rotation = map_.keyframes[1].cam_from_world.rotation;
    map.keyframes[1].cam_from_world.translation.z() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(refusal_of(map), kf1 + "pose not finite");
  }
  {
    LocalizationMap map = map_;
    map.keyframes[0].name.clear();
    EXPECT_EQ(refusal_of(map), "map.rmap: keyframe 0: empty name or control character in name");
    map.keyframes[0].name = std::string("IMG\0.JPG", 8);
    EXPECT_EQ(refusal_of(map), "map.rmap: keyframe 0: empty name or control character in name");
    map.keyframes[0].name = "IMG\n.JPG";
    EXPECT_EQ(refusal_of(map), "map.rmap: keyframe 0: empty name or control character in name");
    map.keyframes[0].name = "Caf\xc3\xa9 1.jpg";  // UTF-8 is a name like any other
    EXPECT_TRUE(ParseLocalizationMap(BytesOf(map), "map.rmap").ok());
  }
  {
    LocalizationMap map = map_;
    Result<InvertedFile> one_image = InvertedFile::Build(map.vocabulary.num_words(), {{0, 1}});
    ASSERT_TRUE(one_image.ok());
    map.keyframe_index = std::move(one_image).value();
    EXPECT_EQ(refusal_of(map), "map.rmap: the keyframe index holds 1 images for 2 keyframes");
  }
  {
    LocalizationMap map = map_;
    Result<InvertedFile> more_words = InvertedFile::Build(map.vocabulary.num_words() + 1, {{0}, {1}});
    ASSERT_TRUE(more_words.ok());
    map.keyframe_index = std::move(more_words).value();
    EXPECT_EQ(refusal_of(map), "map.rmap: the keyframe index has " + std::to_string(map.vocabulary.num_words() + 1) +
                                   " words, the vocabulary " + std::to_string(map.vocabulary.num_words()));
  }
}

// A count far beyond the bytes left is refused before anything is allocated for it.
TEST_F(LocalizationMapIoTest, RefusesHugeCountsBehindAValidChecksum) {
  // The point count follows the frame name (uint32 length + characters) and the metric flag.
  const size_t at = 24 + 4 + map_.frame.size() + 1;
  uint32_t count = 0;
  std::memcpy(&count, &bytes_[at], sizeof(count));
  ASSERT_EQ(count, 40u);
  for (const uint32_t huge : {0x10000u, 0x7fffffffu, 0xffffffffu}) {
    std::string bytes = bytes_;
    std::memcpy(&bytes[at], &huge, sizeof(huge));
    RepairMapHeader(&bytes);
    EXPECT_EQ(Refusal(bytes).rfind("map.rmap: malformed payload: the point count at byte", 0), 0u);
  }
  // One more point than there are shifts everything after it: still refused.
  std::string bytes = bytes_;
  const uint32_t one_more = 41;
  std::memcpy(&bytes[at], &one_more, sizeof(one_more));
  RepairMapHeader(&bytes);
  Refusal(bytes);
}

}  // namespace
}  // namespace reconar
