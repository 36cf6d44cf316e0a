#include "dim3/surface_boundary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <tuple>

#include "core/error.hpp"
#include "core/sized_level.hpp"
#include "dim3/read_surface.hpp"
#include "dim3/surface_checks.hpp"
#include "dim3/triangle_predicates.hpp"

namespace febemesh::dim3 {

namespace {

int edge_slot(TriangleRegion r) { return static_cast<int>(r) - static_cast<int>(TriangleRegion::Edge0); }
int vertex_slot(TriangleRegion r) { return static_cast<int>(r) - static_cast<int>(TriangleRegion::Vertex0); }
bool is_edge(TriangleRegion r) { return r >= TriangleRegion::Edge0 && r <= TriangleRegion::Edge2; }
bool is_vertex(TriangleRegion r) { return r >= TriangleRegion::Vertex0; }

}  // namespace

SurfaceBoundary::SurfaceBoundary(Surface surface, SurfaceOptions options)
    : SurfaceBoundary(std::move(surface), AabbTree(), options) {}

SurfaceBoundary::SurfaceBoundary(Surface surface, AabbTree tree, SurfaceOptions options)
    : surface_(std::move(surface)),
      options_(options),
      tree_(tree.n_triangles() == surface_.n_triangles() && surface_.n_triangles() > 0
                ? std::move(tree)
                : AabbTree(surface_.vertices(), surface_.triangles())),
      features_(surface_, options.features) {
  diagonal_ = surface_.bounding_box().extent().norm();
  const int nt = surface_.n_triangles();
  curvature_.assign(nt, 0.0);
  near_feature_.assign(nt, false);
  std::vector<P3> centroid(nt);
  for (std::int32_t t = 0; t < nt; ++t) {
    const Triangle& tr = surface_.triangle(t);
    centroid[t] = (surface_.vertex(tr[0]) + surface_.vertex(tr[1]) + surface_.vertex(tr[2])) / 3.0;
  }
  // Curvature across each smooth edge (bending angle over the centroid distance), averaged at
  // the vertices, then over the triangle's vertices: single edges of irregular meshes are noisy
  // and the level field takes a maximum, so an average keeps outliers from driving it.
  std::vector<double> kappa_sum(surface_.n_vertices(), 0.0);
  std::vector<int> kappa_count(surface_.n_vertices(), 0);
  for (std::int32_t e = 0; e < surface_.n_edges(); ++e) {
    if (features_.is_feature_edge(e)) continue;
    const auto tris = surface_.edge_triangles(e);
    const double gap = (centroid[tris[0]] - centroid[tris[1]]).norm();
    if (!(gap > 0.0)) continue;
    for (std::int32_t v : surface_.edge(e)) {
      kappa_sum[v] += features_.dihedral(e) / gap;
      ++kappa_count[v];
    }
  }
  for (std::int32_t t = 0; t < nt; ++t) {
    double kappa = 0.0;
    for (int i = 0; i < 3; ++i) {
      const std::int32_t v = surface_.triangle(t)[i];
      if (kappa_count[v] > 0) kappa += kappa_sum[v] / kappa_count[v] / 3.0;
      if (features_.is_feature_edge(surface_.triangle_edge(t, i)) || features_.is_corner(v)) near_feature_[t] = true;
    }
    curvature_[t] = kappa;
  }
  set_root_scale(options_.root_scale);
}

void SurfaceBoundary::set_root_scale(double scale) {
  options_.root_scale = scale;
  root_side_ = root_box().extent()[0];
  const std::size_t nt = curvature_.size();
  curvature_level_.assign(nt, -std::numeric_limits<double>::infinity());
  for (std::size_t t = 0; t < nt; ++t)
    if (const double kappa = curvature_[t]; kappa > 0.0) curvature_level_[t] = std::log2(root_side_ * kappa / options_.arc);
  // Thickness: the first surface point hit by a ray from the centroid straight inwards. A part
  // thinner than a few octants has no interior octant across it and falls apart (measured: rotor
  // and elephant at level 4 changed topology), so the level field asks for `thickness_cells`
  // octants across it.
  set_thickness_level(options_.thickness_cells, options_.thickness_max_level);
}

const std::vector<double>& SurfaceBoundary::thicknesses() {
  if (thickness_.empty()) {
    thickness_.resize(surface_.n_triangles());
    for (std::int32_t t = 0; t < surface_.n_triangles(); ++t) thickness_[t] = thickness(t);
  }
  return thickness_;
}

const std::vector<double>& SurfaceBoundary::centroid_thicknesses() {
  if (centroid_thickness_.empty()) {
    centroid_thickness_.resize(surface_.n_triangles());
    for (std::int32_t t = 0; t < surface_.n_triangles(); ++t) centroid_thickness_[t] = centroid_thickness(t);
  }
  return centroid_thickness_;
}

double SurfaceBoundary::thin_share(double h) {
  const std::vector<double>& thick = thicknesses();
  double thin = 0.0, all = 0.0;
  for (std::int32_t t = 0; t < surface_.n_triangles(); ++t) {
    const double a = surface_.triangle_area(t);
    all += a;
    if (thick[t] < h) thin += a;
  }
  return all > 0 ? thin / all : 0.0;
}

double SurfaceBoundary::thin_parts_level(double cells, int level) {
  const std::vector<double>& thick = thicknesses();
  std::vector<std::pair<double, double>> levels;  // (level, area)
  double all = 0.0;
  for (std::int32_t t = 0; t < surface_.n_triangles(); ++t) {
    const double l = std::log2(root_side_ * cells / thick[t]);
    if (!(std::isfinite(l) && l > level)) continue;
    const double a = surface_.triangle_area(t);
    levels.emplace_back(l, a);
    all += a;
  }
  if (levels.empty()) return -std::numeric_limits<double>::infinity();
  std::sort(levels.begin(), levels.end());
  double below = 0.0;
  for (const auto& [l, a] : levels)
    if ((below += a) >= 0.5 * all) return l;
  return levels.back().first;
}

void SurfaceBoundary::set_thickness_level(double cells, double max_level) {
  options_.thickness_cells = cells;
  options_.thickness_max_level = max_level;
  thickness_level_.assign(surface_.n_triangles(), -std::numeric_limits<double>::infinity());
  if (!(cells > 0)) return;
  const std::vector<double>& thick = thicknesses();
  for (std::size_t t = 0; t < thick.size(); ++t)
    if (std::isfinite(thick[t]) && thick[t] > 0) thickness_level_[t] = std::log2(root_side_ * cells / thick[t]);
  sample_begin_.clear();
  sample_point_.clear();
  sample_level_.clear();
  sample_reach_.clear();
  if (!options_.thickness_sampled) return;
  // A grid of rays over each triangle whose thickness level passes the global level, spaced a
  // quarter of its four-ray thickness (the finest octant of the cap at least).
  const double finest = root_side_ / std::exp2(max_level);
  sample_begin_.assign(surface_.n_triangles() + 1, 0);
  sample_reach_.assign(surface_.n_triangles(), 0.0);
  for (std::int32_t t = 0; t < surface_.n_triangles(); ++t) {
    sample_begin_[t] = static_cast<std::int32_t>(sample_point_.size());
    if (!(thickness_level_[t] > options_.global_level)) continue;
    const Triangle& tr = surface_.triangle(t);
    const P3 &a = surface_.vertex(tr[0]), &b = surface_.vertex(tr[1]), &c = surface_.vertex(tr[2]);
    const double edge = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double spacing = std::max(0.25 * thick[t], finest);
    const int n = std::min(200, std::max(1, static_cast<int>(std::ceil(edge / spacing))));
    sample_reach_[t] = edge / n;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const P3 p = a + (b - a) * (static_cast<double>(i) / n) + (c - a) * (static_cast<double>(j) / n);
        const std::int32_t vertex = i == 0 && j == 0 ? tr[0] : i == n ? tr[1] : j == n ? tr[2] : -1;
        const double th = thickness_from(t, p, vertex);
        if (!(std::isfinite(th) && th > 0)) continue;
        sample_point_.push_back(p);
        sample_level_.push_back(std::log2(root_side_ * cells / th));
        thickness_level_[t] = std::max(thickness_level_[t], sample_level_.back());
      }
  }
  sample_begin_[surface_.n_triangles()] = static_cast<std::int32_t>(sample_point_.size());
}

