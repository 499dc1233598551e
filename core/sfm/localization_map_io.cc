// The map file (core/sfm/localization_map.h): writer and validating reader.
//
// Payload layout (little-endian, ByteWriter/ByteReader of core/base/binary_io.h):
//   string frame; uint8 metric (0 or 1);
//   uint32 num_points; double xyz[num_points][3]; uint8 rgb[num_points][3];
//     uint8 descriptor[num_points][128];
//   uint32 num_keyframes; per keyframe:
//     string name; int32 width, height;
//     double focal, cx, cy, k1, k2, aspect;
//     double R[9] (cam_from_world, row-major), t[3];
//     uint32 num_observations; float keypoint[n][2]; int32 point_id[n]; uint8 descriptor[n][128];
//   the vocabulary tree (VocabularyTree::Serialize); the inverted file (InvertedFile::Serialize).
// A string is a uint32 length and its characters.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/base/atomic_file.h"
#include "core/base/binary_io.h"
#include "core/sfm/localization_map.h"

namespace reconar {
namespace {

constexpr char kMagic[8] = {'R', 'C', 'N', 'R', 'M', 'A', 'P', '\0'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderBytes = sizeof(kMagic) + sizeof(uint32_t) + sizeof(uint64_t) + sizeof(uint32_t);
constexpr size_t kDescriptorBytes = 128;
constexpr uint32_t kMaxStringBytes = 4096;
constexpr uint32_t kMaxCount = static_cast<uint32_t>(std::numeric_limits<int32_t>::max());
// Bytes of one element behind each count: the guard that keeps a damaged count from allocating more
// than the payload can hold.
constexpr size_t kPointBytes = 3 * sizeof(double) + 3 + kDescriptorBytes;
constexpr size_t kKeyframeMinBytes =
    sizeof(uint32_t) + 2 * sizeof(int32_t) + 6 * sizeof(double) + 12 * sizeof(double) + sizeof(uint32_t);
constexpr size_t kObservationBytes = 2 * sizeof(float) + sizeof(int32_t) + kDescriptorBytes;
constexpr double kRotationTolerance = 1e-6;

// The first inconsistency between the arrays of the map that share a count in the file, or "".
std::string SizeMismatch(const LocalizationMap& map) {
  const size_t n = map.points.size();
  if (n > kMaxCount || map.keyframes.size() > kMaxCount) return "too many points or keyframes";
  if (map.colors.size() != n || map.point_descriptors.size() != kDescriptorBytes * n) {
    return std::to_string(n) + " points, " + std::to_string(map.colors.size()) + " colors and " +
           std::to_string(map.point_descriptors.size()) + " descriptor bytes";
  }
  if (map.frame.size() > kMaxStringBytes) return "frame name longer than " + std::to_string(kMaxStringBytes);
  for (size_t i = 0; i < map.keyframes.size(); ++i) {
    const MapKeyframe& keyframe = map.keyframes[i];
    const size_t m = keyframe.point_ids.size();
    if (keyframe.name.size() > kMaxStringBytes) return "keyframe " + std::to_string(i) + ": name too long";
    if (m > kMaxCount || keyframe.keypoints.size() != m || keyframe.descriptors.size() != kDescriptorBytes * m) {
      return "keyframe " + std::to_string(i) + " has " + std::to_string(keyframe.keypoints.size()) + " keypoints, " +
             std::to_string(m) + " point ids and " + std::to_string(keyframe.descriptors.size()) + " descriptor bytes";
    }
  }
  return "";
}

void PutDoubles(ByteWriter* writer, const double* values, int count) {
  for (int i = 0; i < count; ++i) writer->Put(values[i]);
}

std::string SerializePayload(const LocalizationMap& map) {
  ByteWriter writer;
  size_t estimate = 64 + kPointBytes * map.points.size();
  for (const MapKeyframe& keyframe : map.keyframes) {
    estimate += kKeyframeMinBytes + keyframe.name.size() + kObservationBytes * keyframe.point_ids.size();
  }
  writer.bytes().reserve(estimate);

  writer.PutString(map.frame);
  writer.Put(static_cast<uint8_t>(map.metric ? 1 : 0));
  writer.Put(static_cast<uint32_t>(map.points.size()));
  for (const Eigen::Vector3d& point : map.points) PutDoubles(&writer, point.data(), 3);
  for (const std::array<uint8_t, 3>& color : map.colors) writer.PutBytes(color.data(), 3);
  writer.PutBytes(map.point_descriptors.data(), map.point_descriptors.size());

  writer.Put(static_cast<uint32_t>(map.keyframes.size()));
  for (const MapKeyframe& keyframe : map.keyframes) {
    writer.PutString(keyframe.name);
    writer.Put(static_cast<int32_t>(keyframe.width));
    writer.Put(static_cast<int32_t>(keyframe.height));
    const RadialCamera& camera = keyframe.camera;
    const double intrinsics[6] = {camera.focal, camera.cx, camera.cy, camera.k1, camera.k2, camera.aspect};
    PutDoubles(&writer, intrinsics, 6);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) writer.Put(keyframe.cam_from_world.rotation(r, c));
    }
    PutDoubles(&writer, keyframe.cam_from_world.translation.data(), 3);
    writer.Put(static_cast<uint32_t>(keyframe.point_ids.size()));
    for (const Eigen::Vector2f& keypoint : keyframe.keypoints) {
      writer.Put(keypoint.x());
      writer.Put(keypoint.y());
    }
    for (const int32_t id : keyframe.point_ids) writer.Put(id);
    writer.PutBytes(keyframe.descriptors.data(), keyframe.descriptors.size());
  }
  map.vocabulary.Serialize(&writer);
  map.keyframe_index.Serialize(&writer);
  return std::move(writer.bytes());
}

std::string Header(const std::string& payload) {
  ByteWriter writer;
  writer.PutBytes(kMagic, sizeof(kMagic));
  writer.Put(kVersion);
  writer.Put(static_cast<uint64_t>(payload.size()));
  writer.Put(Crc32(payload.data(), payload.size()));
  return std::move(writer.bytes());
}

bool AllFinite(const double* values, int count) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

// Parses and validates the payload; every error is InvalidArgument "<what>: <reason>".
class PayloadParser {
 public:
  PayloadParser(std::string_view payload, const std::string& what) : reader_(payload), what_(what) {}

