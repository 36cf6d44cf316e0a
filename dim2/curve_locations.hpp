#pragma once
// The locations on the curve of a 2D mesh's interface nodes, kept for those nodes only (by
// node, ascending). One BoundaryLocation (32 bytes) for every node, most of them with none, was
// 16 bytes an element at the 2D pipeline's memory peak (massif, bracket at 10^6 triangles).

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "core/boundary.hpp"
#include "core/error.hpp"

namespace febemesh::dim2 {

class CurveLocations {
 public:
  /// Node v's location, or one with patch -1 when v has none.
  const BoundaryLocation& operator[](std::int32_t v) const {
    const std::int32_t k = slot(v);
    return k >= 0 ? at_[static_cast<std::size_t>(k)] : none_;
  }
  /// Node v's location, which it must have (add).
  BoundaryLocation& at(std::int32_t v) {
    const std::int32_t k = slot(v);
    MESH_ASSERT(k >= 0, "node " << v << " has no location on the curve");
    return at_[static_cast<std::size_t>(k)];
  }
  /// Gives node v a location; v above every node given one so far.
  void add(std::int32_t v, const BoundaryLocation& w) {
    MESH_ASSERT(node_.empty() || v > node_.back(), "node " << v << " located after node " << node_.back());
    node_.push_back(v);
    at_.push_back(w);
  }
  void reserve(std::size_t n) {
    node_.reserve(n);
    at_.reserve(n);
  }
  /// The located nodes, ascending, and their locations in the same order.
  std::span<const std::int32_t> nodes() const { return node_; }
  std::span<const BoundaryLocation> locations() const { return at_; }
  std::span<BoundaryLocation> locations() { return at_; }
  std::size_t size() const { return node_.size(); }

 private:
  /// Node v's index in node_ / at_, or -1.
  std::int32_t slot(std::int32_t v) const {
    const auto it = std::lower_bound(node_.begin(), node_.end(), v);
    return it != node_.end() && *it == v ? static_cast<std::int32_t>(it - node_.begin()) : -1;
  }

  std::vector<std::int32_t> node_;
  std::vector<BoundaryLocation> at_;
  static inline const BoundaryLocation none_{};
};

}  // namespace febemesh::dim2