double SurfaceBoundary::thickness_from(std::int32_t t, const P3& from_point, std::int32_t vertex) const {
  const P3 n = surface_.normal(t).normalized();
  const P3 from = from_point - 1e-9 * diagonal_ * n, to = from_point - diagonal_ * n;
  // Hits nearer than this (share of the ray, which is one diagonal long) are the start's own
  // surface met again by round-off.
  const double near = 1e-7;
  double first = std::numeric_limits<double>::infinity();
  bool leaves = false;
  tree_.for_each_on_segment(from, to, [&](std::int32_t u) {
    if (u == t) return;
    if (vertex >= 0) {
      const Triangle& tu = surface_.triangle(u);
      if (tu[0] == vertex || tu[1] == vertex || tu[2] == vertex) return;
    }
    const auto& q = tree_.points(u);
    const double s = line_triangle_parameter(from, to, q[0], q[1], q[2]);
    if (!(s > near) || s > first) return;
    // The ray runs along -n: it leaves the solid through u when u's outward normal is along it.
    const bool out = surface_.normal(u).dot(n) < 0;
    leaves = s < first ? out : (leaves || out);
    first = s;
  });
  return std::isfinite(first) && leaves ? first * diagonal_ : std::numeric_limits<double>::infinity();
}

double SurfaceBoundary::centroid_thickness(std::int32_t t) const {
  const Triangle& tr = surface_.triangle(t);
  return thickness_from(t, (surface_.vertex(tr[0]) + surface_.vertex(tr[1]) + surface_.vertex(tr[2])) / 3.0, -1);
}