  Result<LocalizationMap> Parse() {
    LocalizationMap map;
    RECONAR_RETURN_IF_ERROR(ParseHeaderFields(&map));
    RECONAR_RETURN_IF_ERROR(ParsePoints(&map));
    uint32_t num_keyframes = 0;
    if (!reader_.GetCount(kKeyframeMinBytes, kMaxCount, &num_keyframes)) return Truncated("the keyframe count");
    map.keyframes.resize(num_keyframes);
    for (uint32_t i = 0; i < num_keyframes; ++i) {
      RECONAR_RETURN_IF_ERROR(ParseKeyframe(static_cast<int>(i), map.num_points(), &map.keyframes[i]));
    }
    Result<VocabularyTree> vocabulary = VocabularyTree::Deserialize(&reader_, what_);
    if (!vocabulary.ok()) return AsInvalidArgument(vocabulary.status());
    map.vocabulary = std::move(vocabulary).value();
    Result<InvertedFile> index = InvertedFile::Deserialize(&reader_, what_);
    if (!index.ok()) return AsInvalidArgument(index.status());
    map.keyframe_index = std::move(index).value();
    if (map.keyframe_index.num_images() != static_cast<int>(map.keyframes.size())) {
      return Error("the keyframe index holds " + std::to_string(map.keyframe_index.num_images()) + " images for " +
                   std::to_string(map.keyframes.size()) + " keyframes");
    }
    if (map.keyframe_index.num_words() != map.vocabulary.num_words()) {
      return Error("the keyframe index has " + std::to_string(map.keyframe_index.num_words()) +
                   " words, the vocabulary " + std::to_string(map.vocabulary.num_words()));
    }
    if (!reader_.ok()) return Truncated("the retrieval index");
    if (reader_.remaining() != 0) {
      return Error(std::to_string(reader_.remaining()) + " unparsed bytes at the end of the payload");
    }
    return map;
  }

