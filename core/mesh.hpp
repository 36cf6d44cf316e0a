#pragma once
// Mesh<Dim>: the FE mesh of the solid and the BE mesh of the interface, sharing one node array.

#include <cstdint>
#include <string>
#include <vector>

#include "core/box.hpp"

namespace febemesh {

/// Typed indices (STYLE.md §5): a VertexId does not convert to an ElemId.
struct VertexId {
  std::int32_t v = -1;
  bool valid() const { return v >= 0; }
  friend bool operator==(VertexId a, VertexId b) { return a.v == b.v; }
  friend bool operator!=(VertexId a, VertexId b) { return a.v != b.v; }
  friend bool operator<(VertexId a, VertexId b) { return a.v < b.v; }
};
struct ElemId {
  std::int32_t v = -1;
  bool valid() const { return v >= 0; }
  friend bool operator==(ElemId a, ElemId b) { return a.v == b.v; }
};

/// Element kinds with Gmsh's node ordering (and Gmsh type codes in gmsh_type()).
enum class ElemType : std::uint8_t { Line2, Tri3, Quad4, Tet4, Hex8, Prism6, Pyramid5 };

int n_nodes(ElemType t);
int dimension(ElemType t);
int gmsh_type(ElemType t);  ///< MSH element type code: 1, 2, 3, 4, 5, 6, 7
int vtk_type(ElemType t);   ///< VTK cell type: 3, 5, 9, 10, 12, 13, 14
const char* name(ElemType t);

/// A block of elements of mixed type, connectivity stored flat.
struct Elements {
  std::vector<ElemType> type;
  std::vector<std::int32_t> offset{0};  ///< size() + 1 entries
  std::vector<VertexId> node;

  std::size_t size() const { return type.size(); }
  bool empty() const { return type.empty(); }
  ElemId add(ElemType t, std::initializer_list<VertexId> nodes);
  ElemId add(ElemType t, const VertexId* nodes, int count);
  const VertexId* nodes(ElemId e) const { return node.data() + offset[e.v]; }
  int n_nodes_of(ElemId e) const { return offset[e.v + 1] - offset[e.v]; }
  void clear();
};

template <int Dim> struct Mesh {
  std::vector<Point<Dim>> points;
  Elements solid;      ///< FE elements (dimension Dim), physical group "solid"
  Elements interface;  ///< BE elements (dimension Dim-1), physical group "interface"

  /// Per solid element: tree level of the cell it came from, and 1 if from a boundary cell.
  std::vector<std::uint8_t> level;
  std::vector<std::uint8_t> from_boundary_cell;

  std::size_t n_points() const { return points.size(); }
  VertexId add_point(const Point<Dim>& p) {
    points.push_back(p);
    return VertexId{static_cast<std::int32_t>(points.size() - 1)};
  }
  const Point<Dim>& point(VertexId v) const { return points[v.v]; }
};

}  // namespace febemesh