double SurfaceBoundary::thickness(std::int32_t t) const {
  const Triangle& tr = surface_.triangle(t);
  double best = centroid_thickness(t);
  for (std::int32_t v : tr) best = std::min(best, thickness_from(t, surface_.vertex(v), v));
  return best;
}

SurfaceBoundary SurfaceBoundary::from_file(const std::string& path, SurfaceOptions options) {
  Surface s(read_surface(path));
  AabbTree tree = validate_surface(s, path);
  return SurfaceBoundary(std::move(s), std::move(tree), options);
}

Box<3> SurfaceBoundary::root_box() const {
  const Box<3> b = surface_.bounding_box();
  const double half = 0.5 * default_root_side(b) * options_.root_scale;
  Box<3> cube;
  cube.lo = b.center().array() - half + 2.0 * half * options_.root_shift.array();
  cube.hi = b.center().array() + half + 2.0 * half * options_.root_shift.array();
  return cube;
}

BoundaryLocation SurfaceBoundary::locate(std::int32_t t, const TrianglePoint& tp) const {
  BoundaryLocation where;
  where.patch = t;
  where.param[0] = tp.u;
  where.param[1] = tp.v;
  if (is_edge(tp.region)) {
    const std::int32_t e = surface_.triangle_edge(t, edge_slot(tp.region));
    if (features_.is_feature_edge(e)) {
      where.kind = BoundaryLocation::Kind::FeatureEdge;
      where.feature = features_.feature_edge_index(e);
    }
  } else if (is_vertex(tp.region)) {
    const std::int32_t v = surface_.triangle(t)[vertex_slot(tp.region)];
    if (features_.is_corner(v)) {
      where.kind = BoundaryLocation::Kind::Corner;
      where.feature = features_.corner_index(v);
    } else if (features_.feature_degree(v) > 0) {
      // A vertex inside a feature line: on the line, report its first feature edge.
      for (std::int32_t e : surface_.vertex_edges(v))
        if (features_.is_feature_edge(e)) {
          where.kind = BoundaryLocation::Kind::FeatureEdge;
          where.feature = features_.feature_edge_index(e);
          break;
        }
    }
  }
  return where;
}

ClosestPoint<3> SurfaceBoundary::to_closest(const AabbTree::Closest& c, const P3& p) const {
  ClosestPoint<3> out;
  out.point = c.where.point;
  out.distance = (c.where.point - p).norm();
  out.where = locate(c.triangle, c.where);
  return out;
}

ClosestPoint<3> SurfaceBoundary::closest_point(const P3& p) const {
  // The last answer on this thread as the search's hint: callers ask about nearby points in a
  // row (the tet optimiser's candidates around one node, the fidelity samples along a
  // triangle). The answer does not depend on it (AabbTree::closest), so neither the thread
  // count nor the order of calls changes any result.
  thread_local std::int32_t last = -1;
  const AabbTree::Closest c = tree_.closest(p, last);
  last = c.triangle;
  return to_closest(c, p);
}