 private:
  Status Error(const std::string& reason) const { return InvalidArgument(what_ + ": " + reason); }
  Status Truncated(const std::string& field) const {
    return Error("malformed payload: " + field + " at byte " + std::to_string(reader_.position()) +
                 " does not fit in the payload");
  }
  // The vocabulary's errors already name `what`; whatever their code, a bad record is bad input.
  static Status AsInvalidArgument(const Status& status) {
    return status.code() == StatusCode::kInvalidArgument ? status : InvalidArgument(status.message());
  }

  Status ParseHeaderFields(LocalizationMap* map) {
    uint8_t metric = 0;
    if (!reader_.GetString(kMaxStringBytes, &map->frame)) return Truncated("the frame name");
    if (!reader_.Get(&metric)) return Truncated("the metric flag");
    if (metric > 1) return Error("metric flag " + std::to_string(metric) + " (0 or 1)");
    map->metric = metric == 1;
    return Status::Ok();
  }

  Status ParsePoints(LocalizationMap* map) {
    uint32_t n = 0;
    if (!reader_.GetCount(kPointBytes, kMaxCount, &n)) return Truncated("the point count");
    map->points.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
      double xyz[3];
      reader_.GetBytes(xyz, sizeof(xyz));
      if (!AllFinite(xyz, 3)) return Error("point " + std::to_string(i) + " is not finite");
      map->points[i] = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    }
    map->colors.resize(n);
    for (uint32_t i = 0; i < n; ++i) reader_.GetBytes(map->colors[i].data(), 3);
    map->point_descriptors.resize(kDescriptorBytes * n);
    reader_.GetBytes(map->point_descriptors.data(), map->point_descriptors.size());
    if (!reader_.ok()) return Truncated("the points");
    return Status::Ok();
  }

  Status ParseKeyframe(int index, int num_points, MapKeyframe* keyframe) {
    const std::string label = "keyframe " + std::to_string(index);
    if (!reader_.GetString(kMaxStringBytes, &keyframe->name)) return Truncated(label + "'s name");
    // A photo's file name: no control characters (they would also garble the messages below).
    const auto control = [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; };
    if (keyframe->name.empty() || std::any_of(keyframe->name.begin(), keyframe->name.end(), control)) {
      return Error(label + ": empty name or control character in name");
    }
    const std::string named = label + " (" + keyframe->name + ")";
    int32_t width = 0;
    int32_t height = 0;
    double intrinsics[6];
    double rotation[9];
    double translation[3];
    reader_.Get(&width);
    reader_.Get(&height);
    reader_.GetBytes(intrinsics, sizeof(intrinsics));
    reader_.GetBytes(rotation, sizeof(rotation));
    reader_.GetBytes(translation, sizeof(translation));
    if (!reader_.ok()) return Truncated(named + "'s camera");
    if (width <= 0 || height <= 0) {
      return Error(named + ": image size " + std::to_string(width) + " x " + std::to_string(height));
    }
    if (!AllFinite(intrinsics, 6) || !(intrinsics[0] > 0.0) || !(intrinsics[5] > 0.0)) {
      return Error(named + ": camera not finite or focal/aspect not positive");
    }
    keyframe->width = width;
    keyframe->height = height;
    keyframe->camera.focal = intrinsics[0];
    keyframe->camera.cx = intrinsics[1];
    keyframe->camera.cy = intrinsics[2];
    keyframe->camera.k1 = intrinsics[3];
    keyframe->camera.k2 = intrinsics[4];
    keyframe->camera.aspect = intrinsics[5];
    if (!AllFinite(rotation, 9) || !AllFinite(translation, 3)) return Error(named + ": pose not finite");
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = rotation[i];
    const double off = (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(off <= kRotationTolerance) || !(r.determinant() > 0.0)) {
      return Error(named + ": the rotation is not a rotation (|R R^T - I| = " + std::to_string(off) + ")");
    }
    keyframe->cam_from_world.rotation = r;
    keyframe->cam_from_world.translation = Eigen::Vector3d(translation[0], translation[1], translation[2]);

    uint32_t m = 0;
    if (!reader_.GetCount(kObservationBytes, kMaxCount, &m)) return Truncated(named + "'s observation count");
    keyframe->keypoints.resize(m);
    for (uint32_t j = 0; j < m; ++j) {
      float xy[2];
      reader_.GetBytes(xy, sizeof(xy));
      if (!std::isfinite(xy[0]) || !std::isfinite(xy[1])) {
        return Error(named + ": keypoint " + std::to_string(j) + " is not finite");
      }
      keyframe->keypoints[j] = Eigen::Vector2f(xy[0], xy[1]);
    }
    keyframe->point_ids.resize(m);
    for (uint32_t j = 0; j < m; ++j) {
      int32_t id = -1;
      reader_.Get(&id);
      if (id < 0 || id >= num_points) {
        return Error(named + ": observation " + std::to_string(j) + " refers to point " + std::to_string(id) + " of " +
                     std::to_string(num_points));
      }
      keyframe->point_ids[j] = id;
    }
    keyframe->descriptors.resize(kDescriptorBytes * m);
    reader_.GetBytes(keyframe->descriptors.data(), keyframe->descriptors.size());
    if (!reader_.ok()) return Truncated(named + "'s observations");
    return Status::Ok();
  }

