#pragma once
// VRML 2.0 (VRML97, ISO/IEC 14772-1) writing for Mesh: the export format of the paper.
//
// WriteVrml writes "#VRML V2.0 utf8" and one Shape:
// - a triangle mesh as geometry IndexedFaceSet { solid FALSE ccw TRUE, coord Coordinate { point },
//   color Color { color } with colorPerVertex TRUE when the mesh has colours (channels byte / 255;
//   alpha is lost), normal Normal { vector } with normalPerVertex TRUE when it has normals,
//   coordIndex with a -1 after each triangle }; colorIndex and normalIndex are left empty, so
//   VRML takes them from coordIndex. The appearance is a grey Material, whose diffuse colour the
//   vertex colours replace (VRML97 6.24);
// - a point cloud as geometry PointSet { coord, color }; PointSet is unlit and has no normals, so
//   the Material's emissiveColor gives uncoloured points their grey.
// Numbers are the shortest text that reads back as the same float. Written atomically.
// kInvalidArgument (nothing written) for an inconsistent mesh (ValidateMesh) or a non-finite
// position or normal.
#include <string>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

Status WriteVrml(const std::string& path, const Mesh& mesh);

}  // namespace reconar
