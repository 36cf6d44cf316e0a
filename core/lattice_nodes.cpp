// Unique lattice nodes of the leaves: corners are integer lattice points, so shared nodes are
// found by sorting their Morton keys (exact, no tolerance), and a node is hanging when one of the
// kept leaves around it has it on its boundary without having it as a corner.

#include <algorithm>

#include "core/error.hpp"
#include "core/orthtree.hpp"

namespace febemesh {

template <int Dim> std::int32_t LatticeNodes<Dim>::find(const LatticePoint<Dim>& p) const {
  const std::uint64_t key = point_key<Dim>(p);
  const auto it = std::lower_bound(points.begin(), points.end(), key,
                                   [](const LatticePoint<Dim>& q, std::uint64_t k) { return point_key<Dim>(q) < k; });
  if (it == points.end() || *it != p) return -1;
  return std::int32_t(it - points.begin());
}

template <int Dim> LatticeNodes<Dim> lattice_nodes(const Orthtree<Dim>& t, const Flags* keep) {
  if (keep != nullptr && keep->size() != t.n_leaves()) {
    throw InputError("lattice_nodes: keep mask has " + std::to_string(keep->size()) + " entries for " +
                     std::to_string(t.n_leaves()) + " leaves");
  }
  const auto kept = [&](std::size_t i) { return keep == nullptr || (*keep)[i] != 0; };
  constexpr int n_corners = Cube<Dim>::n_corners;

  std::vector<std::uint64_t> keys;
  keys.reserve(t.n_leaves() * n_corners);
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    if (!kept(i)) continue;
    for (int k = 0; k < n_corners; ++k) keys.push_back(point_key<Dim>(corner(t.leaf(i), k)));
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  if (keys.size() > std::size_t(std::numeric_limits<std::int32_t>::max())) {
    throw LimitError("lattice_nodes: " + std::to_string(keys.size()) + " nodes exceed 32-bit node ids");
  }

  LatticeNodes<Dim> nodes;
  nodes.points.reserve(keys.size());
  for (const std::uint64_t k : keys) nodes.points.push_back(point_from_key<Dim>(k));

  nodes.leaf_corners.resize(t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    auto& row = nodes.leaf_corners[i];
    for (int k = 0; k < n_corners; ++k) {
      if (!kept(i)) {
        row[k] = -1;
        continue;
      }
      const std::uint64_t key = point_key<Dim>(corner(t.leaf(i), k));
      row[k] = std::int32_t(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
    }
  }

  // The leaves touching node p are those containing the 2^Dim finest lattice cells around p.
  const LeafKeys<Dim> leaf_keys(t);
  // Nodes come in Morton order, so each of the 2^Dim cells around them moves little in the
  // leaves' Morton order from one node to the next: its search starts at its previous answer.
  std::array<std::size_t, n_corners> hint{};
  nodes.hanging.assign(keys.size(), 0);
  for (std::size_t n = 0; n < nodes.points.size(); ++n) {
    const LatticePoint<Dim>& p = nodes.points[n];
    for (int o = 0; o < n_corners && !nodes.hanging[n]; ++o) {
      LatticePoint<Dim> q = p;
      bool inside = true;
      for (int d = 0; d < Dim; ++d) {
        if (corner_is_upper(o, d)) {
          inside = inside && q[d] < root_length<Dim>;
        } else {
          inside = inside && q[d] > 0;
          q[d] -= inside ? 1 : 0;
        }
      }
      if (!inside) continue;
      const std::size_t j = leaf_keys.locate_near(q, hint[o]);
      if (j != no_leaf) hint[o] = j;
      if (j != no_leaf && kept(j) && !is_corner(t.leaf(j), p)) nodes.hanging[n] = 1;
    }
  }
  return nodes;
}

template struct LatticeNodes<2>;
template struct LatticeNodes<3>;
template LatticeNodes<2> lattice_nodes<2>(const Orthtree<2>&, const Flags*);
template LatticeNodes<3> lattice_nodes<3>(const Orthtree<3>&, const Flags*);

}  // namespace febemesh
