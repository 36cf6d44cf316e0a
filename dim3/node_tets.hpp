#pragma once
// The tetrahedra at each node of a mesh of tetrahedra, in compressed rows (core/incidence_csr.hpp):
// node v's are tets[start[v] .. start[v + 1]), ascending. The tet optimiser builds them and
// hands them to the edge removal that follows it (the connectivity does not change in between),
// which would otherwise build the same lists again.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace febemesh::dim3 {

struct NodeTets {
  std::vector<std::int32_t> start, tets;
  /// Whether these are lists of n_nodes nodes over n_tets tetrahedra (four uses each).
  bool fits(std::size_t n_nodes, std::size_t n_tets) const {
    return start.size() == n_nodes + 1 && tets.size() == 4 * n_tets;
  }
  void clear() {
    std::vector<std::int32_t>().swap(start);
    std::vector<std::int32_t>().swap(tets);
  }
};

}  // namespace febemesh::dim3
