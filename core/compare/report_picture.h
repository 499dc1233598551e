#pragma once
// compare/report.png: the comparison as one picture a person can read on site: the registration in
// a line, a histogram of the signed deviations, a top view of the as-built points coloured by their
// deviation with the elements named where they stand, the colour scale, and the per-element table.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/compare/compare_project.h"
#include "core/mesh/mesh.h"

namespace reconar {

// The diverging colour scale of the outputs: blue below (inside) the design, white on it, red above
// (outside), saturated at `full` metres.
std::array<uint8_t, 4> DeviationColour(double signed_m, double full);

// The scale as geometry, for the 3D outputs: a strip of quads from `start` along `along` (its
// length) and `across` (its width), coloured from -full (at start) to +full, with its name saying
// what the colours mean.
NamedMesh DeviationLegendStrip(double full, double world_units_per_metre, const Eigen::Vector3d& start,
                               const Eigen::Vector3d& along, const Eigen::Vector3d& across);

// `points`: the as-built points the report was computed on (its element_of_point and
// signed_distance_m are per point); `up`: the unit direction the top view looks down along.
Image<uint8_t> DrawCompareReport(const CompareReport& report, const CompareOptions& options,
                                 const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up);

}  // namespace reconar
