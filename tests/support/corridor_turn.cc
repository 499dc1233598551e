// The L-shaped corridor of corridor_walk.h. Coordinates on the ground are (x, z); a leg's frame is
// its direction `along` (the heading of a walker going down it) and `right`, its centre line
// passing through the corner point (0, 0, corner_z) where the two legs' centre lines meet.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "tests/support/corridor_rendering.h"
#include "tests/support/corridor_walk.h"

namespace reconar::testing {
namespace {

constexpr double kDegree = M_PI / 180.0;

Eigen::Vector2d Along(double heading) { return {std::sin(heading), std::cos(heading)}; }
Eigen::Vector2d Right(double heading) { return {std::cos(heading), -std::sin(heading)}; }
Eigen::Vector2d Ground(const Eigen::Vector3d& p) { return {p.x(), p.z()}; }

// The walk and the corridor built round it: down the z axis, round the corner on a circular arc of
// `turn` radians over arc_length_m (the heading turning evenly with the distance walked), then
// straight down the second leg.
struct CornerWalk {
  double step_m = 0.0;
  double turn = 0.0;  // radians, positive to the right
  double arc_start_m = 0.0;
  double arc_length_m = 0.0;
  Eigen::Vector2d arc_end = Eigen::Vector2d::Zero();
  Eigen::Vector2d corner = Eigen::Vector2d::Zero();  // (0, corner_z)
  double half_width_m = 0.0;
  double end_m = 0.0;     // the end wall's distance from the corner down the second leg
  double tan_half = 0.0;  // tan(turn / 2): the corners' offsets along the legs, per metre of half width

  static Result<CornerWalk> Of(const CorridorTurnOptions& options) {
    const CorridorWalkOptions& walk = options.walk;
    RECONAR_RETURN_IF_ERROR(corridor::CheckWalkOptions(walk, "RenderCorridorTurn"));
    const double magnitude = std::abs(options.turn_deg);
    if (!(magnitude >= 15.0 && magnitude <= 135.0)) {
      return InvalidArgument("RenderCorridorTurn: turn_deg must be 15..135 degrees either way");
    }
    const int turn_frame = options.turn_frame < 0 ? walk.frames / 2 : options.turn_frame;
    if (options.turn_steps < 1 || turn_frame - 0.5 * options.turn_steps < 0.0) {
      return InvalidArgument("RenderCorridorTurn: the turn must take at least one step and start at or after frame 0");
    }
    CornerWalk path;
    path.step_m = walk.step_m;
    path.turn = options.turn_deg * kDegree;
    path.arc_start_m = walk.step_m * (turn_frame - 0.5 * options.turn_steps);
    path.arc_length_m = walk.step_m * options.turn_steps;
    const double radius = path.arc_length_m / path.turn;  // signed: the centre of the arc is to the right
    path.arc_end =
        Eigen::Vector2d(radius * (1.0 - std::cos(path.turn)), path.arc_start_m + radius * std::sin(path.turn));
    const Eigen::Vector2d second = Along(path.turn);
    path.corner = Eigen::Vector2d(0.0, path.arc_end.y() - path.arc_end.x() / second.x() * second.y());
    path.half_width_m = walk.half_width_m;
    path.end_m = walk.length_m - path.corner.y();
    path.tan_half = std::tan(0.5 * path.turn);
    // Every eye inside the corridor, a quarter of a metre from its walls, and the last one at least
    // a metre from the end wall.
    for (int i = 0; i < walk.frames; ++i) {
      const Eigen::Vector2d eye = Ground(path.Camera(walk, i).Centre());
      const bool first_leg = path.OnFirstLeg(eye);
      const double across = first_leg ? eye.x() : (eye - path.corner).dot(Right(path.turn));
      const double along = first_leg ? 0.0 : (eye - path.corner).dot(second);
      if (std::abs(across) > path.half_width_m - 0.25 || along > path.end_m - 1.0) {
        return InvalidArgument("RenderCorridorTurn: frame " + std::to_string(i) +
                               "'s eye leaves the corridor (too tight a turn, or too short a second leg)");
      }
    }
    return path;
  }

