#pragma once
// IFC (the STEP text form buildings are designed in) read into design elements through IFC++:
// one element per product with geometry, named by its GlobalId and then its Name, its geometry
// tessellated by IFC++ (Carve) in the model's length unit converted to metres and placed by the
// product's placement chain. For `reconar-ifc2glb`, which writes them as a GLB that `reconar
// compare` reads; the runtime does not link IFC++ (docs/compare.md says why).
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

// kNotFound for a missing file; kCorruptData naming the file when it holds no IFC entity or no
// product with triangles.
Result<std::vector<NamedMesh>> ReadIfcElements(const std::string& path);

}  // namespace reconar
