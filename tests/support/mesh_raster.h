#pragma once
// Which triangle of a mesh each pixel of a pinhole camera sees: a z-buffer rasterizer on the CPU,
// for rendered test scenes with exact cameras (object_capture.h). Pixel centres are at integer
// coordinates, x right, y down, the camera looking down +z (x_pixel = fx X/Z + cx). A pixel is
// covered when its centre lies inside or on an edge of a triangle's projection (so a shared edge
// leaves no crack), and the triangle nearest along the pixel's ray wins (depth interpolated
// perspective-correctly). Both sides of a triangle are drawn. Test support only.
#include <cstdint>

#include "core/base/image.h"
#include "core/math/rigid3.h"
#include "core/mesh/mesh.h"

namespace reconar::testing {

struct PinholeView {
  double fx = 1.0, fy = 1.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;
  Rigid3 cam_from_world;
};

struct TriangleRaster {
  Image<int32_t> triangle;  // index into Mesh::triangles, -1 where no triangle is seen
  Image<float> depth;       // camera z of the surface seen, 0 where none
};

// Triangles with a corner closer than `near_m` in front of the camera (or behind it) are left out.
TriangleRaster RasterizeTriangles(const Mesh& mesh, const PinholeView& view, double near_m = 1e-3);

}  // namespace reconar::testing
