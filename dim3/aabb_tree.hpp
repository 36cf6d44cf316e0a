#pragma once
// A bounding-volume hierarchy over the triangles of a surface: the spatial index behind every
// boundary query (closest point, local minima of the distance, segment crossing, box overlap,
// ray parity). A flat array of nodes, children adjacent, leaves of at most 4 triangles, split
// at the median centroid along the longest axis (deterministic: ties broken by index).

#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/box.hpp"
#include "dim3/surface.hpp"
#include "dim3/triangle_predicates.hpp"

namespace febemesh::dim3 {

/// Sixteen fixed unit directions for ray parity (pseudo-random from a fixed seed, so that rays
/// are unlikely to run along the axis-aligned structure of CAD parts, yet every run is the same).
const std::array<P3, 16>& ray_directions();

class AabbTree {
 public:
  struct Closest {
    std::int32_t triangle = -1;
    TrianglePoint where;
    double distance2 = std::numeric_limits<double>::infinity();
  };

  AabbTree() = default;
  AabbTree(const std::vector<P3>& vertices, const std::vector<Triangle>& triangles);

  int n_triangles() const { return static_cast<int>(ids_.size()); }
  int n_nodes() const { return static_cast<int>(nodes_.size()); }
  Box<3> bounds() const { return nodes_.empty() ? Box<3>::empty() : nodes_[0].box; }
  /// Corner coordinates of triangle t (by its surface index).
  const std::array<P3, 3>& points(std::int32_t t) const { return points_[slot_[t]]; }

  /// Closest point of the surface to p; ties go to the first triangle met (deterministic).
  Closest closest(const P3& p) const;
  /// closest(p), the same answer, found faster when triangle `hint` (-1: none) is near it: its
  /// distance bounds the search from the start. The bound carries a slack far above the
  /// distances' rounding (slack2_), so that no subtree holding the answer is cut.
  Closest closest(const P3& p, std::int32_t hint) const;
  /// Closest point over triangles with skip(t) false.
  template <class Skip> Closest closest_if(const P3& p, Skip&& skip) const;

  /// Calls f(t) for every triangle whose box is within `radius` of p (a superset of the
  /// triangles within `radius`), in tree order.
  template <class F> void for_each_near(const P3& p, double radius, F&& f) const;
  /// Calls f(t) for every triangle whose box meets `box`.
  template <class F> void for_each_in_box(const Box<3>& box, F&& f) const;
  /// Calls f(t) for every triangle whose box meets the segment [a, b].
  template <class F> void for_each_on_segment(const P3& a, const P3& b, F&& f) const;

  /// for_each_on_segment, less the triangles whose own box the segment misses: for callers
  /// whose test is exact (segment_triangle), which finds no contact with those either (the
  /// tree's nodes are pruned by the same padded slab test). A leaf's four triangles each cost
  /// segment_triangle's two or five orient3d otherwise (is_inside: 428 M instructions at
  /// sphere966 L5).
  template <class F> void for_each_boxed_on_segment(const P3& a, const P3& b, F&& f) const;

  /// Does any triangle meet the closed box (exact separating-axis test on candidates)?
  bool overlaps(const Box<3>& box) const;

  /// Squared distance from p to a box (0 inside).
  static double box_distance2(const Box<3>& b, const P3& p);
  /// Does segment [a, b] meet the closed box (slab test)?
  static bool segment_meets_box(const P3& a, const P3& b, const Box<3>& box);

 private:
  struct Node {
    Box<3> box;
    std::int32_t first = 0;  ///< leaf: first slot; inner: index of the left child (right = +1)
    std::int32_t count = 0;  ///< leaf: number of triangles; inner: 0
  };
  void build(std::int32_t node, std::int32_t begin, std::int32_t end, const std::vector<P3>& centroids);
  /// closest_if visiting only boxes within `bound` (squared) of p, and only triangles whose
  /// box is: the answer when it lies within the bound. The triangle in slot `known_slot` (-1:
  /// none) has its closest point `known` already (the same numbers: not computed again).
  template <class Skip>
  Closest closest_within(const P3& p, double bound, Skip&& skip, std::int32_t known_slot = -1,
                         const TrianglePoint* known = nullptr) const;

  /// The tree walk of the for_each_* queries: f(t) for the triangles of every leaf whose
  /// node boxes all meet (meets(box)), and with `triangle_boxes` whose own box meets too.
  template <class Meets, class F> void walk(const Meets& meets, bool triangle_boxes, F&& f) const;

