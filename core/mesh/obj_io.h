#pragma once
// Wavefront OBJ writing and reading for Mesh (the text format every modeller opens).
//
// WriteObj writes, after a "# reconar" comment:
// - "v x y z" per vertex, "v x y z r g b" when the mesh has colours (the common vertex-colour
//   extension of MeshLab, Blender and CloudCompare; channels in 0..1 = byte / 255; alpha is lost);
// - "vn nx ny nz" per vertex when the mesh has normals (vertex i uses normal i);
// - "f a//a b//b c//c" per triangle with normals, "f a b c" without (1-based, counter-clockwise);
//   a point cloud is its "v" (and "vn") lines only.
// Numbers are the shortest text that reads back as the same float, so positions and normals
// round-trip exactly and colours to the same bytes. Written atomically. kInvalidArgument (nothing
// written) for an inconsistent mesh (ValidateMesh) or a non-finite position or normal.
//
// ReadObj reads "v" (3 numbers, 4 with a weight that is ignored, or 6 with r g b in 0..1), "vn"
// and "f" with corners "v", "v/vt", "v//vn" or "v/vt/vn" (negative = relative to the end, as the
// format allows); polygons are fan-triangulated (0,i,i+1). Every other statement (vt, g, o, s,
// usemtl, mtllib, l, p, ...) is skipped. OBJ indexes normals apart from positions while Mesh keeps
// one per vertex: vertex i takes the normal its face corners name, or "vn" number i when no corner
// names one and there are as many "vn" as "v" lines (point clouds); when some vertex would get two
// different normals or none, the mesh is returned without normals. Colours are kept when every
// vertex has them (alpha 255). Errors: kNotFound for a missing file; kCorruptData naming the file
// and line for a malformed number (nan and inf among them), a bad corner or an index out of range,
// and for a file without any vertex.
//
// ReadObjGroups reads the same, and splits the triangles by the group their face was in ("g NAME"
// or "o NAME", the latest of either; faces before any are the group "default"): one NamedMesh per
// group with faces, in the order the groups first appear, each with only the vertices its
// triangles use (their normals and colours with them). A file without faces is kCorruptData.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

Status WriteObj(const std::string& path, const Mesh& mesh);
// A texture page's image file, for the triangles from first_triangle on (core/mesh/mesh.h's
// TexturePage).
struct ObjTextureFile {
  size_t first_triangle = 0;
  std::string file_name;  // relative to the OBJ
};
// WriteObj with the mesh's texcoords ("vt u v", v flipped to OBJ's upward axis; corners "v/vt" or
// "v/vt/vn") and a material library beside it (OBJ's stem + ".mtl", written first, atomically)
// with a material per page ("texture", "texture_1", ...; "usemtl" before the page's first face)
// mapping the page's file (written by the caller) as the diffuse colour. kInvalidArgument,
// nothing written, for a mesh without texcoords or pages out of order.
Status WriteTexturedObj(const std::string& obj_path, const Mesh& mesh, const std::vector<ObjTextureFile>& pages);
Result<Mesh> ReadObj(const std::string& path);
Result<std::vector<NamedMesh>> ReadObjGroups(const std::string& path);

}  // namespace reconar
