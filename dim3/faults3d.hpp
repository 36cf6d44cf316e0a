#pragma once
// What a try of the 3D pipeline (mesh3d_try) finds wrong with its mesh and where its repairs act
// (internal to dim3): a problem at each inverted tetrahedron and folded interface triangle, the
// places where the surface mesh touches itself, the faults behind them (the cells they came
// from and the lattice nodes behind), and their description in progress and error messages.

#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "core/orthtree.hpp"
#include "dim3/boundary_octants.hpp"
#include "dim3/templates3d.hpp"

namespace febemesh::dim3 {

/// Where the tetrahedra with a node on the surface (an interface node) meet other than through
/// shared nodes, edges and faces: a node on another's edge or face, two nodes at one place, a
/// face used three times (the validator's checks on that part of the mesh). One problem per
/// place, at the node.
std::vector<Problem3> surface_contacts(const Mesh<3>& m, int n_threads);

/// The first three problems and where they are, then how many more.
std::string describe(const std::vector<Problem3>& problems);

/// Appends a problem at each inverted element and folded interface triangle, their messages
/// followed by `when`.
void add_problems(const Mesh<3>& m, const std::vector<std::size_t>& bad, const std::vector<std::size_t>& folded,
                  const std::string& when, std::vector<Problem3>& out);

/// Where the faults behind the inverted tets `bad` lie (Options3d::repair_at_cells): the centre
/// of the cell each came from (an interior octant, or a boundary octant's face) and `behind`,
/// the lattice nodes behind them and the folded triangles (nodes_behind).
std::vector<P3> fault_places(const Orthtree<3>& t, const OctantComplex& oc, const TetMesh& fe,
                             const std::vector<std::size_t>& bad, const std::vector<P3>& behind);

/// The lattice nodes behind the inverted tets `bad` and folded interface triangles `folded`:
/// their own lattice nodes and the face nodes projecting onto their surface nodes, as positions.
std::vector<P3> nodes_behind(const Orthtree<3>& t, const OctantComplex& oc, const Mesh<3>& m,
                             const std::vector<std::size_t>& bad, const std::vector<std::size_t>& folded);

}  // namespace febemesh::dim3
