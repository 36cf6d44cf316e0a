#pragma once
// Facets and edges of mesh elements with Gmsh's local numbering, oriented facet keys, and the
// boundary of a solid mesh (facets used once). Validation, writers and smoothing build on these.

#include <array>
#include <compare>
#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh.hpp"

namespace febemesh {

/// A facet (edge of a 2D element, face of a 3D element) with its nodes in element order.
/// Orientation: in 2D the element lies to the left of the edge (counter-clockwise traversal);
/// in 3D the right-hand normal of the face points out of the element. Gmsh's tables.
struct Facet {
  ElemType type = ElemType::Line2;
  int n = 0;
  std::array<VertexId, 4> node{};
};

/// Orientation-free identity of a facet: its node ids sorted, unused slots -1.
struct FacetKey {
  std::array<std::int32_t, 4> v{-1, -1, -1, -1};
  friend auto operator<=>(const FacetKey&, const FacetKey&) = default;
};

int n_facets(ElemType t);
int n_edges(ElemType t);
/// Local node indices of facet f, oriented outward (see Facet).
std::span<const int> facet_local_nodes(ElemType t, int f);
ElemType facet_type(ElemType t, int f);
/// Local node indices of edge e (Gmsh's edge tables).
std::array<int, 2> edge_local_nodes(ElemType t, int e);

Facet facet_of(const Elements& els, ElemId e, int f);
/// An element of dimension Dim-1 seen as a facet (interface elements).
Facet as_facet(const Elements& els, ElemId e);

FacetKey key_of(const Facet& f);
/// +1 or -1; two uses of the same facet (equal keys) are opposite iff their signs differ.
int orientation_of(const Facet& f);

/// One use of a facet by a solid element.
struct FacetUse {
  FacetKey key;
  ElemId elem;
  std::int8_t local = 0;        ///< facet index within the element
  std::int8_t orientation = 0;  ///< orientation_of(facet)
};

/// Every facet use of `els`, sorted by (key, element, local facet): equal keys are adjacent.
std::vector<FacetUse> facet_uses(const Elements& els);
/// Slow twin of facet_uses (one comparison sort): the same vector.
std::vector<FacetUse> facet_uses_ref(const Elements& els);

/// A facet of the solid used by exactly one element, oriented outward.
struct BoundaryFacet {
  Facet facet;
  ElemId elem;
  int local = 0;
};

/// The boundary of the solid: facets used exactly once, in (element, local facet) order.
/// Facets used twice or more are interior (or non-conforming: validate() reports those).
std::vector<BoundaryFacet> boundary_facets(const Elements& solid);

/// Distinct edges of `els` as sorted node pairs, sorted. The edge uses are bucketed in runs of
/// nodes of at most `run_uses` uses (0: a quarter of them, at least 2^20), one pass over the
/// elements a run, on n_threads threads (each its own range of elements); the same result for
/// every run length and thread count.
std::vector<std::array<VertexId, 2>> unique_edges(const Elements& els, std::size_t run_uses = 0, int n_threads = 1);

/// Appends to `out` the distinct edge neighbours of node v in the polygons `elems` (the nodes
/// before and after v in each), ascending. `listed` has a byte per node, all 0; it marks the
/// ones seen and is all 0 again on return. (The 2D smoothing and angle optimiser, per node: a
/// mark and an insertion sort instead of std::sort and std::unique, 428M -> 388M instructions
/// in optimise_angles at flange level 9.)
void append_polygon_neighbours(const Elements& els, std::int32_t v, std::span<const std::int32_t> elems,
                               std::vector<std::int32_t>& out, std::vector<std::uint8_t>& listed);
/// Slow twin of unique_edges (one comparison sort): the same vector.
std::vector<std::array<VertexId, 2>> unique_edges_ref(const Elements& els);

}  // namespace febemesh
