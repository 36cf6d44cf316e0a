#pragma once
// Helpers of the pipelines' repair loop (2D and 3D alike): when the boundary-cell construction
// finds the tree too coarse somewhere, the leaves around those places are refined and the
// construction is redone.

#include <vector>

#include "core/orthtree.hpp"

namespace febemesh {

/// Flags of the leaves classified IN.
Flags interior_flags(const std::vector<Side>& sides);

/// Flags every leaf (below max_level) whose box meets the box of half-side `cells` x the size of
/// the leaf containing each place. Returns false when no leaf can be refined any more.
template <int Dim>
bool mark_around(const Orthtree<Dim>& t, const std::vector<Point<Dim>>& places, double cells, int max_level,
                 Flags& flags);

}  // namespace febemesh