  ByteReader reader_;
  const std::string& what_;
};

}  // namespace

Status WriteLocalizationMap(const std::string& path, const LocalizationMap& map) {
  const std::string mismatch = SizeMismatch(map);
  if (!mismatch.empty()) return InvalidArgument(path + ": cannot write the map: " + mismatch);
  const std::string payload = SerializePayload(map);
  const std::string header = Header(payload);
  return WriteFileAtomically(path, [&](std::FILE* file) {
    if (std::fwrite(header.data(), 1, header.size(), file) != header.size() ||
        std::fwrite(payload.data(), 1, payload.size(), file) != payload.size()) {
      return FileError(StatusCode::kIoError, path, "write failed");
    }
    return Status::Ok();
  });
}

Result<LocalizationMap> ReadLocalizationMap(const std::string& path) {
  Result<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return ParseLocalizationMap(*bytes, path);
}

Result<LocalizationMap> ParseLocalizationMap(std::string_view bytes, const std::string& what) {
  const auto error = [&](const std::string& reason) { return InvalidArgument(what + ": " + reason); };
  if (bytes.empty()) return error("not a reconar map file (empty file)");
  if (std::memcmp(bytes.data(), kMagic, std::min(bytes.size(), sizeof(kMagic))) != 0) {
    return error("not a reconar map file (bad magic)");
  }
  if (bytes.size() < kHeaderBytes) {
    return error("truncated (" + std::to_string(bytes.size()) + " bytes, the header alone has " +
                 std::to_string(kHeaderBytes) + ")");
  }
  ByteReader header(bytes.substr(sizeof(kMagic), kHeaderBytes - sizeof(kMagic)));
  uint32_t version = 0;
  uint64_t payload_bytes = 0;
  uint32_t payload_crc = 0;
  header.Get(&version);
  header.Get(&payload_bytes);
  header.Get(&payload_crc);
  if (version != kVersion) {
    return error("map version " + std::to_string(version) + ", this build reads " + std::to_string(kVersion));
  }
  const uint64_t available = bytes.size() - kHeaderBytes;
  if (available < payload_bytes) {
    return error("truncated (" + std::to_string(available) + " of " + std::to_string(payload_bytes) +
                 " payload bytes)");
  }
  if (available > payload_bytes) {
    return error(std::to_string(available - payload_bytes) + " trailing bytes after the payload");
  }
  const std::string_view payload = bytes.substr(kHeaderBytes);
  if (Crc32(payload.data(), payload.size()) != payload_crc) return error("checksum mismatch (damaged file)");
  return PayloadParser(payload, what).Parse();
}

}  // namespace reconar
