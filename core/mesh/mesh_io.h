#pragma once
// PLY (Stanford polygon file format) reading and writing for Mesh.
//
// ReadPly reads ascii, binary_little_endian and binary_big_endian files:
// - element "vertex": x y z (any scalar type, usually float or double); nx ny nz when all three are
//   present; red green blue [alpha] as uchar or as float/double in 0..1 when all three colours are
//   present (alpha defaults to 255). Other vertex properties (confidence, intensity, ...) are skipped.
// - element "face": the list property "vertex_indices" (or "vertex_index") with any integer count
//   and index type. Polygons with more than three corners are fan-triangulated (0,i,i+1); faces with
//   fewer than three corners are skipped. Other face properties are skipped.
// - every other element (edge, range_grid, material, ...) is skipped.
// Errors: kNotFound for a missing file; kCorruptData naming the file and the place for a bad header,
// a truncated body, a malformed number, a position that is not a finite float or a vertex index out
// of range; kUnsupported for valid PLY we do not read (a colour property of another integer type, a
// list-typed x).
//
// WritePly writes x y z (float), nx ny nz (float) when the mesh has normals, red green blue alpha
// (uchar) when it has colours, and "face" with "list uchar int vertex_indices" when it has
// triangles; atomically (core/base/atomic_file.h). ASCII numbers are the shortest text that reads
// back as the same float, so both formats round-trip exactly.
#include <string>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

Result<Mesh> ReadPly(const std::string& path);

enum class PlyFormat {
  kBinaryLittleEndian,
  kAscii,
};

// kInvalidArgument (nothing written) when the mesh is inconsistent (see ValidateMesh).
Status WritePly(const std::string& path, const Mesh& mesh, PlyFormat format = PlyFormat::kBinaryLittleEndian);

}  // namespace reconar
