// Orthtree<Dim> construction and the map from the integer lattice to real coordinates.

#include "core/orthtree.hpp"

#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/huge_pages.hpp"

namespace febemesh {

namespace detail {
// Arrays from 4 MiB up get huge pages: below that the one partly used huge page at each end
// would be a visible share of the array.
void* allocate_leaf_bytes(std::size_t bytes) {
  void* p = ::operator new(bytes);
  if (bytes >= (std::size_t(4) << 20)) advise_huge_pages(p, bytes);
  return p;
}
// Unsized: clang 14 has no sized operator delete without -fsized-deallocation.
void deallocate_leaf_bytes(void* p, std::size_t /*bytes*/) noexcept { ::operator delete(p); }
}  // namespace detail

template <int Dim> Box<Dim> root_cube(const Box<Dim>& domain) {
  const Point<Dim> ext = domain.hi - domain.lo;
  if (!domain.lo.allFinite() || !domain.hi.allFinite() || !(ext.minCoeff() >= 0.0) ||
      !(ext.maxCoeff() > 0.0)) {
    std::ostringstream os;
    os << "tree domain must be a finite box of positive size, got lo=(" << domain.lo.transpose()
       << ") hi=(" << domain.hi.transpose() << ")";
    throw InputError(os.str());
  }
  Box<Dim> cube;
  cube.lo = domain.lo;
  cube.hi = domain.lo + Point<Dim>::Constant(ext.maxCoeff());
  return cube;
}

template <int Dim> Orthtree<Dim>::Orthtree() : Orthtree(Box<Dim>{Point<Dim>::Zero(), Point<Dim>::Ones()}) {}

template <int Dim>
Orthtree<Dim>::Orthtree(const Box<Dim>& domain) : Orthtree(root_cube(domain), LeafVector<Dim>{Cell<Dim>{}}) {}

template <int Dim>
Orthtree<Dim>::Orthtree(const Box<Dim>& root_cube, const std::vector<Cell<Dim>>& leaves)
    : Orthtree(root_cube, LeafVector<Dim>(leaves.begin(), leaves.end())) {}

template <int Dim>
Orthtree<Dim>::Orthtree(const Box<Dim>& root_cube, LeafVector<Dim> leaves)
    : root_(root_cube), leaves_(std::move(leaves)) {
  // The side divided by a power of two is exact, so lattice positions of the upper root
  // faces land exactly on root_.hi.
  unit_ = (root_.hi[0] - root_.lo[0]) / double(root_length<Dim>);
  MESH_ASSERT(unit_ > 0.0, "root cube has no size");
  MESH_ASSERT(is_complete(*this), "leaves are not sorted, linear and complete (" << leaves_.size()
                                                                                 << " leaves)");
}

template <int Dim> Box<Dim> geometry(const Orthtree<Dim>& t, const Cell<Dim>& c) {
  Box<Dim> b;
  const double len = double(length(c));
  for (int d = 0; d < Dim; ++d) {
    b.lo[d] = t.root_box().lo[d] + t.unit() * double(c.anchor[d]);
    b.hi[d] = t.root_box().lo[d] + t.unit() * (double(c.anchor[d]) + len);
  }
  return b;
}

template <int Dim> Point<Dim> position(const Orthtree<Dim>& t, const LatticePoint<Dim>& p) {
  Point<Dim> x;
  for (int d = 0; d < Dim; ++d) x[d] = t.root_box().lo[d] + t.unit() * double(p[d]);
  return x;
}

template class Orthtree<2>;
template class Orthtree<3>;
template Box<2> root_cube<2>(const Box<2>&);
template Box<3> root_cube<3>(const Box<3>&);
template Box<2> geometry<2>(const Orthtree<2>&, const Cell<2>&);
template Box<3> geometry<3>(const Orthtree<3>&, const Cell<3>&);
template Point<2> position<2>(const Orthtree<2>&, const LatticePoint<2>&);
template Point<3> position<3>(const Orthtree<3>&, const LatticePoint<3>&);

}  // namespace febemesh
