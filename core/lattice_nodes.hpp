#pragma once
// Helpers of lattice_nodes (core/orthtree.hpp) that its users share.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace febemesh {

/// std::lower_bound(keys, key) as an index, found by galloping outward from `hint`: the same
/// answer in O(log distance) steps (the corners of consecutive leaves lie close in Morton order).
/// Requires keys sorted ascending.
std::size_t lower_bound_from(const std::vector<std::uint64_t>& keys, std::uint64_t key, std::size_t hint);

}  // namespace febemesh
