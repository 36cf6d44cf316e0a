#pragma once
// The quadrants after the paper's step 3 (interior quadrants plus boundary quadrants), with
// shared nodes: what smoothing, the BE mesh and the FE templates work on.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/boundary.hpp"
#include "core/box.hpp"
#include "core/error.hpp"
#include "core/huge_pages.hpp"

namespace febemesh::dim2 {

enum class NodeKind : std::uint8_t {
  Interior = 0,  ///< a lattice node of the interior quadrants, off the free edges
  Chain = 1,     ///< a lattice node on a free edge (the paper's Q points)
  Boundary = 2   ///< a projection on the curve (the paper's P points)
};

/// The nodes around an interior quadrant: its 4 corners and, 2:1 balance allowing one per
/// edge, up to 4 hanging mid-edge nodes, stored inline (a heap vector per quadrant cost up to
/// four allocations and ~40 bytes more each, at the run's memory peak).
class QuadrantRing {
 public:
  static constexpr std::size_t capacity = 8;
  void push_back(std::int32_t v) {
    MESH_ASSERT(n_ < capacity, "ring of more than " << capacity << " nodes");
    v_[n_++] = v;
  }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  std::int32_t operator[](std::size_t k) const { return v_[k]; }
  const std::int32_t* begin() const { return v_.data(); }
  const std::int32_t* end() const { return v_.data() + n_; }
  operator std::span<const std::int32_t>() const { return {v_.data(), n_}; }

 private:
  std::array<std::int32_t, capacity> v_{};
  std::uint8_t n_ = 0;
};

struct InteriorQuadrant {
  /// The tree's leaf (build_quadrant_complex refuses trees of 2^32 leaves or more: 4 bytes, not
  /// 8, make a quadrant 48 bytes instead of 56; at 10^6 triangles the interior quadrants were 27.5
  /// MB of the 86.6 MB heap peak, massif on bracket).
  std::uint32_t leaf = 0;
  std::uint8_t level = 0;
  /// Nodes counter-clockwise from the lower-left corner, hanging mid-edge nodes included.
  QuadrantRing ring;
  /// corner_slot[k]: position in `ring` of corner k of FaceCorners<2>::ring order (ll, lr, ur, ul).
  std::array<std::uint8_t, 4> corner_slot{};
  bool has_hanging() const { return ring.size() > 4; }
};
static_assert(sizeof(InteriorQuadrant) == 48);

/// A boundary quadrant, counter-clockwise: Q2, Q1 (the free edge, reversed), P1, P2 (on the
/// curve). P1 == P2 makes it a triangle (the paper's coincident projections). A corner of the
/// curve between P1 and P2 that no boundary node could be pulled onto without distorting the
/// quadrant is inserted as a fifth node between P1 and P2.
struct BoundaryQuadrant {
  std::array<std::int32_t, 4> node{};  ///< Q2, Q1, P1, P2
  std::int32_t corner = -1;            ///< node of an inserted corner between P1 and P2, or -1
  std::size_t leaf = 0;                ///< the interior quadrant behind the free edge
  std::uint8_t level = 0;              ///< level of the free edge's cell
  bool is_triangle() const { return node[2] == node[3]; }
  /// The nodes counter-clockwise: 3, 4 or 5 of them.
  std::vector<std::int32_t> polygon() const {
    std::vector<std::int32_t> p{node[0], node[1], node[2]};
    if (corner >= 0) p.push_back(corner);
    if (!is_triangle()) p.push_back(node[3]);
    return p;
  }
};

struct QuadrantComplex {
  std::vector<Point<2>> points;
  std::vector<NodeKind> kind;
  std::vector<InteriorQuadrant> interior;
  std::vector<BoundaryQuadrant> boundary;

  /// Where Boundary node i lies on the curve. Requires kind[i] == NodeKind::Boundary.
  BoundaryLocation& where(std::int32_t i) { return where_[index_of(i)]; }
  const BoundaryLocation& where(std::int32_t i) const { return where_[index_of(i)]; }

  /// Room for n_lattice lattice nodes and n_boundary boundary nodes (add_node's arrays), on
  /// huge pages where large.
  void reserve_nodes(std::size_t n_lattice, std::size_t n_boundary) {
    reserve_room(points, n_lattice + n_boundary);  // (n_boundary: at most)
    reserve_room(kind, n_lattice + n_boundary);
    reserve_room(where_, n_boundary);
  }

  /// Lattice nodes (Interior, Chain) first, then Boundary nodes: only these have a location
  /// (32 bytes a node for every node was ~16 bytes an element at the run's memory peak).
  std::int32_t add_node(const Point<2>& p, NodeKind k, const BoundaryLocation& w = {}) {
    const auto i = static_cast<std::int32_t>(points.size());
    if (k == NodeKind::Boundary) {
      if (where_.empty()) first_boundary_ = i;
      MESH_ASSERT(std::size_t(i - first_boundary_) == where_.size(), "boundary node " << i << " after a lattice node");
      where_.push_back(w);
    } else {
      MESH_ASSERT(where_.empty(), "lattice node " << i << " after a boundary node");
    }
    points.push_back(p);
    kind.push_back(k);
    return i;
  }

 private:
  std::size_t index_of(std::int32_t i) const {
    MESH_ASSERT(i >= first_boundary_ && std::size_t(i - first_boundary_) < where_.size(), "node " << i << " has no location");
    return static_cast<std::size_t>(i - first_boundary_);
  }
  std::vector<BoundaryLocation> where_;
  std::int32_t first_boundary_ = 0;
};

}  // namespace febemesh::dim2
