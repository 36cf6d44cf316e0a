#include "core/local_repair.hpp"

namespace febemesh {

Flags interior_flags(const std::vector<Side>& sides) {
  Flags in(sides.size());
  for (std::size_t i = 0; i < sides.size(); ++i) in[i] = sides[i] == Side::In ? 1 : 0;
  return in;
}

template <int Dim>
bool mark_around(const Orthtree<Dim>& t, const std::vector<Point<Dim>>& places, double cells, int max_level,
                 Flags& flags) {
  flags.assign(t.n_leaves(), 0);
  bool any = false;
  for (const Point<Dim>& p : places) {
    const std::size_t i = locate(t, p);
    const double h = t.unit() * length(t.leaf(i == no_leaf ? 0 : i));
    Box<Dim> b;
    b.lo = p.array() - cells * h;
    b.hi = p.array() + cells * h;
    for (std::size_t j : leaves_in_box(t, b)) {
      if (t.leaf(j).level < max_level) {
        flags[j] = 1;
        any = true;
      }
    }
  }
  return any;
}

template bool mark_around<2>(const Orthtree<2>&, const std::vector<Point<2>>&, double, int, Flags&);
template bool mark_around<3>(const Orthtree<3>&, const std::vector<Point<3>>&, double, int, Flags&);

}  // namespace febemesh
