#include "core/free_facets.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include "core/error.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {

template <int Dim>
std::array<LatticePoint<Dim>, Cube<Dim>::n_face_corners> FreeFacet<Dim>::corners() const {
  std::array<LatticePoint<Dim>, Cube<Dim>::n_face_corners> out;
  for (int k = 0; k < Cube<Dim>::n_face_corners; ++k) out[k] = corner(cell, FaceCorners<Dim>::corners[face][k]);
  return out;
}

namespace {

/// Morton keys [lo, hi) covered without a gap by kept leaves, leaf i's among them; empty when
/// not known (lo == hi).
struct KeptKeys {
  std::uint64_t lo = 0, hi = 0;
};

/// Appends the free facets of kept leaf i, in facet order. A facet inside a cell all of whose
/// keys are in `kept` has only kept leaves across it, and no neighbour search is made for it:
/// most kept leaves lie inside such runs (flange level 9: free_facets 220 M instructions).
template <int Dim>
void leaf_free_facets(const Orthtree<Dim>& t, const LeafKeys<Dim>& keys, const Flags& keep, std::size_t i,
                      std::vector<std::size_t>& nb, std::vector<FreeFacet<Dim>>& out, KeptKeys kept = {}) {
  const Cell<Dim>& c = t.leaf(i);
  const std::uint64_t key = kept.lo < kept.hi ? morton_key(c) : 0;
  for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
    if (kept.lo < kept.hi) {
      // The facet lies at x along its axis; x = odd * 2^z, so it is inside the cell of side
      // 2^(z+1) that holds leaf i (unless it is on the root's boundary).
      const std::uint32_t x = c.anchor[face_axis(f)] + (face_side(f) ? length(c) : 0);
      if (x != 0 && x != root_length<Dim>) {
        const std::uint64_t volume = std::uint64_t(1) << (Dim * (std::countr_zero(x) + 1));
        const std::uint64_t first = key & ~(volume - 1);
        if (kept.lo <= first && first + volume <= kept.hi) continue;
      }
    }
    keys.face_neighbours(i, f, nb);
    if (nb.empty()) {
      out.push_back({i, f, c});
      continue;
    }
    const bool finer = t.leaf(nb[0]).level > c.level;
    if (!finer) {
      if (!keep[nb[0]]) out.push_back({i, f, c});
      continue;
    }
    // Finer side: if none of them is kept, the whole facet is free (its sub-facet corners
    // would not be nodes); otherwise each unkept finer neighbour gives a free sub-facet.
    const bool any_kept = std::any_of(nb.begin(), nb.end(), [&](std::size_t n) { return keep[n] != 0; });
    if (!any_kept) {
      out.push_back({i, f, c});
      continue;
    }
    for (std::size_t n : nb) {
      if (keep[n]) continue;
      Cell<Dim> mirror;
      // The finer neighbour's mirror inside `c` across facet f (opposite facet of the neighbour).
      const bool ok = face_neighbour(t.leaf(n), f ^ 1, mirror);
      MESH_ASSERT(ok, "finer neighbour has no mirror inside its coarser neighbour");
      (void)ok;
      out.push_back({i, f, mirror});
    }
  }
}

}  // namespace

template <int Dim>
std::vector<FreeFacet<Dim>> free_facets(const Orthtree<Dim>& t, const LeafKeys<Dim>& keys, const Flags& keep, int n_threads) {
  // Runs of leaves on n_threads threads, each with its own list, joined in leaf order (the
  // serial list: a leaf's facets depend on the tree and the flags only). A chunk starts its
  // runs of kept keys at its first leaf: a run it cuts short only skips fewer neighbour
  // searches, which find the same facets. (Serial, this was 11 of the 19 ms the 2D buffer rule
  // took at flange 1e6, on one thread or two.)
  const std::size_t n = t.n_leaves();
  const std::size_t chunk = n_threads <= 1 ? std::max<std::size_t>(n, 1) : chunk_size(n, n_threads, std::size_t(1) << 14);
  std::vector<std::vector<FreeFacet<Dim>>> parts((n + chunk - 1) / chunk);
  for_each_chunk(n, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::vector<FreeFacet<Dim>>& out = parts[c];
    std::vector<std::size_t> nb;
    KeptKeys run;
    std::size_t run_end = 0;  // leaves [.., run_end) are in `run`
    for (std::size_t i = begin; i < end; ++i) {
      if (!keep[i]) continue;
      if (i >= run_end) {  // a new run of kept leaves without key gaps
        run.lo = morton_key(t.leaf(i));
        run.hi = run.lo + volume_units(t.leaf(i));
        for (run_end = i + 1; run_end < n && keep[run_end] && morton_key(t.leaf(run_end)) == run.hi; ++run_end)
          run.hi += volume_units(t.leaf(run_end));
      }
      leaf_free_facets(t, keys, keep, i, nb, out, run);
    }
  });
  if (parts.size() == 1) return std::move(parts[0]);
  std::size_t total = 0;
  for (const auto& part : parts) total += part.size();
  std::vector<FreeFacet<Dim>> out;
  out.reserve(total);
  for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

