#include "dim3/aabb_tree.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "core/error.hpp"

namespace febemesh::dim3 {

const std::array<P3, 16>& ray_directions() {
  static const std::array<P3, 16> dirs = [] {
    std::array<P3, 16> d;
    std::mt19937 gen(20240611u);  // fixed seed: deterministic runs
    auto uniform = [&] { return static_cast<double>(gen()) / 4294967296.0; };
    for (auto& v : d) {
      // Uniform on the sphere (Archimedes): z uniform in [-1, 1], angle uniform.
      const double z = 2.0 * uniform() - 1.0, phi = 2.0 * 3.14159265358979323846 * uniform();
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      v = P3(r * std::cos(phi), r * std::sin(phi), z);
    }
    return d;
  }();
  return dirs;
}

AabbTree::AabbTree(const std::vector<P3>& vertices, const std::vector<Triangle>& triangles) {
  const std::int32_t n = static_cast<std::int32_t>(triangles.size());
  if (n == 0) return;
  ids_.resize(n);
  std::iota(ids_.begin(), ids_.end(), 0);
  std::vector<P3> centroids(n);
  for (std::int32_t t = 0; t < n; ++t)
    centroids[t] = (vertices[triangles[t][0]] + vertices[triangles[t][1]] + vertices[triangles[t][2]]) / 3.0;
  // Fill points_ by triangle index first; build() permutes ids_, then we reorder.
  points_.resize(n);
  for (std::int32_t t = 0; t < n; ++t)
    points_[t] = {vertices[triangles[t][0]], vertices[triangles[t][1]], vertices[triangles[t][2]]};
  nodes_.reserve(2 * static_cast<std::size_t>(n) / 2 + 8);
  nodes_.push_back({});
  build(0, 0, n, centroids);
  std::vector<std::array<P3, 3>> by_slot(n);
  slot_.resize(n);
  for (std::int32_t s = 0; s < n; ++s) {
    by_slot[s] = points_[ids_[s]];
    slot_[ids_[s]] = s;
  }
  points_ = std::move(by_slot);
  boxes_.resize(n);
  double coordinate = 0.0;
  for (std::int32_t s = 0; s < n; ++s) {
    boxes_[s] = Box<3>::empty();
    for (const P3& q : points_[s]) boxes_[s].expand(q), coordinate = std::max(coordinate, q.cwiseAbs().maxCoeff());
  }
  pair_boxes_.resize(nodes_.size() / 2);
  for (std::size_t k = 0; k < pair_boxes_.size(); ++k)
    for (int c = 0; c < 2; ++c)
      for (int d = 0; d < 3; ++d) {
        pair_boxes_[k].lo[d][c] = nodes_[2 * k + 1 + c].box.lo[d];
        pair_boxes_[k].hi[d][c] = nodes_[2 * k + 1 + c].box.hi[d];
      }
  const double scale = coordinate + nodes_[0].box.extent().norm();
  slack2_ = (1e-8 * scale) * (1e-8 * scale);
}

void AabbTree::build(std::int32_t node, std::int32_t begin, std::int32_t end,
                     const std::vector<P3>& centroids) {
  Box<3> box = Box<3>::empty(), cbox = Box<3>::empty();
  for (std::int32_t s = begin; s < end; ++s) {
    for (const P3& q : points_[ids_[s]]) box.expand(q);
    cbox.expand(centroids[ids_[s]]);
  }
  nodes_[node].box = box;
  constexpr std::int32_t leaf_size = 4;
  if (end - begin <= leaf_size) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  int axis = 0;
  const P3 ext = cbox.extent();
  if (ext[1] > ext[axis]) axis = 1;
  if (ext[2] > ext[axis]) axis = 2;
  const std::int32_t mid = begin + (end - begin) / 2;
  std::nth_element(ids_.begin() + begin, ids_.begin() + mid, ids_.begin() + end,
                   [&](std::int32_t a, std::int32_t b) {
                     const double ca = centroids[a][axis], cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  const std::int32_t left = static_cast<std::int32_t>(nodes_.size());
  nodes_.push_back({});
  nodes_.push_back({});
  nodes_[node].first = left;
  nodes_[node].count = 0;
  MESH_ASSERT(end - begin > 0, "empty node");
  build(left, begin, mid, centroids);
  build(left + 1, mid, end, centroids);
}

AabbTree::Closest AabbTree::closest(const P3& p) const {
  return closest_if(p, [](std::int32_t) { return false; });
}

AabbTree::Closest AabbTree::closest(const P3& p, std::int32_t hint) const {
  double bound = std::numeric_limits<double>::infinity();
  if (hint >= 0 && hint < n_triangles()) {
    // The walk meets the hint's triangle again (usually the answer): its point is reused.
    const auto& q = points(hint);
    const TrianglePoint tp = closest_on_triangle(p, q[0], q[1], q[2]);
    bound = (tp.point - p).squaredNorm() * (1.0 + 1e-9) + slack2_;
    return closest_within(p, bound, [](std::int32_t) { return false; }, slot_[hint], &tp);
  }
  return closest_within(p, bound, [](std::int32_t) { return false; });
}

bool AabbTree::overlaps(const Box<3>& box) const {
  bool found = false;
  // for_each_in_box cannot stop early; the box test prunes enough for the boxes we ask about.
  for_each_in_box(box, [&](std::int32_t t) {
    if (found) return;
    const auto& q = points(t);
    found = box_triangle_overlap(box, q[0], q[1], q[2]);
  });
  return found;
}

double AabbTree::box_distance2(const Box<3>& b, const P3& p) {
  double d2 = 0.0;
  for (int d = 0; d < 3; ++d) {
    // max(lo - p, 0, p - hi) in two maxsd (std::max of a list: a loop); the same square.
    const double e = std::max(std::max(b.lo[d] - p[d], p[d] - b.hi[d]), 0.0);
    d2 += e * e;
  }
  return d2;
}

bool AabbTree::segment_meets_box(const P3& a, const P3& b, const Box<3>& box) {
  double t0 = 0.0, t1 = 1.0;
  const P3 dir = b - a;
  for (int d = 0; d < 3; ++d) {
    // Slightly enlarged slabs: a segment grazing a face must not be pruned by round-off.
    const double pad = 1e-12 * (std::abs(box.hi[d]) + std::abs(box.lo[d]) + 1.0);
    const double lo = box.lo[d] - pad, hi = box.hi[d] + pad;
    if (dir[d] == 0.0) {
      if (a[d] < lo || a[d] > hi) return false;
      continue;
    }
    double ta = (lo - a[d]) / dir[d], tb = (hi - a[d]) / dir[d];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace febemesh::dim3
