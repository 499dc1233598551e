#include "core/compare/ifc_import.h"

#include <codecvt>
#include <locale>

#include <ifcpp/IFC4/include/IfcGloballyUniqueId.h>
#include <ifcpp/IFC4/include/IfcLabel.h>
#include <ifcpp/IFC4/include/IfcRoot.h>
#include <ifcpp/geometry/Carve/GeometryConverter.h>
#include <ifcpp/model/BuildingModel.h>
#include <ifcpp/reader/ReaderSTEP.h>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

std::string Utf8(const std::wstring& text) {
  std::string out;
  for (const wchar_t c : text) out.push_back(c < 0x80 ? static_cast<char>(c) : '?');
  return out;
}

}  // namespace

Result<std::vector<NamedMesh>> ReadIfcElements(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  // From the text: IFC++'s loadModelFromFile reads nothing from a path on Linux (no message).
  shared_ptr<BuildingModel> model(new BuildingModel());
  shared_ptr<ReaderSTEP> reader(new ReaderSTEP());
  reader->loadModelFromString(text, model);
  if (model->getMapIfcEntities().empty()) return FileError(StatusCode::kCorruptData, path, "no IFC entity read");
  shared_ptr<GeometryConverter> converter(new GeometryConverter(model));
  converter->convertGeometry();
  std::vector<NamedMesh> elements;
  for (const auto& [entity_id, product] : converter->getShapeInputData()) {
    if (product->m_ifc_object_definition.expired()) continue;
    const shared_ptr<IfcRoot> root = dynamic_pointer_cast<IfcRoot>(shared_ptr<IfcObjectDefinition>(product->m_ifc_object_definition));
    NamedMesh element;
    element.name = root && root->m_GlobalId ? Utf8(root->m_GlobalId->m_value) : "#" + std::to_string(entity_id);
    if (root && root->m_Name && !root->m_Name->m_value.empty()) element.name += " " + Utf8(root->m_Name->m_value);
    const carve::math::Matrix world_from_product = product->getTransform();
    for (const shared_ptr<RepresentationData>& representation : product->m_vec_representations) {
      for (const shared_ptr<ItemShapeData>& item : representation->m_vec_item_data) {
        for (const shared_ptr<carve::mesh::MeshSet<3>>& mesh_set : item->m_meshsets) {
          for (carve::mesh::Mesh<3>* mesh : mesh_set->meshes) {
            for (carve::mesh::Face<3>* face : mesh->faces) {
              std::vector<uint32_t> corners;
              carve::mesh::Edge<3>* edge = face->edge;
              for (size_t k = 0; k < face->nVertices(); ++k, edge = edge->next) {
                const carve::geom::vector<3> p = world_from_product * edge->vert->v;
                corners.push_back(static_cast<uint32_t>(element.mesh.positions.size()));
                element.mesh.positions.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y),
                                                    static_cast<float>(p.z));
              }
              for (size_t k = 1; k + 1 < corners.size(); ++k) {
                element.mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
              }
            }
          }
        }
      }
    }
    if (!element.mesh.triangles.empty()) elements.push_back(std::move(element));
  }
  if (elements.empty()) return FileError(StatusCode::kCorruptData, path, "no IFC product with geometry");
  return elements;
}

}  // namespace reconar
