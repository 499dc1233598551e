#pragma once
// Screened Poisson surface reconstruction (Kazhdan & Hoppe 2013, "Screened Poisson Surface
// Reconstruction", ACM ToG 32(3); Kazhdan, Bolitho & Hoppe 2006, "Poisson Surface
// Reconstruction", SGP) of a watertight mesh from oriented points.
//
// Method, as implemented here:
//  - The points are mapped into a cube of edge `scale` x the bounding box's largest edge.
//  - Sampling density: every sample is splatted with trilinear (first-order B-spline) weights
//    into the grid of depth `depth - 2` (PoissonRecon's kernel depth); the density at a point is
//    the interpolated splat sum ("samples per kernel-depth node"). A sample stands for the surface
//    area h_kernel^2 / density, which weights its normal, its screening term and the iso-value.
//  - Hierarchy: one regular grid per depth from min(depth, 5) to `depth`. The coarsest is complete;
//    each finer one is stored only in a band (8^3-node blocks) around the cells holding samples and
//    the cells where the coarser solution crosses the iso-value, so the band follows the surface
//    also where Poisson closes holes in the data.
//  - FEM (`degree`, fem_level.h): quadratic B-splines centred on the cells (default, as
//    PoissonRecon's --degree 2: 3 cells of support per axis, 5^3 stencils, prolongation
//    [1,3,3,1]/4, Neumann boundary by reflection) or trilinear hats on the nodes (degree 1).
//    The normal field V is splatted with the basis' own kernel (degree 2) or node-centred
//    quadratic weights (degree 1). Screened energy |grad chi - V|^2 + point_weight * 2^depth *
//    sum_s area_s chi(p_s)^2 (samples merged per cell, as PoissonRecon does); cascadic solve
//    coarse to fine with Jacobi-preconditioned CG, the finer level correcting the prolonged
//    coarser solution inside its band.
//  - Iso-value: area-weighted mean of chi at the samples. Surface: marching cubes on the finest
//    band (watertight: cube polygons are derived face-consistently, see marching_cubes.h) over
//    chi at the cell corners. Degree 2: a corner's value is the B-spline sum (the mean of its 8
//    cells' coefficients) and each iso-vertex is the root of chi along its cube edge, a C1
//    piecewise quadratic known exactly from the end values and the edge midpoint's value and
//    slope (PoissonRecon fits one quadratic per edge to values and derivatives instead).
//  - Trim: every output vertex gets PoissonRecon's density value, the estimated octree depth at
//    which a node would hold `samples_per_node` samples: kernel_depth + log4(density /
//    samples_per_node), or where that is below kernel_depth, found between the coarser depths
//    whose nodes first hold enough samples (as PoissonRecon 8). The surface is cut along the
//    line where this value equals `trim` and the part below is dropped, except components
//    smaller than 0.001 of the area, which swap sides (SurfaceTrimmer --trim with its default
//    --aRatio; see surface_trim.h).
//
// On the bunny range scans at depth 8 (tests/core/mesh/poisson/poisson_bunny_test.cc) degree 2
// is closer to the reference than degree 1 by ~8 % both ways and than PoissonRecon 8.0 (COLMAP
// 3.8's poisson_mesher) too, at about the same cost as degree 1.
#include <cstddef>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

struct PoissonOptions {
  int depth = 8;                  // finest grid: 2^depth cells per cube edge (PoissonRecon --depth); 2..11
  // Screening weight alpha (PoissonRecon --pointWeight); 0 = unscreened Poisson. The default is
  // COLMAP's (--PoissonMeshing.point_weight 1), the pipeline this one replaces; PoissonRecon's own
  // command line defaults to 4, which fits the samples more tightly (and their noise with them).
  // Normalised as PoissonRecon 8 does in total: alpha * 2^depth * (sampled surface area in
  // unit-cube units), here spread over the samples by their area instead of evenly per sample.
  double point_weight = 1.0;
  // B-spline degree of the finite elements: 2 = quadratic B-splines on the cells (PoissonRecon's
  // --degree 2), each iso-vertex at the root of the B-spline sum along its cube edge; 1 =
  // trilinear hats on the grid nodes, iso-vertices by linear interpolation.
  int degree = 2;
  double samples_per_node = 1.5;  // PoissonRecon --samplesPerNode: the density unit of the trim value
  double scale = 1.1;             // bounding cube edge / bounding box's largest edge (>= 1)
  // Density trim like SurfaceTrimmer --trim: drop the surface whose estimated sample depth (see
  // above) is below this, cutting triangles along the trim line (surface_trim.h). 0 keeps
  // everything (the default: trimming is a choice about the data).
  // A value of depth - 1 drops surface where samples are ~4x sparser than one sample group per
  // finest cell, e.g. where Poisson bridged holes in the data.
  double trim = 0.0;
  // Threads of the CG solve (matrix-vector products, vector updates); the result is the same for
  // any count (fixed work split and summation order, see fem_level.h).
  int num_threads = 1;
  bool show_progress = false;     // core/base/progress.h lines on stderr

  // Ok, or kInvalidArgument naming the offending option.
  Status Check() const;
};

struct PoissonReport {
  int octree_nodes = 0;       // grid nodes stored over all levels
  int unknowns = 0;           // nodes solved for over all levels
  int solver_iterations = 0;  // CG iterations over all levels
  size_t vertices = 0, triangles = 0;
  size_t cells_skipped = 0;   // crossing cells left open at the band's edge (0 = watertight)
  double iso_value = 0.0;
  double seconds_octree = 0.0, seconds_solve = 0.0, seconds_extract = 0.0, seconds_trim = 0.0;
};

// oriented_points: a point cloud Mesh with positions and unit normals (outward); optional colours
// become output vertex colours interpolated from the nearby samples. Triangles of the input are
// ignored. Returns kInvalidArgument naming the reason when there are no normals, fewer than 3
// points, non-finite coordinates or all points coincide. Output: counter-clockwise triangles seen
// from outside, vertex normals from the triangles.
Result<Mesh> ReconstructPoissonSurface(const Mesh& oriented_points, const PoissonOptions& options,
                                       PoissonReport* report = nullptr);

}  // namespace reconar