template <int Dim> std::vector<FreeFacet<Dim>> free_facets(const Orthtree<Dim>& t, const Flags& keep) {
  return free_facets(t, LeafKeys<Dim>(t), keep);
}

// A leaf's free facets depend on its own flag and its face neighbours' (a symmetric relation in
// a balanced tree), so only those of the changed leaves and their neighbours are rebuilt; the
// rest are copied through in leaf order.
template <int Dim>
void update_free_facets(const Orthtree<Dim>& t, const LeafKeys<Dim>& keys, const Flags& keep,
                        const std::vector<std::size_t>& changed, std::vector<FreeFacet<Dim>>& facets) {
  std::vector<std::size_t> redo(changed), nb;
  for (const std::size_t i : changed)
    for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
      keys.face_neighbours(i, f, nb);
      redo.insert(redo.end(), nb.begin(), nb.end());
    }
  std::sort(redo.begin(), redo.end());
  redo.erase(std::unique(redo.begin(), redo.end()), redo.end());
  std::vector<FreeFacet<Dim>> out;
  out.reserve(facets.size() + 4 * redo.size());
  std::size_t k = 0;  // next old facet
  for (const std::size_t i : redo) {
    for (; k < facets.size() && facets[k].leaf < i; ++k) out.push_back(facets[k]);
    while (k < facets.size() && facets[k].leaf == i) ++k;  // leaf i's old facets
    if (keep[i]) leaf_free_facets(t, keys, keep, i, nb, out);
  }
  out.insert(out.end(), facets.begin() + static_cast<std::ptrdiff_t>(k), facets.end());
  facets = std::move(out);
}

namespace {

/// The parameters [t0, t1] of the part of segment [a, b] in the open box `box`; t0 >= t1 when
/// it misses the box.
template <int Dim>
std::pair<double, double> interval_in_open_box(const Box<Dim>& box, const Point<Dim>& a, const Point<Dim>& b) {
  double t0 = 0.0, t1 = 1.0;
  for (int d = 0; d < Dim; ++d) {
    const double dir = b[d] - a[d];
    if (std::abs(dir) < 1e-300) {
      if (a[d] <= box.lo[d] || a[d] >= box.hi[d]) return {1.0, 0.0};
      continue;
    }
    double s0 = (box.lo[d] - a[d]) / dir, s1 = (box.hi[d] - a[d]) / dir;
    if (s0 > s1) std::swap(s0, s1);
    t0 = std::max(t0, s0);
    t1 = std::min(t1, s1);
    if (t0 >= t1) return {1.0, 0.0};
  }
  return {t0, t1};
}

/// The length t1 - t0 of that part as a share of the segment, or a negative number when it
/// misses the box.
template <int Dim>
double share_in_open_box(const Box<Dim>& box, const Point<Dim>& a, const Point<Dim>& b) {
  const auto [t0, t1] = interval_in_open_box(box, a, b);
  return t0 < t1 ? t1 - t0 : -1.0;
}

/// The bounding box of segment [a, b]: the leaves it may meet are in it.
template <int Dim> Box<Dim> segment_box(const Point<Dim>& a, const Point<Dim>& b) {
  Box<Dim> sb = Box<Dim>::empty();
  sb.expand(a);
  sb.expand(b);
  return sb;
}

/// Does the segment meet the open box `box`?
template <int Dim>
bool segment_meets_open_box(const Box<Dim>& box, const Point<Dim>& a, const Point<Dim>& b) {
  return share_in_open_box(box, a, b) >= 0.0;
}

}  // namespace

template <int Dim>
bool segment_enters_kept(const Orthtree<Dim>& t, const Flags& keep, const Point<Dim>& a, const Point<Dim>& b,
                         double rel_tol) {
  for (std::size_t i : leaves_in_box(t, segment_box<Dim>(a, b))) {
    if (!keep[i]) continue;
    Box<Dim> box = geometry(t, t.leaf(i));
    const double shrink = rel_tol * (box.hi[0] - box.lo[0]);
    box.lo.array() += shrink;
    box.hi.array() -= shrink;
    if (segment_meets_open_box(box, a, b)) return true;
  }
  return false;
}

