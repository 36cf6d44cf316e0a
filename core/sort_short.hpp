#pragma once
// Sorting a node's neighbour list: usually a few dozen ids, where an insertion sort beats
// std::sort's set-up; longer lists (hubs: a fan centre, a pole) go to std::sort. The smoothing's
// and the tet optimiser's node lists are sorted by this, once per list and list build; the
// validator's facet buckets by the stable variant.

#include <algorithm>
#include <iterator>

namespace febemesh {

template <class It> void sort_short(It lo, It hi) {
  if (hi - lo > 32) {
    std::sort(lo, hi);
    return;
  }
  for (It i = lo + (lo != hi); i < hi; ++i)
    for (It j = i; j != lo && *j < *std::prev(j); --j) std::iter_swap(j, std::prev(j));
}

/// The same for records whose equal keys must keep their order (stable), by `less`.
template <class It, class Less> void stable_sort_short(It lo, It hi, Less less) {
  if (hi - lo > 32) {
    std::stable_sort(lo, hi, less);
    return;
  }
  for (It i = lo + (lo != hi); i < hi; ++i)
    for (It j = i; j != lo && less(*j, *std::prev(j)); --j) std::iter_swap(j, std::prev(j));
}

}  // namespace febemesh
