#pragma once
// Step 6 of the paper: the FE mesh from templates, and step 5: the BE mesh (the boundary
// quadrants' sides on the curve), sharing nodes.
//
// Interior quadrant templates (tri): no hanging node: two triangles across the shorter
// diagonal; one to four hanging nodes (the other five configurations of a 2:1 balanced
// quadrant): a fan around a centre node, whose triangles all have angles >= 45 deg on the
// lattice. Boundary quadrant: two triangles across the diagonal with the better smallest angle,
// or one triangle when P1 == P2.
// quad: the mixed mesh split once more (triangle -> 3 quads, quad -> 4 quads through edge
// midpoints and centroids; midpoints of curve edges are placed on the curve), so every element
// is a quadrilateral and the mesh stays conforming.
// mixed: quads for quadrants without hanging nodes and for boundary quadrants, triangle fans in
// the transitions.

#include <cstdint>
#include <functional>
#include <string>

#include "core/mesh.hpp"
#include "dim2/curve_locations.hpp"
#include "dim2/quadrant_complex.hpp"

namespace febemesh::dim2 {

enum class ElementKind : std::uint8_t { Tri = 0, Quad = 1, Mixed = 2 };
const char* name(ElementKind k);
/// "tri" | "quad" | "mixed"; throws std::invalid_argument otherwise.
ElementKind element_kind_from(const std::string& s);

/// The point of the curve halfway (in parameter) between two boundary nodes on the same loop,
/// with its location. Used to split curve edges in quad mode.
using CurveMidpoint = std::function<std::pair<Point<2>, BoundaryLocation>(const BoundaryLocation&,
                                                                           const BoundaryLocation&)>;

struct FeBeMesh {
  Mesh<2> mesh;
  /// The interface nodes' locations on the curve (the other nodes have none: patch < 0).
  CurveLocations where;
};

/// Triangles / quads / mixed elements of every quadrant, and the BE edges, sharing nodes.
/// Quad = the mixed mesh split once (split_to_quads). The interior quadrants' templates run on
/// n_threads threads; the mesh is the same for every count.
FeBeMesh fe_be_mesh(const QuadrantComplex& qc, ElementKind kind, const CurveMidpoint& midpoint, int n_threads = 1);

/// All quadrilaterals: every element split once through its centroid and edge midpoints
/// (triangle -> 3 quads, quad -> 4), conforming because neighbours share the edge midpoints;
/// the midpoints of BE edges lie on the curve (`midpoint`), each BE edge becomes two.
FeBeMesh split_to_quads(const FeBeMesh& in, const CurveMidpoint& midpoint);

}  // namespace febemesh::dim2