std::vector<ClosestPoint<3>> SurfaceBoundary::closest_points(const P3& p, int max_count) const {
  std::vector<ClosestPoint<3>> out;
  if (max_count <= 0) return out;
  const AabbTree::Closest first = tree_.closest(p);
  out.push_back(to_closest(first, p));
  if (max_count == 1) return out;

  // A candidate is a local minimum of the distance on the surface when it lies inside a face,
  // or on an edge / at a vertex that no triangle around comes closer to.
  const double same = 1e-9 * diagonal_;
  auto distance_to = [&](std::int32_t u) {
    const auto& q = tree_.points(u);
    return (closest_on_triangle(p, q[0], q[1], q[2]).point - p).norm();
  };
  // Key of the landing element: (0 face | 1 edge | 2 vertex, id).
  auto key_of = [&](std::int32_t t, TriangleRegion r) {
    if (is_edge(r)) return std::pair<int, std::int32_t>{1, surface_.triangle_edge(t, edge_slot(r))};
    if (is_vertex(r)) return std::pair<int, std::int32_t>{2, surface_.triangle(t)[vertex_slot(r)]};
    return std::pair<int, std::int32_t>{0, t};
  };
  const auto first_key = key_of(first.triangle, first.where.region);
  double radius = std::max(2.0 * out[0].distance, 1e-3 * diagonal_);
  // Alternatives much farther than the nearest point are no use to a projection: search up to
  // max(3 d, d + 5% of the diagonal).
  const double max_radius = std::max(3.0 * out[0].distance, out[0].distance + 0.05 * diagonal_);
  radius = std::min(radius, max_radius);
  std::vector<std::tuple<double, std::pair<int, std::int32_t>, ClosestPoint<3>>> minima;
  for (;;) {
    minima.clear();
    std::vector<std::pair<int, std::int32_t>> seen{first_key};
    tree_.for_each_near(p, radius, [&](std::int32_t t) {
      const auto& q = tree_.points(t);
      const TrianglePoint tp = closest_on_triangle(p, q[0], q[1], q[2]);
      const double d = (tp.point - p).norm();
      if (d > radius) return;
      const auto key = key_of(t, tp.region);
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) return;
      bool local_min = true;
      if (key.first == 1) {
        local_min = distance_to(surface_.opposite_triangle(key.second, t)) >= d - same;
      } else if (key.first == 2) {
        for (std::int32_t u : surface_.vertex_triangles(key.second))
          if (distance_to(u) < d - same) local_min = false;
      }
      if (!local_min) return;
      seen.push_back(key);
      ClosestPoint<3> c;
      c.point = tp.point;
      c.distance = d;
      c.where = locate(t, tp);
      minima.emplace_back(d, key, c);
    });
    const int found = static_cast<int>(minima.size());
    if (found + 1 >= max_count || radius >= max_radius) break;
    radius = std::min(2.0 * radius, max_radius);
  }
  std::sort(minima.begin(), minima.end(), [](const auto& a, const auto& b) {
    return std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
  });
  for (const auto& m : minima) {
    if (static_cast<int>(out.size()) >= max_count) break;
    const ClosestPoint<3>& c = std::get<2>(m);
    // Round-off can split one minimum between a face and its edge: keep one.
    bool duplicate = false;
    for (const auto& o : out) duplicate = duplicate || (o.point - c.point).norm() <= same;
    if (!duplicate) out.push_back(c);
  }
  return out;
}

bool SurfaceBoundary::segment_crosses(const P3& a, const P3& b) const {
  // The open segment: its ends pulled in by 1e-9 of its length, so that a segment ending on the
  // surface (a node and its projection) does not count as crossing there.
  const P3 d = b - a;
  const P3 a1 = a + 1e-9 * d, b1 = b - 1e-9 * d;
  bool crosses = false;
  tree_.for_each_boxed_on_segment(a1, b1, [&](std::int32_t t) {
    if (crosses) return;
    const auto& q = tree_.points(t);
    crosses = segment_triangle(a1, b1, q[0], q[1], q[2]) != Crossing::Miss;
  });
  return crosses;
}

bool SurfaceBoundary::crosses_before(const P3& a, const P3& p) const {
  const double len = (p - a).norm();
  if (!(len > 0)) return false;
  const double short_by = std::max(1e-7, 1e-9 * diagonal_ / len);
  if (short_by >= 1.0) return false;
  return segment_crosses(a, a + (1.0 - short_by) * (p - a));
}

P3 SurfaceBoundary::pseudo_normal(std::int32_t t, TriangleRegion region) const {
  if (is_edge(region)) {
    const std::int32_t e = surface_.triangle_edge(t, edge_slot(region));
    P3 n = P3::Zero();
    for (std::int32_t u : surface_.edge_triangles(e)) n += surface_.normal(u);
    return n;
  }
  if (is_vertex(region)) {
    const std::int32_t v = surface_.triangle(t)[vertex_slot(region)];
    P3 n = P3::Zero();
    for (std::int32_t u : surface_.vertex_triangles(v)) {
      const Triangle& tr = surface_.triangle(u);
      const int i = tr[0] == v ? 0 : tr[1] == v ? 1 : 2;
      const P3 a = surface_.vertex(tr[(i + 1) % 3]) - surface_.vertex(v);
      const P3 b = surface_.vertex(tr[(i + 2) % 3]) - surface_.vertex(v);
      n += std::atan2(a.cross(b).norm(), a.dot(b)) * surface_.normal(u);
    }
    return n;
  }
  return surface_.normal(t);
}

