#pragma once
// Hand-built meshes for the core mesh tests, in both dimensions.

#include <array>
#include <numeric>
#include <vector>

#include "core/cube.hpp"
#include "core/mesh.hpp"
#include "core/mesh_topology.hpp"
#include "core/quality.hpp"

namespace febemesh::test {

/// Corner c of a cube (bit d = upper along axis d) in Gmsh's quad / hex node order.
template <int Dim> constexpr std::array<int, Cube<Dim>::n_corners> gmsh_cube_order() {
  if constexpr (Dim == 2) {
    return {0, 1, 3, 2};
  } else {
    return {0, 1, 3, 2, 4, 5, 7, 6};
  }
}

/// Adds the cube with corner ids `corner` (bit numbering) as one quad/hex or as Kuhn simplices
/// (one per axis permutation: conforming between neighbouring cubes), positively oriented.
template <int Dim> void add_cube(Mesh<Dim>& mesh, const std::array<VertexId, Cube<Dim>::n_corners>& corner, bool simplices) {
  if (!simplices) {
    std::array<VertexId, Cube<Dim>::n_corners> nodes;
    const auto order = gmsh_cube_order<Dim>();
    for (int i = 0; i < Cube<Dim>::n_corners; ++i) nodes[i] = corner[order[i]];
    mesh.solid.add(Dim == 2 ? ElemType::Quad4 : ElemType::Hex8, nodes.data(), Cube<Dim>::n_corners);
    return;
  }
  std::array<int, Dim> axes;
  std::iota(axes.begin(), axes.end(), 0);
  do {
    std::array<VertexId, Dim + 1> nodes;
    int c = 0;
    nodes[0] = corner[0];
    for (int k = 0; k < Dim; ++k) nodes[k + 1] = corner[c |= 1 << axes[k]];
    const ElemType t = Dim == 2 ? ElemType::Tri3 : ElemType::Tet4;
    ElemPoints<Dim> ep;
    ep.n = Dim + 1;
    for (int k = 0; k <= Dim; ++k) ep.p[k] = mesh.points[nodes[k].v];
    if (signed_measure<Dim>(t, ep.span()) < 0) std::swap(nodes[1], nodes[2]);
    mesh.solid.add(t, nodes.data(), Dim + 1);
  } while (std::next_permutation(axes.begin(), axes.end()));
}

/// Sets the interface to the boundary facets of the solid (what a pipeline must produce).
template <int Dim> void set_interface_to_boundary(Mesh<Dim>& mesh) {
  mesh.interface.clear();
  for (const BoundaryFacet& b : boundary_facets(mesh.solid)) mesh.interface.add(b.facet.type, b.facet.node.data(), b.facet.n);
}

/// n^Dim cubes of side h from the origin, as quads/hexes or simplices, with its interface.
template <int Dim> Mesh<Dim> grid_mesh(int n, bool simplices, double h = 1.0) {
  Mesh<Dim> mesh;
  const int m = n + 1;
  int total = 1;
  for (int d = 0; d < Dim; ++d) total *= m;
  for (int i = 0; i < total; ++i) {
    Point<Dim> p;
    for (int d = 0, r = i; d < Dim; ++d, r /= m) p[d] = h * (r % m);
    mesh.add_point(p);
  }
  int cells = 1;
  for (int d = 0; d < Dim; ++d) cells *= n;
  for (int c = 0; c < cells; ++c) {
    std::array<int, Dim> ijk;
    for (int d = 0, r = c; d < Dim; ++d, r /= n) ijk[d] = r % n;
    std::array<VertexId, Cube<Dim>::n_corners> corner;
    for (int k = 0; k < Cube<Dim>::n_corners; ++k) {
      int id = 0;
      for (int d = Dim - 1; d >= 0; --d) id = id * m + ijk[d] + (corner_is_upper(k, d) ? 1 : 0);
      corner[k] = VertexId{id};
    }
    add_cube<Dim>(mesh, corner, simplices);
  }
  mesh.level.assign(mesh.solid.size(), 1);
  mesh.from_boundary_cell.assign(mesh.solid.size(), 0);
  set_interface_to_boundary(mesh);
  return mesh;
}

/// The classic 2:1 configuration: 2^(Dim-1) unit cubes on [0,1] x [0,2]^(Dim-1) beside one cube
/// of side 2 on [1,3] x [0,2]^(Dim-1). The big cube does not see the small cubes' nodes on
/// x = 1: 3^(Dim-1) - 2^(Dim-1) hanging nodes. The interface is the boundary facets.
template <int Dim> Mesh<Dim> hanging_mesh(bool simplices) {
  Mesh<Dim> mesh;
  // Lattice 4 x 3^(Dim-1) of integer points, id = x + 4 (y + 3 z).
  const int nz = Dim == 3 ? 3 : 1;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) {
        Point<Dim> p;
        p[0] = x;
        p[1] = y;
        if constexpr (Dim == 3) p[2] = z;
        mesh.add_point(p);
      }
  auto id = [](int x, int y, int z) { return VertexId{x + 4 * (y + 3 * z)}; };
  auto cube = [&](int x, int y, int z, int size) {
    std::array<VertexId, Cube<Dim>::n_corners> corner;
    for (int k = 0; k < Cube<Dim>::n_corners; ++k)
      corner[k] = id(x + size * ((k >> 0) & 1), y + size * ((k >> 1) & 1), Dim == 3 ? z + size * ((k >> 2) & 1) : 0);
    add_cube<Dim>(mesh, corner, simplices);
  };
  for (int z = 0; z < (Dim == 3 ? 2 : 1); ++z)
    for (int y = 0; y < 2; ++y) cube(0, y, z, 1);
  cube(1, 0, 0, 2);
  // Drop the lattice points x = 2 (and x = 3 off the big cube's corners) by not using them:
  // rebuild with only the used points so that no node is unused.
  std::vector<std::int32_t> remap(mesh.points.size(), -1);
  Mesh<Dim> out;
  for (VertexId& v : mesh.solid.node) {
    if (remap[v.v] < 0) remap[v.v] = out.add_point(mesh.points[v.v]).v;
    v = VertexId{remap[v.v]};
  }
  out.solid = mesh.solid;
  set_interface_to_boundary(out);
  return out;
}

}  // namespace febemesh::test
