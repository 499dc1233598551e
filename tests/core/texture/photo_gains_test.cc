// The photos' exposure gains (core/texture/photo_gains.h) against gains that made the colours.
#include "core/texture/photo_gains.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace reconar {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct RingCapture {
  FaceCandidateTable table;
  std::vector<Eigen::Vector3d> true_log_gain;  // per photo: what brings its colours to the faces' own
};

// `num_photos` photos around a ring of faces, each seeing the 40 faces around its position, their
// exposure drifting once around the ring by +-0.8 in log (a camera on automatic turning from a
// bright wall to a dark one), with a white balance of its own. A fraction `outliers` of the
// candidates show something else (a passer-by), exposed as the rest of their photo. Colours carry
// 2 % noise.
RingCapture MakeRing(int num_photos, double outliers, unsigned seed) {
  const int num_faces = 10 * num_photos;
  std::mt19937 random(seed);
  // Colours within 16..250 at every exposure: none is left out as too dark or clipped.
  std::uniform_real_distribution<double> radiance(40.0, 100.0), balance(-0.1, 0.1), unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<Eigen::Vector3d> face_colour(static_cast<size_t>(num_faces));
  for (Eigen::Vector3d& colour : face_colour) colour = Eigen::Vector3d(radiance(random), radiance(random), radiance(random));
  RingCapture capture;
  std::vector<std::vector<FaceCandidate>> per_photo(static_cast<size_t>(num_photos));
  for (int p = 0; p < num_photos; ++p) {
    const double drift = 0.8 * std::sin(2.0 * kPi * p / num_photos);
    const Eigen::Vector3d log_gain(drift + balance(random), drift + balance(random), drift + balance(random));
    capture.true_log_gain.push_back(log_gain);
    for (int offset = -20; offset < 20; ++offset) {
      FaceCandidate candidate;
      candidate.face = (10 * p + offset + num_faces) % num_faces;
      candidate.photo = p;
      const bool outlier = unit(random) < outliers;
      for (int c = 0; c < 3; ++c) {
        const double seen = outlier ? radiance(random) : face_colour[static_cast<size_t>(candidate.face)][c];
        candidate.colour[static_cast<size_t>(c)] = static_cast<float>(seen * std::exp(-log_gain[c] + noise(random)));
      }
      per_photo[static_cast<size_t>(p)].push_back(candidate);
    }
  }
  capture.table = GroupByFace(static_cast<size_t>(num_faces), per_photo);
  return capture;
}

// The largest error of the gains' logs against the truth, up to a common shift per channel.
double LogGainError(const std::vector<Eigen::Vector3f>& gains, const std::vector<Eigen::Vector3d>& truth) {
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (size_t p = 0; p < gains.size(); ++p) shift += gains[p].cast<double>().array().log().matrix() - truth[p];
  shift /= static_cast<double>(gains.size());
  double error = 0.0;
  for (size_t p = 0; p < gains.size(); ++p) {
    const Eigen::Vector3d difference = gains[p].cast<double>().array().log().matrix() - truth[p] - shift;
    error = std::max(error, difference.cwiseAbs().maxCoeff());
  }
  return error;
}

TEST(PhotoGainsTest, LevelsAnExposureThatDriftsAroundTheCapture) {
  const RingCapture capture = MakeRing(40, 0.0, 1);
  const std::vector<Eigen::Vector3f> gains = EstimatePhotoGains(capture.table, 40);
  ASSERT_EQ(gains.size(), 40u);
  // Each photo's gain relative to its neighbour's is known to about 0.005 (2 % noise, some 30
  // faces shared); around the ring that adds up as a random walk. The drift spans 1.6 in log.
  EXPECT_LT(LogGainError(gains, capture.true_log_gain), 0.05);
}

TEST(PhotoGainsTest, APasserByDoesNotPullTheGains) {
  const RingCapture capture = MakeRing(40, 0.1, 2);
  EXPECT_LT(LogGainError(EstimatePhotoGains(capture.table, 40), capture.true_log_gain), 0.05);
}

TEST(PhotoGainsTest, KeepsTheMeanColourOfTheCandidates) {
  const RingCapture capture = MakeRing(20, 0.05, 3);
  const std::vector<Eigen::Vector3f> gains = EstimatePhotoGains(capture.table, 20);
  Eigen::Vector3d observed = Eigen::Vector3d::Zero(), levelled = Eigen::Vector3d::Zero();
  for (const FaceCandidate& candidate : capture.table.candidates) {
    for (int c = 0; c < 3; ++c) {
      observed[c] += candidate.colour[static_cast<size_t>(c)];
      levelled[c] += gains[static_cast<size_t>(candidate.photo)][c] * candidate.colour[static_cast<size_t>(c)];
    }
  }
  EXPECT_LT(((levelled - observed).array() / observed.array()).abs().maxCoeff(), 1e-5);
}

TEST(PhotoGainsTest, ClippedAndUnsharedCandidatesSayNothing) {
  // Photo 0 and 1 share face 0; photo 1 is twice as bright. Face 1, clipped in photo 1, would say
  // otherwise. Photo 2 shares no face: it keeps the common scale.
  std::vector<std::vector<FaceCandidate>> per_photo(3);
  auto add = [&](int photo, int face, float value) {
    FaceCandidate candidate;
    candidate.photo = photo;
    candidate.face = face;
    candidate.colour = {value, value, value};
    per_photo[static_cast<size_t>(photo)].push_back(candidate);
  };
  add(0, 0, 50.0f);
  add(1, 0, 100.0f);
  add(0, 1, 200.0f);
  add(1, 1, 255.0f);
  add(2, 2, 80.0f);
  const FaceCandidateTable table = GroupByFace(3, per_photo);
  const std::vector<Eigen::Vector3f> gains = EstimatePhotoGains(table, 3);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(gains[0][c] / gains[1][c], 2.0, 1e-4);
    EXPECT_NEAR(gains[2][c] * gains[2][c], gains[0][c] * gains[1][c], 1e-4);  // log gain 0 before the common scale
  }
}

TEST(PhotoGainsTest, NothingSharedLeavesEveryGainAtOne) {
  EXPECT_TRUE(EstimatePhotoGains(FaceCandidateTable(), 0).empty());
  const std::vector<Eigen::Vector3f> gains = EstimatePhotoGains(GroupByFace(0, {}), 2);
  ASSERT_EQ(gains.size(), 2u);
  for (const Eigen::Vector3f& gain : gains) EXPECT_EQ(gain, Eigen::Vector3f::Ones());
}

}  // namespace
}  // namespace reconar
