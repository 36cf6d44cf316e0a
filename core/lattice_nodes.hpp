#pragma once
// Helpers of lattice_nodes (core/orthtree.hpp) that its users share.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/orthtree.hpp"

namespace febemesh {

enum class HangingFlags { Computed, Skipped };
/// lattice_nodes(t, keep), with `hanging` left empty when Skipped: finding them looks up the
/// leaves around every node, and the pipelines do not read them (their rings find the mid-edge
/// nodes themselves). Runs on n_threads threads; the same nodes for every count.
template <int Dim>
LatticeNodes<Dim> lattice_nodes(const Orthtree<Dim>& t, const Flags* keep, HangingFlags hanging, int n_threads = 1);

/// std::lower_bound(keys, key) as an index, found by galloping outward from `hint`: the same
/// answer in O(log distance) steps (the corners of consecutive leaves lie close in Morton order).
/// Requires keys sorted ascending.
std::size_t lower_bound_from(const std::vector<std::uint64_t>& keys, std::uint64_t key, std::size_t hint);

}  // namespace febemesh