template <int Dim>
bool segment_enters_kept_region(const Orthtree<Dim>& t, const Flags& keep, const Point<Dim>& a, const Point<Dim>& b,
                                double rel_tol, double graze_length) {
  std::vector<std::size_t> nb;
  for (std::size_t i : leaves_in_box(t, segment_box<Dim>(a, b))) {
    if (!keep[i]) continue;
    const Box<Dim> cell = geometry(t, t.leaf(i));
    const double size = cell.hi[0] - cell.lo[0];
    Box<Dim> box = cell;
    box.lo.array() += 1e-9 * size;
    box.hi.array() -= 1e-9 * size;
    const double share = share_in_open_box(box, a, b);
    if (share < 0.0) continue;
    if (graze_length > 0 && share * (b - a).norm() > graze_length * size) return true;
    // It grazes the leaf at least: shrink the faces on the region's boundary by the allowance.
    for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
      face_neighbours(t, i, f, nb);
      const bool inner = !nb.empty() && std::all_of(nb.begin(), nb.end(), [&](std::size_t j) { return keep[j] != 0; });
      if (inner) continue;
      if (f % 2) box.hi[f / 2] = cell.hi[f / 2] - rel_tol * size;
      else box.lo[f / 2] = cell.lo[f / 2] + rel_tol * size;
    }
    if (segment_meets_open_box(box, a, b)) return true;
  }
  return false;
}

template <int Dim>
double cells_along_kept(const Orthtree<Dim>& t, const Flags& keep, const Point<Dim>& a, const Point<Dim>& b,
                        double rel_tol) {
  std::vector<std::pair<double, double>> parts;
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i : leaves_in_box(t, segment_box<Dim>(a, b))) {
    if (!keep[i]) continue;
    Box<Dim> box = geometry(t, t.leaf(i));
    const double size = box.hi[0] - box.lo[0];
    box.lo.array() -= rel_tol * size;
    box.hi.array() += rel_tol * size;
    const auto part = interval_in_open_box(box, a, b);
    if (part.first >= part.second) continue;
    parts.push_back(part);
    smallest = std::min(smallest, size);
  }
  if (parts.empty()) return 0.0;
  std::sort(parts.begin(), parts.end());
  double covered = 0.0, lo = parts[0].first, hi = parts[0].second;
  for (const auto& [t0, t1] : parts) {
    if (t0 > hi) covered += hi - lo, lo = t0, hi = t1;
    else hi = std::max(hi, t1);
  }
  covered += hi - lo;
  return covered * (b - a).norm() / smallest;
}

template struct FreeFacet<2>;
template struct FreeFacet<3>;
template std::vector<FreeFacet<2>> free_facets<2>(const Orthtree<2>&, const Flags&);
template std::vector<FreeFacet<3>> free_facets<3>(const Orthtree<3>&, const Flags&);
template std::vector<FreeFacet<2>> free_facets<2>(const Orthtree<2>&, const LeafKeys<2>&, const Flags&, int);
template std::vector<FreeFacet<3>> free_facets<3>(const Orthtree<3>&, const LeafKeys<3>&, const Flags&, int);
template void update_free_facets<2>(const Orthtree<2>&, const LeafKeys<2>&, const Flags&, const std::vector<std::size_t>&,
                                    std::vector<FreeFacet<2>>&);
template void update_free_facets<3>(const Orthtree<3>&, const LeafKeys<3>&, const Flags&, const std::vector<std::size_t>&,
                                    std::vector<FreeFacet<3>>&);
template bool segment_enters_kept<2>(const Orthtree<2>&, const Flags&, const Point<2>&, const Point<2>&, double);
template bool segment_enters_kept<3>(const Orthtree<3>&, const Flags&, const Point<3>&, const Point<3>&, double);
template double cells_along_kept<2>(const Orthtree<2>&, const Flags&, const Point<2>&, const Point<2>&, double);
template double cells_along_kept<3>(const Orthtree<3>&, const Flags&, const Point<3>&, const Point<3>&, double);
template bool segment_enters_kept_region<2>(const Orthtree<2>&, const Flags&, const Point<2>&, const Point<2>&,
                                             double, double);
template bool segment_enters_kept_region<3>(const Orthtree<3>&, const Flags&, const Point<3>&, const Point<3>&,
                                             double, double);

}  // namespace febemesh
