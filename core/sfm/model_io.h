#pragma once
// Readers and writers of the sparse model (core/sfm/reconstruction.h) in the formats other tools
// read: COLMAP text (cameras.txt, images.txt, points3D.txt), Bundler v0.3 (bundle.out +
// list.txt) and a PLY point cloud. Every file is written atomically.
//
// What the writers export: all cameras, the registered images, and the points that are not
// deleted and are seen by at least one registered image. Track elements in unregistered images
// are dropped, and keypoints whose point is not exported get POINT3D_ID -1.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

// COLMAP text model in `dir` (created if missing), as COLMAP's model_converter writes it.
// Camera i gets CAMERA_ID i + 1 (model RADIAL: f cx cy k1 k2), image i IMAGE_ID i + 1, point i
// POINT3D_ID i + 1. Pixel coordinates (keypoints, principal point) are shifted by +0.5: COLMAP
// puts the centre of the top-left pixel at (0.5, 0.5), we put it at (0, 0).
Status WriteColmapTextModel(const Reconstruction& reconstruction, const std::string& dir);

// Reads cameras.txt, images.txt and points3D.txt from `dir`. Camera models SIMPLE_PINHOLE,
// PINHOLE (only with fx = fy to 1e-6 relative), SIMPLE_RADIAL and RADIAL are accepted. Cameras,
// images and points are stored in increasing id order; every image read is registered.
// Errors name the place: "dir/images.txt:12: reason".
Result<Reconstruction> ReadColmapTextModel(const std::string& dir);

// Bundler v0.3 (Snavely's bundle.out) and its list.txt, one line per image in image order:
// image_paths[i] if given (then one per image), else images[i].name.
// Bundler's camera looks down -z with y up, so R_bundler = diag(1,-1,-1) R and likewise t, and
// its keys are relative to the image centre with y up: x = u - (w-1)/2, y = (h-1)/2 - v in our
// pixel convention. Bundler has no principal point: its readers assume it at the image centre, so
// a model whose cx, cy lie elsewhere (or whose aspect is not 1) projects off its keys by the
// difference; the COLMAP model is the exact one. Unregistered images
// are written as all-zero cameras, as Bundler does.
Status WriteBundlerModel(const Reconstruction& reconstruction, const std::string& bundle_out_path,
                         const std::string& list_txt_path, const std::vector<std::string>& image_paths = {});

// Binary little-endian PLY of the exported points: x y z (float), red green blue (uchar).
Status WritePointsPly(const Reconstruction& reconstruction, const std::string& path);

}  // namespace reconar
