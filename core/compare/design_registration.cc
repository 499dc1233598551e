#include "core/compare/design_registration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "core/compare/point_to_plane.h"
#include "core/math/point_spread.h"
#include "core/mesh/triangle_bvh.h"

namespace reconar {
namespace {

struct Unit {
  const char* name;
  double metres;
};
constexpr Unit kUnits[] = {{"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"in", 0.0254}, {"ft", 0.3048}};

double RotationAngleDeg(const Eigen::Matrix3d& rotation) {
  return std::acos(std::clamp((rotation.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
}

// How far the ICP may take the control points beyond twice their own RMS: a design drawn to the
// millimetre, tags placed to a few.
constexpr double kControlSlack = 0.005;

std::vector<double> ControlResiduals(const std::vector<ControlPair>& control, const Sim3& world_from_design) {
  std::vector<double> residuals;
  for (const ControlPair& pair : control) residuals.push_back((world_from_design.Apply(pair.design) - pair.world).norm());
  return residuals;
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double squares = 0.0;
  for (const double value : values) squares += value * value;
  return std::sqrt(squares / static_cast<double>(values.size()));
}

double ControlRms(const std::vector<ControlPair>& control, const Sim3& world_from_design) {
  return Rms(ControlResiduals(control, world_from_design));
}

}  // namespace

std::vector<NamedMesh> PlacedElements(const Design& design, const Sim3& world_from_design) {
  std::vector<NamedMesh> placed;
  placed.reserve(design.elements.size());
  for (const NamedMesh& element : design.elements) {
    NamedMesh moved{element.name, Mesh()};
    moved.mesh.positions.reserve(element.mesh.positions.size());
    for (const Eigen::Vector3f& p : element.mesh.positions) {
      moved.mesh.positions.push_back(world_from_design.Apply(p.cast<double>()).cast<float>());
    }
    moved.mesh.triangles = element.mesh.triangles;
    placed.push_back(std::move(moved));
  }
  return placed;
}

DesignSurface PlaceDesign(const Design& design, const Sim3& world_from_design) {
  DesignSurface surface;
  surface.mesh = JoinMeshes(PlacedElements(design, world_from_design));
  for (size_t e = 0; e < design.elements.size(); ++e) {
    surface.element_of_triangle.insert(surface.element_of_triangle.end(), design.elements[e].mesh.triangles.size(),
                                       static_cast<int>(e));
  }
  surface.face_normals.reserve(surface.mesh.triangles.size());
  for (const std::array<uint32_t, 3>& t : surface.mesh.triangles) {
    const Eigen::Vector3d a = surface.mesh.positions[t[0]].cast<double>();
    const Eigen::Vector3d normal =
        (surface.mesh.positions[t[1]].cast<double>() - a).cross(surface.mesh.positions[t[2]].cast<double>() - a);
    surface.face_normals.push_back(normal.norm() > 0.0 ? Eigen::Vector3d(normal.normalized()) : Eigen::Vector3d::Zero());
  }
  return surface;
}

Result<DesignRegistration> RegisterDesign(const Design& design, const std::vector<ControlPair>& control,
                                          const std::vector<Eigen::Vector3d>& as_built,
                                          const DesignRegistrationOptions& options) {
  DesignRegistration registration;
  if (!control.empty()) {
    if (control.size() < 3) {
      return InvalidArgument("design registration: " + std::to_string(control.size()) +
                             " control point(s); a similarity needs 3 not on one line (a tag's 4 corners, or 3 "
                             "tags' centres)");
    }
    std::vector<Eigen::Vector3d> from, to;
    for (const ControlPair& pair : control) {
      from.push_back(pair.design);
      to.push_back(pair.world);
    }
    // Collinear points fix no turn about their line: the second eigenvalue of their spread.
    const Eigen::Vector3d spread = SpreadOfPoints(from).eigenvalues;
    if (!(spread[1] > 1e-12 * spread[2])) {
      return InvalidArgument("design registration: the control points lie on one line");
    }
    RECONAR_ASSIGN_OR_RETURN(const Sim3 free_fit, AlignSimilarity(from, to));
    registration.control_scale = free_fit.scale;
    if (options.similarity) {
      registration.world_from_design = free_fit;
      registration.units = "fitted";
      registration.metres_per_unit = free_fit.scale;
    } else {
      const Unit* unit = nullptr;
      for (const Unit& candidate : kUnits) {
        if (std::abs(std::log(free_fit.scale / candidate.metres)) < std::log(1.03)) unit = &candidate;
      }
      if (unit == nullptr) {
        char scale[64];
        std::snprintf(scale, sizeof(scale), "%.6g", free_fit.scale);
        return InvalidArgument(std::string("design registration: the control points put ") + scale +
                               " m in a design unit, which is no metre, centimetre, millimetre, inch or foot (within "
                               "3 %); check the control file, or fit the scale (--similarity)");
      }
      registration.units = unit->name;
      registration.metres_per_unit = unit->metres;
      RECONAR_ASSIGN_OR_RETURN(registration.world_from_design, AlignSimilarity(from, to, unit->metres));
    }
  }

  if (options.refine && !as_built.empty()) {
    const DesignSurface surface = PlaceDesign(design, registration.world_from_design);
    const TriangleBvh bvh(surface.mesh);
    std::vector<Eigen::Vector3d> points;
    const size_t stride = std::max<size_t>(1, as_built.size() / static_cast<size_t>(std::max(1, options.max_points)));
    for (size_t i = 0; i < as_built.size(); i += stride) points.push_back(as_built[i]);
    PointToPlaneOptions icp;
    // The ICP refines the control's placement; it does not replace it. With control it starts
    // from points within 3 x the control's RMS (at least 1 cm) of the design, so that an element
    // built a few centimetres off (a column moved 4 cm) cannot pull the whole design half way
    // toward itself before the bound tightens.
    icp.max_distance = options.max_distance;
    const double control_rms = ControlRms(control, registration.world_from_design);
    if (!control.empty()) {
      icp.max_distance = std::clamp(3.0 * control_rms, std::min(0.01, options.max_distance), options.max_distance);
    }
    icp.max_iterations = options.max_iterations;
    ThreadPool pool(ThreadPool::ResolveThreadCount(options.num_threads));
    const PointToPlaneReport fit = AlignPointsToSurface(points, bvh, surface.face_normals, icp, Rigid3(), &pool);
    // The points moved onto the design: the design moves by the inverse onto the points.
    const Rigid3 world_from_placed = fit.surface_from_points.Inverse();
    Sim3 refined = registration.world_from_design;
    refined.rotation = world_from_placed.rotation * refined.rotation;
    refined.translation = world_from_placed.rotation * refined.translation + world_from_placed.translation;
    // Accepted only when it keeps to the control: surfaces that leave a motion weakly held (walls
    // alone, with a few points near their top and bottom faces) let the ICP slide the design along
    // them (the room's four walls: 155 mm, the control then 158 mm off).
    const double refined_control_rms = ControlRms(control, refined);
    if (fit.inliers >= 6 && refined_control_rms > 2.0 * control_rms + kControlSlack) {
      char reason[160];
      std::snprintf(reason, sizeof(reason),
                    "the ICP's placement put the control points %.1f mm RMS off (%.1f mm from the control alone)",
                    1000.0 * refined_control_rms, 1000.0 * control_rms);
      registration.icp_rejected = reason;
    } else if (fit.inliers >= 6) {
      registration.world_from_design = refined;
      registration.refined = true;
      registration.icp_rms_m = fit.rms;
      registration.points_used = fit.inliers;
      // The overlap: the share of the points within max_distance of the placed design.
      int near = 0;
      const Rigid3 placed_from_world = fit.surface_from_points;
      for (const Eigen::Vector3d& p : points) near += bvh.Nearest(placed_from_world * p, options.max_distance).triangle >= 0;
      registration.overlap = static_cast<double>(near) / static_cast<double>(points.size());
      registration.icp_iterations = fit.iterations;
      registration.free_directions = fit.free_directions;
      registration.icp_turn_deg = RotationAngleDeg(world_from_placed.rotation);
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& p : points) centre += p / static_cast<double>(points.size());
      registration.icp_shift_m = (world_from_placed * centre - centre).norm();
    }
  }
  registration.control_residuals_m = ControlResiduals(control, registration.world_from_design);
  registration.control_rms_m = Rms(registration.control_residuals_m);
  return registration;
}

}  // namespace reconar