  // The walker's eye and heading after walking `distance` metres.
  void At(double distance, Eigen::Vector3d* eye, double* heading) const {
    if (distance <= arc_start_m) {
      *eye = Eigen::Vector3d(0.0, 0.0, distance);
      *heading = 0.0;
    } else if (distance < arc_start_m + arc_length_m) {
      const double radius = arc_length_m / turn;
      *heading = turn * (distance - arc_start_m) / arc_length_m;
      *eye = Eigen::Vector3d(radius * (1.0 - std::cos(*heading)), 0.0, arc_start_m + radius * std::sin(*heading));
    } else {
      const Eigen::Vector2d on = arc_end + (distance - arc_start_m - arc_length_m) * Along(turn);
      *eye = Eigen::Vector3d(on.x(), 0.0, on.y());
      *heading = turn;
    }
  }

  GroundTruthCamera Camera(const CorridorWalkOptions& walk, int i) const {
    Eigen::Vector3d eye;
    double heading = 0.0;
    At(step_m * i, &eye, &heading);
    return corridor::HandHeldCamera(walk, i, eye, heading);
  }

  // Which leg a point on the ground belongs to: the legs meet on the line through both corners,
  // normal to the bisecting heading.
  bool OnFirstLeg(const Eigen::Vector2d& ground) const { return (ground - corner).dot(Along(0.5 * turn)) < 0.0; }
};

// A strip of panels down a surface: panel k spans [origin + k length, origin + (k + 1) length),
// the first and last stretched beyond.
struct PanelStrip {
  int first_texture = 0;
  int stride = 1;  // between a panel's texture and the next panel's
  int panels = 1;
  double origin_m = 0.0;
};

class CornerCorridor {
 public:
  // The textures each leg needs: its left wall, right wall, floor and ceiling interleaved per panel
  // (first leg, then second), then the end wall.
  static int TextureCount(const CorridorWalkOptions& options, const CornerWalk& path) {
    return 4 * (FirstLegPanels(options, path) + SecondLegPanels(options, path)) + 1;
  }

  CornerCorridor(const CorridorWalkOptions& options, const CornerWalk& path, std::vector<RgbTexture> textures)
      : options_(options), path_(path), textures_(std::move(textures)) {
    const int first = FirstLegPanels(options, path), second = SecondLegPanels(options, path);
    for (int k = 0; k < 4; ++k) {
      first_leg_[k] = {k, 4, first, 0.0};
      second_leg_[k] = {4 * first + k, 4, second, SecondLegOrigin(path)};
    }
  }

  Eigen::Vector3f Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
    const double w = path_.half_width_m;
    const double up = options_.ceiling_above_eye_m;
    const double height = options_.eye_above_floor_m + up;
    double nearest = std::numeric_limits<double>::infinity();
    Eigen::Vector3f colour(0.0f, 0.0f, 0.0f);
    const Eigen::Vector2d ground_origin = Ground(origin), ground_direction = Ground(direction);
    // A vertical wall through `start` running along `run`, from `from` to `to` metres along it.
    auto try_wall = [&](const Eigen::Vector2d& start, const Eigen::Vector2d& run, double from, double to,
                        auto&& texture_at) {
      const Eigen::Vector2d normal(run.y(), -run.x());
      const double rate = normal.dot(ground_direction);
      if (std::abs(rate) < 1e-12) return;
      const double t = normal.dot(start - ground_origin) / rate;
      if (t <= 0.0 || t >= nearest) return;
      const double s = (ground_origin + t * ground_direction - start).dot(run);
      if (s < from || s > to) return;
      nearest = t;
      colour = texture_at(s, ((origin.y() + t * direction.y()) + up) / height);
    };
    const double infinity = std::numeric_limits<double>::infinity();
    const Eigen::Vector2d z_axis(0.0, 1.0);
    const Eigen::Vector2d along = Along(path_.turn), right = Right(path_.turn);
    // The first leg's walls run along z from the start (s = z) to the corners, the second leg's from
    // the corners (s measured from the corner point) to the end wall.
    for (const int side : {-1, 1}) {
      const int strip = side < 0 ? 0 : 1;
      const double corner_s = -side * w * path_.tan_half;
      try_wall(Eigen::Vector2d(side * w, 0.0), z_axis, -infinity, path_.corner.y() + corner_s,
               [&](double s, double v) { return Sample(first_leg_[strip], s, v); });
      try_wall(path_.corner + side * w * right, along, -corner_s, path_.end_m,
               [&](double s, double v) { return Sample(second_leg_[strip], s, v); });
    }
    const int end_texture = static_cast<int>(textures_.size()) - 1;
    try_wall(path_.corner + path_.end_m * along, right, -w, w, [&](double s, double v) {
      return textures_[static_cast<size_t>(end_texture)].Sample((s + w) / (2 * w), v);
    });
    // Floor and ceiling: panels down each leg, across from its left wall to its right.
    for (const int strip : {2, 3}) {
      const double plane = strip == 2 ? options_.eye_above_floor_m : -up;
      if (std::abs(direction.y()) < 1e-12) continue;
      const double t = (plane - origin.y()) / direction.y();
      if (t <= 0.0 || t >= nearest) continue;
      nearest = t;
      const Eigen::Vector2d hit = ground_origin + t * ground_direction;
      if (path_.OnFirstLeg(hit)) {
        colour = Sample(first_leg_[strip], hit.y(), (hit.x() + w) / (2 * w));
      } else {
        const Eigen::Vector2d from_corner = hit - path_.corner;
        colour = Sample(second_leg_[strip], from_corner.dot(along), (from_corner.dot(right) + w) / (2 * w));
      }
    }
    return colour;
  }

