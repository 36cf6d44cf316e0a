// ElemType tables and the flat element block of core/mesh.hpp.

#include "core/mesh.hpp"

#include "core/error.hpp"

namespace febemesh {

namespace {
struct ElemInfo {
  int n_nodes;
  int dimension;
  int gmsh;
  int vtk;
  const char* name;
};
// Indexed by ElemType; Gmsh and VTK codes from their file-format documentation.
constexpr ElemInfo elem_info[] = {
    {2, 1, 1, 3, "line"},     {3, 2, 2, 5, "triangle"}, {4, 2, 3, 9, "quadrangle"},
    {4, 3, 4, 10, "tetrahedron"}, {8, 3, 5, 12, "hexahedron"}, {6, 3, 6, 13, "prism"},
    {5, 3, 7, 14, "pyramid"},
};
const ElemInfo& info(ElemType t) {
  const auto i = static_cast<std::size_t>(t);
  MESH_ASSERT(i < std::size(elem_info), "bad ElemType " << i);
  return elem_info[i];
}
}  // namespace

int n_nodes(ElemType t) { return info(t).n_nodes; }
int dimension(ElemType t) { return info(t).dimension; }
int gmsh_type(ElemType t) { return info(t).gmsh; }
int vtk_type(ElemType t) { return info(t).vtk; }
const char* name(ElemType t) { return info(t).name; }

ElemId Elements::add(ElemType t, std::initializer_list<VertexId> nodes) {
  return add(t, nodes.begin(), static_cast<int>(nodes.size()));
}

ElemId Elements::add(ElemType t, const VertexId* nodes, int count) {
  MESH_ASSERT(count == n_nodes(t), name(t) << " needs " << n_nodes(t) << " nodes, got " << count);
  type.push_back(t);
  node.insert(node.end(), nodes, nodes + count);
  offset.push_back(static_cast<std::int32_t>(node.size()));
  return ElemId{static_cast<std::int32_t>(type.size() - 1)};
}

void Elements::clear() {
  type.clear();
  offset.assign(1, 0);
  node.clear();
}

}  // namespace febemesh