  std::vector<Node> nodes_;
  std::vector<std::int32_t> ids_;             ///< triangle index in slot order
  std::vector<std::int32_t> slot_;            ///< slot of each triangle
  std::vector<std::array<P3, 3>> points_;     ///< corners in slot order (cache-friendly leaves)
  std::vector<Box<3>> boxes_;                 ///< box of each triangle, in slot order
  /// The boxes of an inner node's two children lane by lane (0 left, 1 right), at
  /// pair_boxes_[(left - 1) / 2] (left children are nodes 1, 3, 5, ...): closest_within takes
  /// both distances in one pass of two-lane operations instead of two box_distance2 calls.
  struct PairBoxes {
    alignas(16) double lo[3][2];
    alignas(16) double hi[3][2];
  };
  std::vector<PairBoxes> pair_boxes_;
  /// box_distance2 of the two children (left child `left`), the same operations lane by lane.
  void children_distance2(std::int32_t left, const P3& p, double& dl, double& dr) const;
  /// Squared distances this far apart may be rounding: (1e-8 (max |coordinate| + diagonal))^2.
  double slack2_ = 0.0;
};

// ---- templates ------------------------------------------------------------------------------

inline void AabbTree::children_distance2(std::int32_t left, const P3& p, double& dl, double& dr) const {
  // box_distance2's max(max(lo - p, p - hi), 0) and ((0 + e0^2) + e1^2) + e2^2 in both lanes:
  // SSE2 on x86-64 (no FMA to fuse the sum), so dl and dr equal box_distance2's bit for bit.
  using V = double __attribute__((vector_size(16)));
  const PairBoxes& b = pair_boxes_[static_cast<std::size_t>(left - 1) / 2];
  const V zero = {0.0, 0.0};
  V d2 = zero;
  for (int d = 0; d < 3; ++d) {
    V lo, hi;
    __builtin_memcpy(&lo, b.lo[d], sizeof lo);
    __builtin_memcpy(&hi, b.hi[d], sizeof hi);
    const V pd = {p[d], p[d]};
    const V below = lo - pd, above = pd - hi;
    const V m = below < above ? above : below;  // std::max(below, above)
    const V e = m < zero ? zero : m;            // std::max(m, 0.0)
    d2 += e * e;
  }
  dl = d2[0], dr = d2[1];
}

template <class Skip> AabbTree::Closest AabbTree::closest_if(const P3& p, Skip&& skip) const {
  return closest_within(p, std::numeric_limits<double>::infinity(), std::forward<Skip>(skip));
}

template <class Skip>
AabbTree::Closest AabbTree::closest_within(const P3& p, double bound, Skip&& skip, std::int32_t known_slot,
                                           const TrianglePoint* known) const {
  Closest best;
  if (nodes_.empty()) return best;
  // Depth first, the nearer child first. A node is cut when its box is no nearer than the
  // best so far or beyond the bound; the farther child is cut when it is pushed already if it
  // is then (the best only shrinks), and the nearer one is visited at once, not pushed.
  // The stack is left uninitialised (std::pair entries would zero 2 KB on every query).
  struct Entry {
    std::int32_t node;
    double d2;
  };
  Entry stack[128];
  int top = 0;
  std::int32_t n = 0;
  double d2 = box_distance2(nodes_[0].box, p);
  for (;;) {
    if (d2 < best.distance2 && d2 <= bound) {
      const Node& node = nodes_[n];
      if (node.count == 0) {
        double dl, dr;
        children_distance2(node.first, p, dl, dr);
        const bool left_first = dl <= dr;
        const double d_far = left_first ? dr : dl;
        if (d_far < best.distance2 && d_far <= bound) stack[top++] = {left_first ? node.first + 1 : node.first, d_far};
        n = left_first ? node.first : node.first + 1;
        d2 = left_first ? dl : dr;
        continue;
      }
      // A triangle whose box is farther than the best so far (beyond the rounding) cannot
      // become the best: its distance is not computed.
      const double reach = std::min(best.distance2, bound) * (1.0 + 1e-9) + slack2_;
      for (std::int32_t s = node.first; s < node.first + node.count; ++s) {
        if (skip(ids_[s])) continue;
        if (box_distance2(boxes_[s], p) > reach) continue;
        const auto& q = points_[s];
        const TrianglePoint tp = s == known_slot ? *known : closest_on_triangle(p, q[0], q[1], q[2]);
        const double dist2 = (tp.point - p).squaredNorm();
        if (dist2 < best.distance2) best = {ids_[s], tp, dist2};
      }
    }
    if (top == 0) break;
    --top;
    n = stack[top].node, d2 = stack[top].d2;
  }
  return best;
}

template <class Meets, class F> void AabbTree::walk(const Meets& meets, bool triangle_boxes, F&& f) const {
  if (nodes_.empty()) return;
  std::array<std::int32_t, 128> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!meets(node.box)) continue;
    if (node.count > 0) {
      for (std::int32_t s = node.first; s < node.first + node.count; ++s)
        if (!triangle_boxes || meets(boxes_[s])) f(ids_[s]);
    } else {
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
  }
}

template <class F> void AabbTree::for_each_near(const P3& p, double radius, F&& f) const {
  const double r2 = radius * radius;
  walk([&](const Box<3>& b) { return !(box_distance2(b, p) > r2); }, false, f);
}

template <class F> void AabbTree::for_each_in_box(const Box<3>& box, F&& f) const {
  walk([&](const Box<3>& b) { return b.overlaps(box); }, false, f);
}

template <class F> void AabbTree::for_each_on_segment(const P3& a, const P3& b, F&& f) const {
  walk([&](const Box<3>& box) { return segment_meets_box(a, b, box); }, false, f);
}

template <class F> void AabbTree::for_each_boxed_on_segment(const P3& a, const P3& b, F&& f) const {
  walk([&](const Box<3>& box) { return segment_meets_box(a, b, box); }, true, f);
}

}  // namespace febemesh::dim3
