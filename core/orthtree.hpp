#pragma once
// Orthtree<Dim>: a linear quadtree (Dim = 2) or octree (Dim = 3). Leaves only, sorted in Morton
// order; parent, children and neighbours are computed (STYLE.md §4, p4est).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <new>
#include <utility>
#include <vector>

#include "core/boundary.hpp"
#include "core/box.hpp"
#include "core/cell.hpp"

namespace febemesh {

inline constexpr std::size_t no_leaf = std::numeric_limits<std::size_t>::max();

namespace detail {
/// Storage for leaf arrays: operator new, plus transparent huge pages for large arrays (see
/// huge_pages.hpp; kept out of this header so that it does not pull in <sys/mman.h>).
void* allocate_leaf_bytes(std::size_t bytes);
void deallocate_leaf_bytes(void* p, std::size_t bytes) noexcept;
}  // namespace detail

/// Allocator of the tree's leaf array. It differs from std::allocator in one respect: resize(n)
/// and emplace_back() leave the new cells unwritten (construct() without arguments does
/// nothing; pass a value, e.g. resize(n, Cell<Dim>{}), to get zero cells), so that threads
/// can fill disjoint parts of a freshly sized array in parallel. Value-initialising them first
/// would be one more serial pass over memory, and memory bandwidth, not arithmetic, is what
/// bounds refinement and balance on two threads here. Cell is an aggregate of integers with no
/// invariant to set up; the tree code writes every cell it adds by resize before publishing it.
template <class T> struct LeafAllocator {
  using value_type = T;
  LeafAllocator() = default;
  template <class U> constexpr LeafAllocator(const LeafAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(detail::allocate_leaf_bytes(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { detail::deallocate_leaf_bytes(p, n * sizeof(T)); }
  template <class U> void construct(U*) noexcept {}
  template <class U, class A, class... Args> void construct(U* p, A&& a, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a), std::forward<Args>(args)...);
  }
  friend bool operator==(const LeafAllocator&, const LeafAllocator&) { return true; }
};

/// The leaves of a tree, in Morton order. A std::vector (all of its interface), see LeafAllocator.
template <int Dim> using LeafVector = std::vector<Cell<Dim>, LeafAllocator<Cell<Dim>>>;

template <int Dim> class Orthtree {
 public:
  /// One root leaf over the unit cube.
  Orthtree();
  /// One root leaf over the smallest cube with lower corner domain.lo enclosing `domain`.
  explicit Orthtree(const Box<Dim>& domain);
  /// Given leaves over a root cube; in Debug asserts they are sorted, linear and complete.
  Orthtree(const Box<Dim>& root_cube, LeafVector<Dim> leaves);
  /// The same from a std::vector (copied).
  Orthtree(const Box<Dim>& root_cube, const std::vector<Cell<Dim>>& leaves);

  const LeafVector<Dim>& leaves() const { return leaves_; }
  std::size_t n_leaves() const { return leaves_.size(); }
  const Cell<Dim>& leaf(std::size_t i) const { return leaves_[i]; }
  /// The root cube in real coordinates.
  const Box<Dim>& root_box() const { return root_; }
  /// Real length of one lattice unit.
  double unit() const { return unit_; }

 private:
  Box<Dim> root_;
  double unit_ = 1.0;
  LeafVector<Dim> leaves_;
};

/// The smallest cube with lower corner domain.lo enclosing `domain` (the root of Orthtree(domain)).
/// Throws InputError for an empty, degenerate or non-finite domain.
template <int Dim> Box<Dim> root_cube(const Box<Dim>& domain);

/// Real box of a cell, and real position of a lattice point.
template <int Dim> Box<Dim> geometry(const Orthtree<Dim>& t, const Cell<Dim>& c);
template <int Dim> Point<Dim> position(const Orthtree<Dim>& t, const LatticePoint<Dim>& p);

// ---- refinement (mark, then repair, then execute: STYLE.md §6) ----------------------------

using Flags = std::vector<std::uint8_t>;

/// The control parameter of a cell: a target level wanted somewhere in its box.
template <int Dim> using ControlFn = std::function<double(const Box<Dim>&)>;

struct RefineOptions {
  int max_level = -1;                  ///< cap; -1 = max_level<Dim>
  std::size_t max_leaves = 200000000;  ///< refuse (LimitError) beyond this many leaves
  int n_threads = 1;                   ///< results identical for any count
};

/// The paper's check_and_subdivide_quadrant from the root: a cell of level L whose control
/// parameter exceeds L+1 is split and its children checked again; otherwise it is split once
/// and left. Throws LimitError when max_leaves would be exceeded.
template <int Dim>
Orthtree<Dim> subdivide_by_control(const Box<Dim>& domain, const ControlFn<Dim>& control,
                                   const RefineOptions& opt = {});

/// Flags[i] = pred(leaf i).
template <int Dim>
Flags mark(const Orthtree<Dim>& t, const std::function<bool(const Cell<Dim>&)>& pred);
/// Split every flagged leaf once.
template <int Dim> Orthtree<Dim> refine(const Orthtree<Dim>& t, const Flags& flags);
/// Split leaves while pred(leaf) holds (up to opt.max_level).
template <int Dim>
Orthtree<Dim> refine_while(const Orthtree<Dim>& t, const std::function<bool(const Cell<Dim>&)>& pred,
                           const RefineOptions& opt = {});

// ---- 2:1 balance ----------------------------------------------------------------------------

enum class BalanceKind : std::uint8_t {
  Face = 0,  ///< neighbours across facets differ by at most one level (the paper's rule)
  Full = 1   ///< across facets, edges and corners
};

struct BalanceOptions {
  std::size_t max_leaves = 200000000;  ///< refuse (LimitError) a result beyond this many leaves
  int n_threads = 1;                   ///< results identical for any count
};

/// The coarsest refinement of `t` that is 2:1 balanced. O(n log n). Throws LimitError, with the
/// leaf count and memory it would need, when the input or the result has more than
/// opt.max_leaves leaves; the count is known level by level before the output is allocated.
template <int Dim>
Orthtree<Dim> balance_2to1(const Orthtree<Dim>& t, BalanceKind kind = BalanceKind::Face,
                           const BalanceOptions& opt = {});

// ---- queries ----------------------------------------------------------------------------------

/// Leaf containing the real point (lower-closed cells; points on the upper root face go to the
/// last cell), or no_leaf outside the root.
template <int Dim> std::size_t locate(const Orthtree<Dim>& t, const Point<Dim>& p);
/// Leaf containing lattice point p (half-open cells), or no_leaf outside the root.
template <int Dim> std::size_t locate(const Orthtree<Dim>& t, const LatticePoint<Dim>& p);
/// Leaf equal to or containing `c`, or no_leaf if `c` is subdivided in `t`.
template <int Dim> std::size_t find_covering_leaf(const Orthtree<Dim>& t, const Cell<Dim>& c);

/// Leaves across facet f of leaf i: empty at the root boundary; one leaf when it is the same
/// size or coarser; the 2^(Dim-1) (or more, if unbalanced) finer leaves touching the facet,
/// in Morton order.
template <int Dim> std::vector<std::size_t> face_neighbours(const Orthtree<Dim>& t, std::size_t i, int f);
/// The same into `out` (cleared first): loops over every facet reuse one vector.
template <int Dim> void face_neighbours(const Orthtree<Dim>& t, std::size_t i, int f, std::vector<std::size_t>& out);
/// Leaves whose closed boxes overlap the closed real box `b`, in Morton order.
template <int Dim> std::vector<std::size_t> leaves_in_box(const Orthtree<Dim>& t, const Box<Dim>& b);

/// The same queries (same answers) on a flat copy of the leaves' Morton keys, for loops that ask
/// many of them of one tree: a probe of the binary search reads a key instead of computing one.
/// The tree must outlive this and stay unchanged.
template <int Dim> class LeafKeys {
 public:
  explicit LeafKeys(const Orthtree<Dim>& t);
  std::size_t find_covering_leaf(const Cell<Dim>& c) const;
  std::size_t locate(const LatticePoint<Dim>& p) const;
  /// locate, searching outward from leaf `hint` (O(log distance); e.g. the previous answer).
  std::size_t locate_near(const LatticePoint<Dim>& p, std::size_t hint) const;
  void face_neighbours(std::size_t i, int f, std::vector<std::size_t>& out) const;

 private:
  const Orthtree<Dim>* tree_;
  std::vector<std::uint64_t> keys_;
};

/// The unique lattice nodes of the (kept) leaves.
template <int Dim> struct LatticeNodes {
  std::vector<LatticePoint<Dim>> points;  ///< sorted by Morton key of the point, unique
  /// 1 when the node lies inside a facet or edge of some kept leaf without being its corner.
  std::vector<std::uint8_t> hanging;
  /// Per leaf (indexed like the tree's leaves), the node index of each corner; -1 if not kept.
  std::vector<std::array<std::int32_t, Cube<Dim>::n_corners>> leaf_corners;
  /// Node index of lattice point p, or -1 (binary search).
  std::int32_t find(const LatticePoint<Dim>& p) const;
};
/// Nodes of all leaves, or only of those with keep[i] != 0.
template <int Dim>
LatticeNodes<Dim> lattice_nodes(const Orthtree<Dim>& t, const Flags* keep = nullptr);

// ---- classification ---------------------------------------------------------------------------

/// IN / OUT / PARTIAL of every leaf against the boundary (paper "Find interior quadrants").
/// Top-down: a leaf inside a cell that b.classify finds IN or OUT takes that answer, so b's
/// classify must be monotone in the box (see classify.cpp).
template <int Dim>
std::vector<Side> classify(const Orthtree<Dim>& t, const Boundary<Dim>& b, int n_threads = 1);
/// classify(t, b) for a refinement t of `before` (the same root box, every leaf of t inside a
/// leaf of `before`), whose answers are before_sides: only the leaves below before's Partial
/// leaves are asked (a repair refines a few places). Any other t is classified from scratch.
template <int Dim>
std::vector<Side> classify_refined(const Orthtree<Dim>& t, const Orthtree<Dim>& before, const std::vector<Side>& before_sides,
                                   const Boundary<Dim>& b, int n_threads = 1);
/// Slow twin: b.classify of every leaf's own box.
template <int Dim> std::vector<Side> classify_ref(const Orthtree<Dim>& t, const Boundary<Dim>& b);

// ---- invariants (fast, and slow reference twins: STYLE.md §7) ---------------------------------

template <int Dim> bool is_sorted_and_linear(const Orthtree<Dim>& t);
template <int Dim> bool is_sorted_and_linear_ref(const Orthtree<Dim>& t);
/// Leaves tile the root exactly (no gap, no overlap).
template <int Dim> bool is_complete(const Orthtree<Dim>& t);
template <int Dim> bool is_complete_ref(const Orthtree<Dim>& t);
template <int Dim> bool is_balanced(const Orthtree<Dim>& t, BalanceKind kind = BalanceKind::Face);
template <int Dim> bool is_balanced_ref(const Orthtree<Dim>& t, BalanceKind kind = BalanceKind::Face);

}  // namespace febemesh
