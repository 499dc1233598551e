#pragma once
// glTF 2.0 binary (.glb) writing and reading for Mesh (https://registry.khronos.org/glTF/specs/2.0/).
//
// WriteGlb writes one scene with one node and one mesh of one primitive:
// - POSITION: float VEC3 with the min/max the specification requires;
// - NORMAL: float VEC3 when the mesh has normals (they must be unit length, as glTF requires);
// - COLOR_0: normalized unsigned byte VEC4 when the mesh has colours. The bytes are stored
//   unchanged: glTF defines COLOR_0 as linear, our colours come from photographs (sRGB), so a
//   viewer shows them somewhat lighter than the photographs;
// - mode TRIANGLES with uint16 indices when every index fits below 65535, uint32 otherwise; a mesh
//   without triangles (a point cloud) is written as mode POINTS without indices;
// - no material (viewers use the default material, modulated by COLOR_0); asset version "2.0",
//   generator "reconar". Each buffer view starts on a 4-byte boundary, the JSON chunk is padded with
//   spaces and the BIN chunk with zeros to 4 bytes. Written atomically.
//
// WriteTexturedGlb writes the same with TEXCOORD_0 (float VEC2) and one material per texture page:
// the page's PNG as its base colour texture (embedded in the BIN chunk; sampler linear, mipmapped,
// clamped to the edge), metallic 0, roughness 1. One page is the mesh as one primitive; several
// pages are one primitive each (the page's triangles and the vertices they use), in page order,
// of the one mesh. COLOR_0, when the mesh has it, multiplies the texture (glTF's rule).
//
// ReadGlb reads the first primitive of the first mesh: POSITION, NORMAL and COLOR_0 (float, or
// normalized unsigned byte/short; VEC3 colours get alpha 255) and the indices (unsigned
// byte/short/int), in mode TRIANGLES or POINTS, in the mesh's own frame (node transforms are not
// applied). kUnsupported for glTF 1.0, extensionsRequired (e.g. KHR_draco_mesh_compression), a
// draco-compressed primitive, sparse accessors, buffers with a URI (external file or data: URI),
// other primitive modes, indexed POINTS. kCorruptData naming the file and the JSON path (e.g.
// "accessors[3].count") for anything that does not parse or lies outside its buffer.
//
// The scene functions read and write a design model: several named elements, one node each.
// WriteGlbScene writes one scene of one node per element (named, unless the name is empty), each
// with its own mesh of one primitive laid out as WriteGlb lays out its mesh; WriteGlb is the scene
// of one unnamed element. ReadGltfScene reads what WriteGlbScene writes and the scenes of other
// tools, .glb or .gltf (see DecodeGltfScene).
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

// The .glb bytes. kInvalidArgument for an inconsistent mesh (ValidateMesh), an empty one, or
// non-finite positions or normals.
Result<std::string> EncodeGlb(const Mesh& mesh);
Status WriteGlb(const std::string& path, const Mesh& mesh);

// `name_for_errors` prefixes every message.
Result<Mesh> DecodeGlb(std::string_view bytes, const std::string& name_for_errors);
Result<Mesh> ReadGlb(const std::string& path);

// Whether `bytes` start with the PNG signature.
bool IsPngSignature(std::string_view bytes);

// A texture page as a file holds it (core/mesh/mesh.h's TexturePage, encoded).
struct EncodedTexturePage {
  size_t first_triangle = 0;
  std::string image;  // PNG or JPEG bytes
};

// kInvalidArgument as EncodeGlb, and for a mesh without texcoords, pages out of order
// (ValidateTexturePages) or an image that is not a PNG.
Result<std::string> EncodeTexturedGlb(const Mesh& mesh, const std::vector<EncodedTexturePage>& pages);
Status WriteTexturedGlb(const std::string& path, const Mesh& mesh, const std::vector<EncodedTexturePage>& pages);

// A mesh with its texture as a .glb holds it.
struct TexturedGlb {
  Mesh mesh;                               // with texcoords when there are pages
  std::vector<EncodedTexturePage> pages;   // empty without a texture
};
// ReadGlb, plus TEXCOORD_0 (float, or normalized unsigned byte/short) and the base colour images
// of the first mesh's primitives' materials (from a buffer view or a data: URI; an external image
// file is kUnsupported, as is a texture on another TEXCOORD set): when every TRIANGLES primitive of
// the first mesh has one, they are read as one mesh, a page per run of primitives with one image.
// Otherwise the first primitive alone, with its image when it has one, without texcoords when not.
Result<TexturedGlb> DecodeTexturedGlb(std::string_view bytes, const std::string& name_for_errors);
Result<TexturedGlb> ReadTexturedGlb(const std::string& path);

// The .glb bytes of one scene with one node per element, in order. kInvalidArgument as EncodeGlb
// (naming the element when there are several), for no element, or for a name that is not UTF-8.
Result<std::string> EncodeGlbScene(const std::vector<NamedMesh>& meshes);
Status WriteGlbScene(const std::string& path, const std::vector<NamedMesh>& meshes);

// Every node of the scene that has a mesh with triangles, as one NamedMesh each, in depth-first
// order from the scene's root nodes: the scene's root nodes are those of `scene` (else scenes[0]),
// or every node without a parent when the file has neither `scene` nor `scenes`. Positions and
// normals are in the scene's frame: each node's `matrix` (column-major, affine) or translation *
// rotation * scale, composed from the root down; normals by the inverse transpose (dropped when
// that is singular), the winding reversed when the transform mirrors. All TRIANGLES primitives of
// the node's mesh concatenated (other modes skipped); NORMAL and COLOR_0 kept only when every one
// of them has it. The name is the node's `name`, else its mesh's, else "node N" (N its index).
//
// `bytes` is a .glb file or a .gltf JSON text. A buffer with a `uri` is a base64 `data:` URI or a
// file relative to `base_directory` (empty: the working directory); the uri must be a relative
// file name (percent-encoded as URIs are) without "..": kCorruptData otherwise, kUnsupported for
// another scheme (http:, ...). Errors as DecodeGlb's, naming `name_for_errors` and the JSON path,
// and kCorruptData for a node with two parents, a cycle of children, a hierarchy deeper than 64
// levels, a scene root that is some node's child, a vertex that is not finite in the scene's frame
// or a scene without any triangle ("no triangle mesh in the scene"); kResourceExhausted beyond
// 2^28 vertices in all (nodes can instance a mesh many times).
Result<std::vector<NamedMesh>> DecodeGltfScene(std::string_view bytes, const std::string& name_for_errors,
                                               const std::string& base_directory);
// .glb or .gltf; a .gltf's external buffers are read from its directory.
Result<std::vector<NamedMesh>> ReadGltfScene(const std::string& path);

}  // namespace reconar
