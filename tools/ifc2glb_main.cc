// `reconar-ifc2glb IN.ifc OUT.glb`: an IFC design converted to GLB for `reconar compare`, one node
// per product with geometry, named by its GlobalId and its Name (core/compare/ifc_import.h).
#include <cstdio>
#include <string>

#include "core/compare/ifc_import.h"
#include "core/mesh/glb_io.h"

int main(int argc, char** argv) {
  if (argc != 3 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr,
                 "usage: reconar-ifc2glb IN.ifc OUT.glb\n"
                 "Converts an IFC design (IFC2x3 or IFC4, STEP text) into a glTF binary that `reconar compare`\n"
                 "reads: one node per product with geometry, named 'GLOBALID NAME', in metres, in the IFC's\n"
                 "world frame (tessellated by IFC++).\n");
    return 2;
  }
  const reconar::Result<std::vector<reconar::NamedMesh>> elements = reconar::ReadIfcElements(argv[1]);
  if (!elements.ok()) {
    std::fprintf(stderr, "reconar-ifc2glb: error: %s\n", elements.status().ToString().c_str());
    return 1;
  }
  const reconar::Status written = reconar::WriteGlbScene(argv[2], *elements);
  if (!written.ok()) {
    std::fprintf(stderr, "reconar-ifc2glb: error: %s\n", written.ToString().c_str());
    return 1;
  }
  size_t triangles = 0;
  for (const reconar::NamedMesh& element : *elements) triangles += element.mesh.triangles.size();
  std::printf("%s: %zu elements, %zu triangles\n", argv[2], elements->size(), triangles);
  return 0;
}