bool SurfaceBoundary::is_inside_ref(const P3& p) const {
  const AabbTree::Closest c = tree_.closest(p);
  if (std::sqrt(c.distance2) <= 1e-12 * diagonal_) return false;  // on the surface: not strictly inside
  return (p - c.where.point).dot(pseudo_normal(c.triangle, c.where.region)) < 0.0;
}

bool SurfaceBoundary::is_inside(const P3& p) const {
  if (!surface_.bounding_box().contains(p)) return false;
  // Ray parity, majority of three rays that miss every edge and vertex by the tolerance.
  const double reach = 2.0 * diagonal_ + 1.0;
  int votes_in = 0, votes_out = 0;
  for (const P3& dir : ray_directions()) {
    const P3 far = p + reach * dir;
    int hits = 0;
    bool degenerate = false;
    tree_.for_each_boxed_on_segment(p, far, [&](std::int32_t t) {
      if (degenerate) return;
      const auto& q = tree_.points(t);
      const Crossing x = segment_triangle(p, far, q[0], q[1], q[2]);
      if (x == Crossing::Degenerate) degenerate = true;
      if (x == Crossing::Proper) ++hits;
    });
    if (degenerate) continue;
    (hits % 2 == 1 ? votes_in : votes_out) += 1;
    if (votes_in >= 2 || votes_out >= 2) break;
  }
  if (votes_in == votes_out) return is_inside_ref(p);  // every ray grazed: p is (nearly) on the surface
  return votes_in > votes_out;
}

Side SurfaceBoundary::classify(const Box<3>& box) const {
  // Enlarged a little: touching within round-off counts as meeting (PARTIAL is always safe).
  Box<3> grown = box;
  const double pad = 1e-9 * std::max(box.extent().maxCoeff(), diagonal_ * 1e-6);
  grown.lo.array() -= pad;
  grown.hi.array() += pad;
  if (tree_.overlaps(grown)) return Side::Partial;
  return is_inside(box.center()) ? Side::In : Side::Out;
}

bool SurfaceBoundary::feature_in_box(std::int32_t t, const Box<3>& box) const {
  for (int i = 0; i < 3; ++i) {
    const std::int32_t e = surface_.triangle_edge(t, i);
    if (features_.is_feature_edge(e)) {
      const Edge& ab = surface_.edge(e);
      if (AabbTree::segment_meets_box(surface_.vertices()[ab[0]], surface_.vertices()[ab[1]], box)) return true;
    }
    const std::int32_t v = surface_.triangle(t)[i];
    if (features_.is_corner(v) && box.contains(surface_.vertices()[v])) return true;
  }
  return false;
}

double SurfaceBoundary::control_level(const Box<3>& box) const {
  double level = std::min(options_.global_level, options_.max_level);
  const double feature_level = options_.global_level + options_.feature_extra_levels;
  const double cap =
      options_.thickness_cells > 0 ? std::max(options_.max_level, options_.thickness_max_level) : options_.max_level;
  tree_.for_each_in_box(box, [&](std::int32_t t) {
    if (level >= cap) return;
    const auto& q = tree_.points(t);
    const auto wanted_at = [&](bool feature, double thick_level) {
      return std::max(std::min(std::max(curvature_level_[t], feature ? feature_level : level), options_.max_level),
                      std::min(thick_level, options_.thickness_max_level));
    };
    bool feature = near_feature_[t];
    double wanted = wanted_at(feature, thickness_level_[t]);
    if (wanted <= level) return;
    if (!box_triangle_overlap(box, q[0], q[1], q[2])) return;
    if (feature && options_.feature_level_at_edges && !feature_in_box(t, box)) {
      feature = false;
      wanted = wanted_at(feature, thickness_level_[t]);
      if (wanted <= level) return;
    }
    if (!sample_begin_.empty() && sample_begin_[t + 1] > sample_begin_[t]) {
      // The thickness level of the samples near the box only.
      double thick_level = -std::numeric_limits<double>::infinity();
      const double reach2 = sample_reach_[t] * sample_reach_[t];
      for (std::int32_t k = sample_begin_[t]; k < sample_begin_[t + 1]; ++k) {
        if (!(sample_level_[k] > thick_level)) continue;
        const P3 d = (sample_point_[k].array().max(box.lo.array()).min(box.hi.array())).matrix() - sample_point_[k];
        if (d.squaredNorm() <= reach2) thick_level = sample_level_[k];
      }
      wanted = wanted_at(feature, thick_level);
      if (wanted <= level) return;
    }
    level = wanted;
  });
  return level;
}

}  // namespace febemesh::dim3
