#pragma once
// Triangulation of tracks into the mapper's model: one track, the tracks of a newly registered
// image, or every track after a global adjustment. A point is created when at least two
// registered views agree within MapperOptions::max_reprojection_error_px at a triangulation angle
// of at least min_triangulation_angle_deg.
#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// Triangulates track t from its registered views (all of them, else the best pair of the first
// 12); true when a point was created.
bool TriangulateTrack(MapperModel* model, int track, const MapperOptions& options);

// New points from the tracks of `image`, and its observations of existing points that the pose
// estimate did not take (within the error bound).
void TriangulateImage(MapperModel* model, int image, const MapperOptions& options);

// Every untriangulated track, then the observations in registered images of the triangulated
// ones that are not attached yet (within the error bound).
void RetriangulateAll(MapperModel* model, const MapperOptions& options);

}  // namespace reconar