 private:
  static double SecondLegOrigin(const CornerWalk& path) { return -path.half_width_m * std::abs(path.tan_half); }
  static int FirstLegPanels(const CorridorWalkOptions& options, const CornerWalk& path) {
    const double length = path.corner.y() + path.half_width_m * std::abs(path.tan_half);
    return std::max(1, static_cast<int>(std::ceil(length / options.panel_length_m)));
  }
  static int SecondLegPanels(const CorridorWalkOptions& options, const CornerWalk& path) {
    return std::max(1, static_cast<int>(std::ceil((path.end_m - SecondLegOrigin(path)) / options.panel_length_m)));
  }

  Eigen::Vector3f Sample(const PanelStrip& strip, double s, double v) const {
    const double panel_coordinate = (s - strip.origin_m) / options_.panel_length_m;
    const int panel = std::clamp(static_cast<int>(std::floor(panel_coordinate)), 0, strip.panels - 1);
    const double u = std::clamp(panel_coordinate - panel, 0.0, 1.0);
    return textures_[static_cast<size_t>(strip.first_texture + strip.stride * panel)].Sample(u, v);
  }

  CorridorWalkOptions options_;
  CornerWalk path_;
  std::vector<RgbTexture> textures_;
  PanelStrip first_leg_[4];
  PanelStrip second_leg_[4];
};

}  // namespace

Result<GroundTruthCamera> CorridorTurnCamera(const CorridorTurnOptions& options, int i) {
  RECONAR_ASSIGN_OR_RETURN(const CornerWalk path, CornerWalk::Of(options));
  return path.Camera(options.walk, i);
}

Result<CorridorTurnLayout> CorridorTurnLayoutOf(const CorridorTurnOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const CornerWalk path, CornerWalk::Of(options));
  CorridorTurnLayout layout;
  layout.corner_z_m = path.corner.y();
  layout.end_wall_m = path.end_m;
  return layout;
}

Result<GroundTruthByName> RenderCorridorTurn(const std::string& out_dir, const CorridorTurnOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const CornerWalk path, CornerWalk::Of(options));
  const CorridorWalkOptions& walk = options.walk;
  const CornerCorridor scene(walk, path, corridor::PanelTextures(walk, CornerCorridor::TextureCount(walk, path)));
  std::vector<GroundTruthCamera> cameras;
  for (int i = 0; i < walk.frames; ++i) cameras.push_back(path.Camera(walk, i));
  return corridor::RenderWalkFrames(out_dir, walk, cameras, [&](const GroundTruthCamera& camera) {
    return corridor::RenderView(scene, camera, walk.supersampling);
  });
}

}  // namespace reconar::testing
