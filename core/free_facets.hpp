#pragma once
// Free facets of the kept (IN) cells: the facets not shared with another kept cell. The paper
// builds one boundary cell on each of them. A facet half-shared with finer kept cells is split
// into the sub-facets of the finer side, so every free facet is a facet of some (possibly
// virtual) cell whose corners are all lattice nodes.

#include <array>
#include <vector>

#include "core/cube_faces.hpp"
#include "core/orthtree.hpp"

namespace febemesh {

template <int Dim> struct FreeFacet {
  std::size_t leaf = no_leaf;  ///< the kept leaf behind the facet
  int face = -1;               ///< which facet of `cell`
  Cell<Dim> cell;              ///< the leaf, or its descendant of the finer side for a sub-facet

  /// The facet's corners as lattice points, in FaceCorners<Dim> order (outward orientation).
  std::array<LatticePoint<Dim>, Cube<Dim>::n_face_corners> corners() const;
};

/// All free facets of the kept leaves (keep[i] != 0), in leaf order then facet order.
/// Requires a 2:1 face-balanced tree.
template <int Dim> std::vector<FreeFacet<Dim>> free_facets(const Orthtree<Dim>& t, const Flags& keep);
/// The same, with the tree's leaf keys already built, on n_threads threads (the same list for
/// every count).
template <int Dim>
std::vector<FreeFacet<Dim>> free_facets(const Orthtree<Dim>& t, const LeafKeys<Dim>& keys, const Flags& keep,
                                        int n_threads = 1);

/// Turns `facets` = free_facets(t, keep before) into free_facets(t, keep) when keep differs
/// only at the leaves `changed` (any order, repeats allowed): only those leaves and their face
/// neighbours are looked at again. `keys` = LeafKeys(t).
template <int Dim>
void update_free_facets(const Orthtree<Dim>& t, const LeafKeys<Dim>& keys, const Flags& keep,
                        const std::vector<std::size_t>& changed, std::vector<FreeFacet<Dim>>& facets);

/// Does the segment [a, b] pass through the interior of a kept leaf? (The paper: the projection
/// segments must not cross other quadrants.) Cells are shrunk by `rel_tol` of their size.
template <int Dim>
bool segment_enters_kept(const Orthtree<Dim>& t, const Flags& keep, const Point<Dim>& a, const Point<Dim>& b,
                         double rel_tol = 1e-9);

/// segment_enters_kept with the allowance `rel_tol` only at the kept region's boundary: a leaf's
/// face shared with kept leaves alone is not shrunk (by 1e-9 of the size only). A segment that
/// runs within the allowance of such a face, between two kept leaves, enters the region; with
/// every face shrunk it entered neither leaf (measured: rotor.off's last folds after ten
/// repairs, a node 0.0008 under the outer wall whose projection ran 15 octants along a lattice
/// plane through the wall to the inner sheet). With graze_length > 0, a segment that runs
/// along a kept leaf (within 1e-9 of its size) for more than graze_length x its size enters too.
template <int Dim>
bool segment_enters_kept_region(const Orthtree<Dim>& t, const Flags& keep, const Point<Dim>& a, const Point<Dim>& b,
                                double rel_tol, double graze_length = 0.0);

/// The length of segment [a, b] that runs within `rel_tol` of their size of kept leaves (the
/// union of its parts in their boxes grown by that much), in units of the smallest such leaf's
/// size; 0 when it passes near none. A projection that runs along the kept region's boundary
/// (on a lattice line at its edge) has a long such run and enters no leaf.
template <int Dim>
double cells_along_kept(const Orthtree<Dim>& t, const Flags& keep, const Point<Dim>& a, const Point<Dim>& b,
                        double rel_tol);

}  // namespace febemesh
