#pragma once
// A uniform grid over a subset of the points (bucketed by counting sort), for box queries of
// about the size of the local spacing (the cells sized by the points' crowding, not the box's
// measure alone): the 2D validator asks one per edge of the mesh. The
// k-d tree it replaced there visited far more nodes than it reported, because the lattice
// nodes share coordinates with its split values (flange level 9, 3.4e5 triangles: 1.4e9
// instructions for the edge and duplicate queries and the build).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/box.hpp"

namespace febemesh {

template <int Dim> class PointGrid {
 public:
  /// Buckets pts[id] for id in ids (any order) into square cells, about one point to each cell
  /// that holds any. The points are copied in cell order (a query's rows read them in order
  /// instead of through the ids: the 3D validator's facet queries scan ~10 points each), so
  /// the grid answers for the points as they were here.
  PointGrid(const std::vector<Point<Dim>>& pts, const std::vector<std::int32_t>& ids) {
    Box<Dim> b = Box<Dim>::empty();
    for (const std::int32_t id : ids)
      if (pts[id].allFinite()) b.expand(pts[id]);
    lo_ = b.lo;
    const Point<Dim> ext = b.hi - b.lo;
    const double big = ext.allFinite() ? ext.maxCoeff() : 0.0;
    for (int d = 0; d < Dim; ++d) k_[d] = 1, inv_[d] = 0.0;
    std::size_t n_cells = 1;
    const auto count = [&] {
      start_.assign(n_cells + 1, 0);
      for (const std::int32_t id : ids) ++start_[cell_of(pts[id]) + 1];
    };
    if (big > 0 && !ids.empty()) {
      // Square cells, about one point each over the box first: side s from the box's measure
      // (each extent at least 1e-3 of the largest, so a flat box does not make needle cells).
      double measure = 1.0;
      for (int d = 0; d < Dim; ++d) measure *= std::max(ext[d], 1e-3 * big);
      const double s = std::pow(measure / static_cast<double>(ids.size()), 1.0 / Dim);
      const auto size_cells = [&](double side) {
        n_cells = 1;
        for (int d = 0; d < Dim; ++d) {
          k_[d] = static_cast<int>(std::clamp(std::ceil(ext[d] / side), 1.0, 1e6));
          inv_[d] = static_cast<double>(k_[d]) / std::max(ext[d], 1e-300);
          n_cells *= static_cast<std::size_t>(k_[d]);
        }
      };
      size_cells(s);
      count();
      // Points on a shell or a thin region of the box crowd the few cells they occupy (the 3D
      // pipeline's check of the tetrahedra at the surface, sphere966 level 6: 6.8 points a held
      // cell): smaller cells then, by the mean crowding, at most 8 times as many cells.
      std::size_t held = 0;
      for (std::size_t c = 0; c < n_cells; ++c) held += start_[c + 1] != 0;
      const double crowding = static_cast<double>(ids.size()) / static_cast<double>(std::max<std::size_t>(held, 1));
      if (crowding > 2.0) {
        const double finer = std::min(std::pow(crowding, 1.0 / Dim), std::pow(8.0, 1.0 / Dim));
        size_cells(s / finer);
        count();
      }
    } else {
      count();
    }
    for (std::size_t c = 0; c < n_cells; ++c) start_[c + 1] += start_[c];
    ids_.resize(ids.size());
    std::vector<std::int32_t> fill(start_.begin(), start_.end() - 1);
    for (const std::int32_t id : ids) ids_[static_cast<std::size_t>(fill[cell_of(pts[id])]++)] = id;
    at_.resize(ids_.size());
    for (std::size_t i = 0; i < ids_.size(); ++i) at_[i] = pts[static_cast<std::size_t>(ids_[i])];
  }

  /// Calls visit(id) for every point inside the closed box: cell by cell (the first axis
  /// fastest), within a cell in the order of the constructor's ids.
  template <class Visit> void query(const Box<Dim>& box, Visit&& visit) const {
    std::array<int, Dim> lo, hi, at;
    for (int d = 0; d < Dim; ++d) {
      if (!(box.lo[d] <= box.hi[d])) return;  // empty (or NaN): contains nothing
      lo[d] = coord(box.lo[d], d), hi[d] = coord(box.hi[d], d);
    }
    // The cells lo[0]..hi[0] of a row (the other coordinates fixed) are consecutive, and so are
    // their points: one run of ids per row, not one per cell (the same visits in the same order;
    // the per-cell index and bounds were most of the 3D validator's hanging-node queries).
    at = lo;
    for (;;) {
      std::size_t c = 0;
      for (int d = Dim - 1; d >= 0; --d) c = c * static_cast<std::size_t>(k_[d]) + static_cast<std::size_t>(at[d]);
      const std::int32_t end = start_[c + static_cast<std::size_t>(hi[0] - lo[0]) + 1];
      for (std::int32_t i = start_[c]; i < end; ++i)
        if (box.contains(at_[static_cast<std::size_t>(i)])) visit(ids_[static_cast<std::size_t>(i)]);
      int d = 1;
      while (d < Dim && at[d] == hi[d]) at[d] = lo[d], ++d;
      if (d == Dim) return;
      ++at[d];
    }
  }

 private:
  /// The cell index along axis d: monotone in x (so a box's cells hold every point inside it),
  /// clamped to the grid (points outside the bounds, non-finite coordinates).
  int coord(double x, int d) const {
    const double t = (x - lo_[d]) * inv_[d];
    if (!(t >= 0)) return 0;
    if (t >= k_[d]) return k_[d] - 1;
    return static_cast<int>(t);
  }
  std::size_t cell_of(const Point<Dim>& p) const {
    std::size_t c = 0;
    for (int d = Dim - 1; d >= 0; --d) c = c * static_cast<std::size_t>(k_[d]) + static_cast<std::size_t>(coord(p[d], d));
    return c;
  }

  Point<Dim> lo_;
  std::array<int, Dim> k_{};
  std::array<double, Dim> inv_{};
  std::vector<std::int32_t> start_, ids_;
  std::vector<Point<Dim>> at_;  ///< pts[ids_[i]]: a row's points read in order, not through the ids
};

}  // namespace febemesh
