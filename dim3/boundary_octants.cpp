#include "dim3/boundary_octants.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <tuple>

#include "core/cube_faces.hpp"
#include "core/error.hpp"
#include "core/lattice_nodes.hpp"
#include "core/parallel_ranges.hpp"
#include "dim3/triangle_predicates.hpp"

namespace febemesh::dim3 {
namespace {

using LP = LatticePoint<3>;

LP midpoint(const LP& a, const LP& b) { return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; }

/// The leaf of each of the eight octants around lattice point p (bit d set = upper side along
/// d), or no_leaf outside the root.
std::array<std::size_t, 8> octants_around(const LeafKeys<3>& keys, const LP& p) {
  std::array<std::size_t, 8> out;
  for (int o = 0; o < 8; ++o) {
    LP q = p;
    bool inside = true;
    for (int d = 0; d < 3; ++d) {
      if (corner_is_upper(o, d)) {
        inside = inside && q[d] < root_length<3>;
      } else {
        inside = inside && q[d] > 0;
        if (inside) q[d] -= 1;
      }
    }
    out[o] = inside ? keys.locate(q) : no_leaf;
  }
  return out;
}

/// The corners of `facets` (free facets of kept octants), ordered by key (deterministic), each
/// once.
std::vector<std::pair<std::uint64_t, LP>> facet_corners(const std::vector<FreeFacet<3>>& facets) {
  std::vector<std::pair<std::uint64_t, LP>> points;
  for (const FreeFacet<3>& f : facets)
    for (const LP& p : f.corners()) points.emplace_back(point_key<3>(p), p);
  // A key names its point: sorting by key alone leaves equal pairs together.
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  points.erase(std::unique(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
               points.end());
  return points;
}

/// Bit o set: octant o of octants_around is kept.
unsigned kept_mask(const std::array<std::size_t, 8>& around, const Flags& in) {
  unsigned kept = 0;
  for (int o = 0; o < 8; ++o)
    if (around[o] != no_leaf && in[around[o]]) kept |= 1u << o;
  return kept;
}

/// Clears in[i] for the leaves in `drop` (no_leaf and repeats allowed); returns the leaves it
/// cleared, in the order of `drop`.
std::vector<std::size_t> unkeep(const std::vector<std::size_t>& drop, Flags& in) {
  std::vector<std::size_t> cleared;
  for (std::size_t i : drop)
    if (i != no_leaf && in[i]) in[i] = 0, cleared.push_back(i);
  return cleared;
}

/// Face-connected components of the octants in `mask` within the 2x2x2 block (octants are
/// face-adjacent when their indices differ in one bit). comp[o] = component or -1.
int components(unsigned mask, std::array<int, 8>& comp) {
  comp.fill(-1);
  int n = 0;
  for (int s = 0; s < 8; ++s) {
    if (!((mask >> s) & 1) || comp[s] >= 0) continue;
    std::array<int, 8> stack{};
    int top = 0;
    stack[top++] = s;
    comp[s] = n;
    while (top > 0) {
      const int o = stack[--top];
      for (int d = 0; d < 3; ++d) {
        const int nb = o ^ (1 << d);
        if (((mask >> nb) & 1) && comp[nb] < 0) {
          comp[nb] = n;
          stack[top++] = nb;
        }
      }
    }
    ++n;
  }
  return n;
}

double face_size(const Orthtree<3>& t, const Cell<3>& c) { return length(c) * t.unit(); }

}  // namespace

std::vector<std::int32_t> face_ring(const LatticeNodes<3>& nodes, const Cell<3>& cell, int face,
                                    std::array<std::uint8_t, 4>& corner_slot) {
  std::vector<std::int32_t> ring;
  const auto& fc = FaceCorners<3>::corners[face];
  for (int k = 0; k < 4; ++k) {
    const LP a = corner(cell, fc[k]), b = corner(cell, fc[(k + 1) % 4]);
    corner_slot[k] = static_cast<std::uint8_t>(ring.size());
    ring.push_back(nodes.find(a));
    MESH_ASSERT(ring.back() >= 0, "free face corner is not a lattice node");
    if (length(cell) >= 2) {
      const std::int32_t m = nodes.find(midpoint(a, b));
      if (m >= 0) ring.push_back(m);
    }
  }
  return ring;
}

/// The octants a pass drops (collected with `in` as it stands, then dropped): look(p, drop) for
/// each of `points` in order, on n_threads threads (chunks' lists joined in order: the same list).
template <class Look>
std::vector<std::size_t> drops_at(const std::vector<std::pair<std::uint64_t, LP>>& points, int n_threads, const Look& look) {
  constexpr std::size_t chunk = 1 << 12;
  std::vector<std::vector<std::size_t>> part((points.size() + chunk - 1) / chunk);
  for_each_chunk(points.size(), chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) look(points[i].second, part[c]);
  });
  std::vector<std::size_t> drop;
  for (const auto& d : part) drop.insert(drop.end(), d.begin(), d.end());
  return drop;
}

std::size_t remove_pinches(const Orthtree<3>& t, Flags& in, int n_threads) {
  std::size_t removed = 0;
  const LeafKeys<3> keys(t);  // the leaves at a point from flat keys (the tree does not change)
  // The free facets once, then only around the octants each pass drops (update_free_facets:
  // the same list; every pass built them and the keys anew, a serial second of elephant L4's
  // two-thread run).
  std::vector<FreeFacet<3>> facets = free_facets(t, keys, in, n_threads);
  for (int pass = 0; pass < 64; ++pass) {
    const auto points = facet_corners(facets);
    const std::vector<std::size_t> to_drop = drops_at(points, n_threads, [&](const LP& p, std::vector<std::size_t>& drop) {
      const auto around = octants_around(keys, p);
      const unsigned kept = kept_mask(around, in);
      std::array<int, 8> ck{}, cu{};
      const int nk = components(kept, ck);
      const int nu = components(~kept & 0xffu, cu);
      if (nk > 1) {
        // Keep the largest kept component (ties: the one with the lowest octant), drop the rest.
        std::array<int, 8> size{};
        for (int o = 0; o < 8; ++o)
          if (ck[o] >= 0) ++size[ck[o]];
        int best = 0;
        for (int c = 1; c < nk; ++c)
          if (size[c] > size[best]) best = c;
        for (int o = 0; o < 8; ++o)
          if (ck[o] >= 0 && ck[o] != best) drop.push_back(around[o]);
      } else if (nu > 1) {
        // Open a passage between the unkept components: drop the first kept octant touching two.
        for (int o = 0; o < 8; ++o) {
          if (ck[o] < 0) continue;
          int first = -1;
          bool two = false;
          for (int d = 0; d < 3; ++d) {
            const int c = cu[o ^ (1 << d)];
            if (c < 0) continue;
            if (first < 0) first = c;
            else if (c != first) two = true;
          }
          if (two) {
            drop.push_back(around[o]);
            break;
          }
        }
      }
    });
    const std::vector<std::size_t> cleared = unkeep(to_drop, in);
    removed += cleared.size();
    if (cleared.empty()) break;
    update_free_facets(t, keys, in, cleared, facets);
  }
  return removed;
}

std::size_t remove_opposing(const Orthtree<3>& t, Flags& in, const std::function<double(const P3&)>& depth_at) {
  std::size_t removed = 0;
  std::map<std::size_t, double> depth;  // leaf -> distance of its centre to the surface (memo)
  const auto depth_of = [&](std::size_t leaf) {
    auto it = depth.find(leaf);
    if (it == depth.end()) {
      const Box<3> b = geometry(t, t.leaf(leaf));
      it = depth.emplace(leaf, depth_at(P3(0.5 * (b.lo + b.hi)))).first;
    }
    return it->second;
  };
  const LeafKeys<3> keys(t);
  for (int pass = 0; pass < 8; ++pass) {
    const auto points = facet_corners(free_facets(t, keys, in));
    std::vector<std::size_t> drop;
    for (const auto& [key, p] : points) {
      const auto around = octants_around(keys, p);
      const unsigned kept = kept_mask(around, in);
      for (int d = 0; d < 3; ++d) {
        // Kept octants with a free face at p facing -d (upper side along d, the lower one
        // unkept) and facing +d (the other way round).
        unsigned down = 0, up = 0;
        for (int o = 0; o < 8; ++o) {
          if (!((kept >> o) & 1u) || ((kept >> (o ^ (1 << d))) & 1u)) continue;
          if ((o >> d) & 1) down |= 1u << o;
          else up |= 1u << o;
        }
        if (down == 0 || up == 0) continue;
        // Drop the one of them nearest the surface (ties: the lower leaf).
        std::size_t best = no_leaf;
        double best_depth = 0.0;
        for (int o = 0; o < 8; ++o) {
          if (!(((down | up) >> o) & 1u)) continue;
          const double dep = depth_of(around[o]);
          if (best == no_leaf || dep < best_depth || (dep == best_depth && around[o] < best)) {
            best = around[o];
            best_depth = dep;
          }
        }
        drop.push_back(best);
        break;
      }
    }
    const std::size_t n = unkeep(drop, in).size();
    removed += n;
    if (n == 0) break;
  }
  return removed;
}

std::size_t keep_largest_components(const Orthtree<3>& t, Flags& in, int n_keep) {
  std::vector<std::int32_t> comp(t.n_leaves(), -1);
  std::vector<std::size_t> size;
  // Neighbours from the leaves' flat keys, searched from the leaf itself, into one reused list:
  // face_neighbours(t, i, f) from the root, a fresh vector each, was 0.17 s of the classify
  // stage at sphere966 level 6 (the most of it; serial).
  const LeafKeys<3> keys(t);
  std::vector<std::size_t> stack, near;
  for (std::size_t s0 = 0; s0 < t.n_leaves(); ++s0) {
    if (!in[s0] || comp[s0] >= 0) continue;
    const std::int32_t c = static_cast<std::int32_t>(size.size());
    std::size_t n = 0;
    stack.assign(1, s0);
    comp[s0] = c;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      ++n;
      for (int f = 0; f < Cube<3>::n_faces; ++f) {
        near.clear();
        keys.face_neighbours(i, f, near);
        for (std::size_t j : near)
          if (in[j] && comp[j] < 0) comp[j] = c, stack.push_back(j);
      }
    }
    size.push_back(n);
  }
  if (static_cast<int>(size.size()) <= n_keep) return 0;
  // The n_keep largest (ties: the first found) stay.
  std::vector<std::int32_t> order(size.size());
  for (std::size_t c = 0; c < size.size(); ++c) order[c] = static_cast<std::int32_t>(c);
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) { return size[a] > size[b]; });
  std::vector<std::uint8_t> keep(size.size(), 0);
  for (int k = 0; k < n_keep; ++k) keep[order[k]] = 1;
  std::size_t removed = 0;
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    if (in[i] && !keep[comp[i]]) in[i] = 0, ++removed;
  return removed;
}

bool enters_interior(const Orthtree<3>& t, const Flags& in, const P3& a, const P3& b, double graze, bool graze_region,
                     double graze_length) {
  return graze_region ? segment_enters_kept_region(t, in, a, b, graze, graze_length) : segment_enters_kept(t, in, a, b, graze);
}

std::size_t apply_buffer(const Orthtree<3>& t, Flags& in, const SurfaceBoundary& s, double fraction, int n_threads,
                         bool whole_face) {
  if (fraction <= 0) return 0;
  std::size_t removed = 0;
  for (int pass = 0; pass < 4; ++pass) {
    const std::vector<FreeFacet<3>> facets = free_facets(t, LeafKeys<3>(t), in, n_threads);
    std::vector<std::uint8_t> near(facets.size(), 0);
    for_each_range(facets.size(), n_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        const FreeFacet<3>& f = facets[k];
        const auto c = f.corners();
        const double h = face_size(t, f.cell);
        P3 centre = P3::Zero();
        double d = whole_face ? 0.0 : std::numeric_limits<double>::infinity();
        const auto take = [&](double x) { d = whole_face ? std::max(d, x) : std::min(d, x); };
        for (const LP& p : c) {
          const P3 x = position(t, p);
          centre += 0.25 * x;
          take(s.closest_point(x).distance);
        }
        take(s.closest_point(centre).distance);
        near[k] = d < fraction * h ? 1 : 0;
      }
    });
    std::vector<std::size_t> drop;
    for (std::size_t k = 0; k < facets.size(); ++k)
      if (near[k]) drop.push_back(facets[k].leaf);
    std::sort(drop.begin(), drop.end());
    drop.erase(std::unique(drop.begin(), drop.end()), drop.end());
    if (drop.empty()) break;
    for (std::size_t i : drop) in[i] = 0;
    removed += drop.size();
  }
  return removed;
}

namespace {

/// The component of `v` along the outward normal of cube face f (f = 2 * axis + side).
double along_face(const P3& v, int f) { return ((f % 2) ? 1.0 : -1.0) * v[f / 2]; }

struct Projector {
  const Orthtree<3>& tree;
  const Flags& in;
  const SurfaceBoundary& surface;
  double graze = 1e-9;

  double min_outward = -1.0;  // BoundaryOctantOptions
  double min_facing = -1.0;
  bool outward_all_faces = false;
  bool graze_region = false;  // BoundaryOctantOptions::graze_region, graze_length
  double graze_length = 0.0;
  double backward_along = 0.0;  // BoundaryOctantOptions::backward_along

  /// The segment from q to a surface point p (on triangle `patch`, -1 = unknown) leaves through
  /// one of q's free faces (`dirs`, bit f = face f) and lands on a side of the surface facing
  /// that way (leaves_outward), enters no interior octant and does not cross the surface before
  /// reaching p.
  bool admissible(const P3& q, const P3& p, std::uint8_t dirs = 0, std::int32_t patch = -1) const {
    if (dirs != 0 && !leaves_outward(q, p, dirs, patch)) return false;
    if (enters_interior(tree, in, q, p, graze, graze_region, graze_length)) return false;
    if (graze_region && backward_along > 0 && dirs != 0 && runs_back_along(q, p, dirs)) return false;
    return !surface.crosses_before(q, p);
  }
  /// The segment from q to p runs back against one of q's free faces (cosine -0.5 or less)
  /// and along the interior octants for more than backward_along octant sizes.
  bool runs_back_along(const P3& q, const P3& p, std::uint8_t dirs) const {
    const P3 d = p - q;
    const double len = d.norm();
    if (len <= 0) return false;
    bool back = false;
    for (int f = 0; f < Cube<3>::n_faces; ++f)
      if (((dirs >> f) & 1) && along_face(d, f) / len <= -0.5) back = true;
    return back && cells_along_kept(tree, in, q, p, graze) > backward_along;
  }
  /// Some free face f of q has cos(p - q, n_f) >= min_outward and cos(n_p, n_f) >= min_facing:
  /// a projection that runs back along the interior octants, or lands on the far side of a part
  /// thinner than the octants (the surface facing away from all of q's free faces), would fold
  /// its boundary octant.
  bool leaves_outward(const P3& q, const P3& p, std::uint8_t dirs, std::int32_t patch) const {
    const P3 d = p - q;
    const double len = d.norm();
    if (len <= 0) return true;
    const P3 np = patch >= 0 ? P3(surface.surface().normal(patch).normalized()) : P3(P3::Zero());
    if (outward_all_faces) {
      bool facing = min_facing <= -1.0 || patch < 0;
      for (int f = 0; f < Cube<3>::n_faces; ++f) {
        if (!((dirs >> f) & 1)) continue;
        if (along_face(d, f) / len < min_outward) return false;
        if (along_face(np, f) >= min_facing) facing = true;
      }
      return facing;
    }
    for (int f = 0; f < Cube<3>::n_faces; ++f) {
      if (!((dirs >> f) & 1)) continue;
      if (along_face(d, f) / len < min_outward) continue;
      if (patch >= 0 && along_face(np, f) < min_facing) continue;
      return true;
    }
    return false;
  }
};

/// Inserts the free faces' corners missing from `nodes` (keeping points sorted by key).
void add_face_corners(LatticeNodes<3>& nodes, const std::vector<FreeFacet<3>>& facets) {
  std::vector<std::uint64_t> extra;
  for (const FreeFacet<3>& f : facets)
    for (const LP& p : f.corners())
      if (nodes.find(p) < 0) extra.push_back(point_key<3>(p));
  if (extra.empty()) return;
  for (const LP& p : nodes.points) extra.push_back(point_key<3>(p));
  std::sort(extra.begin(), extra.end());
  extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
  nodes.points.clear();
  for (std::uint64_t k : extra) nodes.points.push_back(point_from_key<3>(k));
  nodes.hanging.assign(nodes.points.size(), 0);  // not used past this point
  decltype(nodes.leaf_corners)().swap(nodes.leaf_corners);  // stale now (and freed already)
}

}  // namespace

bool first_hit(const SurfaceBoundary& s, const P3& q, const P3& end, P3& hit) {
  double best = std::numeric_limits<double>::infinity();
  s.tree().for_each_on_segment(q, end, [&](std::int32_t t) {
    const auto& v = s.tree().points(t);
    const double tt = line_triangle_parameter(q, end, v[0], v[1], v[2]);
    if (tt > 0 && tt <= 1 && tt < best) best = tt;
  });
  if (!std::isfinite(best)) return false;
  hit = q + best * (end - q);
  return true;
}

namespace {

/// The paper's "other normals": the outward normals of a node's free faces (`dirs`, bit f =
/// face f), their sum first.
std::vector<P3> ray_directions(std::uint8_t dirs) {
  std::vector<P3> rays;
  P3 sum = P3::Zero();
  for (int f = 0; f < 6; ++f)
    if ((dirs >> f) & 1) sum += facet_normal<3>(f);
  if (sum.norm() > 0) rays.push_back(sum.normalized());
  for (int f = 0; f < 6; ++f)
    if ((dirs >> f) & 1) rays.push_back(facet_normal<3>(f));
  return rays;
}

/// The surface point where the ray from q along `dir` first meets the surface within `reach`
/// (its closest point, with the distance from q), if it does.
bool ray_surface_point(const SurfaceBoundary& s, const P3& q, const P3& dir, double reach, ClosestPoint<3>& out) {
  P3 hit;
  if (!first_hit(s, q, q + reach * dir, hit)) return false;
  out = s.closest_point(hit);
  out.distance = (out.point - q).norm();
  return true;
}

/// The first admissible surface point along the rays from q in ray_directions(dirs).
bool ray_projection(const SurfaceBoundary& s, const Projector& proj, const P3& q, std::uint8_t dirs, double reach,
                    ClosestPoint<3>& out) {
  for (const P3& dir : ray_directions(dirs)) {
    ClosestPoint<3> cp;
    if (!ray_surface_point(s, q, dir, reach, cp) || !proj.admissible(q, cp.point, dirs, cp.where.patch)) continue;
    out = cp;
    return true;
  }
  return false;
}

/// The worst cosine between the segment q..p and the outward normals of q's free faces (`dirs`,
/// bit f = face f); 1 when p = q or q has no free face. Negative: the projection runs back
/// against one of the faces, and the boundary octant of that face folds (diagnose3d "backward").
double worst_outward(const P3& q, const P3& p, std::uint8_t dirs) {
  const P3 d = p - q;
  const double len = d.norm();
  double worst = 1.0;
  if (!(len > 0)) return worst;
  for (int f = 0; f < Cube<3>::n_faces; ++f)
    if ((dirs >> f) & 1) worst = std::min(worst, along_face(d, f) / len);
  return worst;
}

/// Other surface points for node q than its closest: the next local minima of the distance
/// (up to max_normals in all) and, with `rays`, the surface points along its free faces'
/// normals and their sum (ray_directions) within `reach`.
std::vector<ClosestPoint<3>> other_projections(const SurfaceBoundary& s, const P3& q, std::uint8_t dirs, double reach,
                                               int max_normals, bool rays) {
  std::vector<ClosestPoint<3>> out = s.closest_points(q, max_normals);
  if (!out.empty()) out.erase(out.begin());
  if (rays)
    for (const P3& dir : ray_directions(dirs)) {
      ClosestPoint<3> c;
      if (ray_surface_point(s, q, dir, reach, c)) out.push_back(c);
    }
  return out;
}

/// Feature line segments bucketed on a uniform grid, for "nearest feature line point" queries.
class FeatureGrid {
 public:
  FeatureGrid(const Features& f, double cell) : f_(f), cell_(cell) {
    for (std::int32_t l = 0; l < static_cast<std::int32_t>(f.lines().size()); ++l) {
      const FeatureLine& line = f.lines()[l];
      for (std::int32_t k = 0; k + 1 < static_cast<std::int32_t>(line.points.size()); ++k) {
        Box<3> b = Box<3>::empty();
        b.expand(line.points[k]);
        b.expand(line.points[k + 1]);
        const auto lo = key(b.lo), hi = key(b.hi);
        for (long x = lo[0]; x <= hi[0]; ++x)
          for (long y = lo[1]; y <= hi[1]; ++y)
            for (long z = lo[2]; z <= hi[2]; ++z) grid_[{x, y, z}].push_back({l, k});
      }
    }
  }
  /// Nearest point on a feature line within about one grid cell of p (distance inf if none).
  Features::LinePoint nearest(const P3& p, std::int32_t& line_out) const {
    Features::LinePoint best;
    best.distance = std::numeric_limits<double>::infinity();
    line_out = -1;
    const auto c = key(p);
    for (long x = c[0] - 1; x <= c[0] + 1; ++x)
      for (long y = c[1] - 1; y <= c[1] + 1; ++y)
        for (long z = c[2] - 1; z <= c[2] + 1; ++z) {
          const auto it = grid_.find({x, y, z});
          if (it == grid_.end()) continue;
          for (const auto& [l, k] : it->second) {
            const FeatureLine& line = f_.lines()[l];
            const P3 a = line.points[k], b = line.points[k + 1];
            const P3 ab = b - a;
            const double len2 = ab.squaredNorm();
            const double tt = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
            const P3 q = a + tt * ab;
            const double d = (q - p).norm();
            if (d < best.distance) {
              best.point = q;
              best.distance = d;
              best.segment = k;
              best.t = tt;
              line_out = l;
            }
          }
        }
    return best;
  }

 private:
  std::array<long, 3> key(const P3& p) const {
    return {static_cast<long>(std::floor(p[0] / cell_)), static_cast<long>(std::floor(p[1] / cell_)),
            static_cast<long>(std::floor(p[2] / cell_))};
  }
  const Features& f_;
  double cell_;
  std::map<std::array<long, 3>, std::vector<std::pair<std::int32_t, std::int32_t>>> grid_;
};


/// The surface face of boundary octant b as the templates will see it: the smallest triangle
/// angle (radians) of its better diagonal, or of its triangle; +inf for the fanned ones (more
/// than four distinct projections), which the templates split from a surface point.
double surface_face_angle(const OctantComplex& oc, const BoundaryOctant& b) {
  std::vector<std::int32_t> pr;
  for (const std::int32_t q : b.ring)
    if (pr.empty() || pr.back() != oc.projection[q]) pr.push_back(oc.projection[q]);
  while (pr.size() > 1 && pr.back() == pr.front()) pr.pop_back();
  const auto angle = [&](std::int32_t i, std::int32_t j, std::int32_t k) {
    const P3 &a = oc.points[i], &c = oc.points[j], &d = oc.points[k];
    const auto at = [](const P3& o, const P3& u, const P3& v) {
      const P3 x = u - o, y = v - o;
      return x.norm() * y.norm() > 0 ? std::atan2(x.cross(y).norm(), x.dot(y)) : 0.0;
    };
    return std::min({at(a, c, d), at(c, d, a), at(d, a, c)});
  };
  if (pr.size() == 3) return angle(pr[0], pr[1], pr[2]);
  if (pr.size() != 4) return std::numeric_limits<double>::infinity();
  return std::max(std::min(angle(pr[0], pr[1], pr[2]), angle(pr[0], pr[2], pr[3])),
                  std::min(angle(pr[0], pr[1], pr[3]), angle(pr[1], pr[2], pr[3])));
}

/// How many cones of boundary octant b (from the centroid of its distinct corner nodes over its
/// faces, each quad split both ways, hanging midpoints left out) are not positive: a cheap
/// stand-in for the templates' tetrahedra, to see whether moving a projection folds the octant.
int folded_cones(const OctantComplex& oc, const BoundaryOctant& b) {
  std::array<std::int32_t, 4> q{}, p{};
  for (int c = 0; c < 4; ++c) q[c] = b.ring[b.corner_slot[c]], p[c] = oc.projection[q[c]];
  std::vector<std::int32_t> distinct = {q[0], q[1], q[2], q[3], p[0], p[1], p[2], p[3]};
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  P3 apex = P3::Zero();
  for (const std::int32_t v : distinct) apex += oc.points[v];
  apex /= static_cast<double>(distinct.size());
  int n = 0;
  const auto cone = [&](std::int32_t i, std::int32_t j, std::int32_t k) {
    if (i == j || j == k || k == i) return;
    const P3 &a = oc.points[i], &b1 = oc.points[j], &c = oc.points[k];
    n += (c - a).dot((b1 - a).cross(apex - a)) > 0 ? 0 : 1;
  };
  const auto quad = [&](std::int32_t a, std::int32_t b1, std::int32_t c, std::int32_t d) {
    cone(a, b1, c), cone(a, c, d), cone(a, b1, d), cone(b1, c, d);
  };
  quad(q[0], q[3], q[2], q[1]);  // the face, seen from the boundary octant's outside
  quad(p[0], p[1], p[2], p[3]);  // the surface face
  for (int i = 0; i < 4; ++i) quad(q[i], q[(i + 1) % 4], p[(i + 1) % 4], p[i]);
  return n;
}

/// Is the surface's edge e concave (the solid's angle there above 180 deg)? Only there do the
/// closest points of the lattice nodes inside the wedge all fall on the edge.
bool is_concave(const Surface& surf, std::int32_t e) {
  const auto tris = surf.edge_triangles(e);
  if (tris.size() != 2) return false;
  const Triangle& t1 = surf.triangle(tris[1]);
  for (const std::int32_t v : t1)
    if (v != surf.edge(e)[0] && v != surf.edge(e)[1])
      return surf.normal(tris[0]).dot(surf.vertex(v) - surf.vertex(surf.edge(e)[0])) > 0;
  return false;
}

/// The surface nodes that feature snapping left on a concave line because snapped ones crowd it
/// (within half of `off_line` face sizes of the line) move `off_line` face sizes into one of the two
/// faces at the line: the one they already lean into, else the one facing their lattice nodes'
/// free faces (`outward`). Each move lands on the surface (closest point), is admissible from
/// all its face nodes, raises the worst angle of the surface faces around the node (if that is
/// below `max_face_angle`, radians) and folds none of their octants' cones (folded_cones) that
/// were not folded, else the node stays.
template <class SizeFn, class CrowdFn, class AdmissibleFn, class OutwardFn>
void push_off_lines(const SurfaceBoundary& s, OctantComplex& oc, std::int32_t n_lat,
                    const std::vector<Features::LinePoint>& hit, const std::vector<std::int32_t>& hit_line,
                    const SizeFn& surface_h, const CrowdFn& is_crowded, const AdmissibleFn& admissible_from_all,
                    const OutwardFn& outward, double off_line, double max_face_angle, BoundaryOctantStats& stats) {
  const Features& feat = s.features();
  const Surface& surf = s.surface();
  std::vector<std::vector<std::int32_t>> octants_of(oc.points.size() - n_lat);  // per surface node
  for (std::size_t k = 0; k < oc.boundary.size(); ++k)
    for (const std::int32_t q : oc.boundary[k].ring) {
      std::vector<std::int32_t>& list = octants_of[oc.projection[q] - n_lat];
      if (list.empty() || list.back() != static_cast<std::int32_t>(k)) list.push_back(static_cast<std::int32_t>(k));
    }
  for (std::int32_t p = n_lat; p < static_cast<std::int32_t>(oc.points.size()); ++p) {
    if (oc.snapped[p] || hit_line[p] < 0 || hit[p].segment < 0) continue;
    const double h = surface_h(p);
    if (!(hit[p].distance < 0.5 * off_line * h) || !is_crowded(hit[p].point, h)) continue;
    const FeatureLine& line = feat.lines()[hit_line[p]];
    const std::int32_t e = line.edges[hit[p].segment];
    if (!is_concave(surf, e)) continue;
    const P3 along = (line.points[hit[p].segment + 1] - line.points[hit[p].segment]).normalized();
    const P3 lean = oc.points[p] - hit[p].point;
    const P3 out = outward(p);
    double best_score = -std::numeric_limits<double>::infinity();
    P3 best_dir = P3::Zero();
    for (const std::int32_t tri : surf.edge_triangles(e)) {
      // Into the triangle, perpendicular to the line, in its plane.
      P3 w = surf.normal(tri).cross(along);
      P3 opposite = P3::Zero();
      for (const std::int32_t v : surf.triangle(tri)) opposite += surf.vertex(v) / 3.0;
      if (w.dot(opposite - line.points[hit[p].segment]) < 0) w = -w;
      if (!(w.norm() > 0)) continue;
      w.normalize();
      const double score = lean.norm() > 1e-9 * h ? w.dot(lean) : surf.normal(tri).dot(out);
      if (score > best_score) best_score = score, best_dir = w;
    }
    if (!(best_dir.norm() > 0)) continue;
    // Only a node with a bad surface face around it (its worst angle), and kept only if that
    // gets better.
    const auto worst_face = [&] {
      double w = std::numeric_limits<double>::infinity();
      for (const std::int32_t k : octants_of[p - n_lat]) w = std::min(w, surface_face_angle(oc, oc.boundary[k]));
      return w;
    };
    const double before = worst_face();
    if (!(before < max_face_angle)) continue;
    const ClosestPoint<3> on = s.closest_point(hit[p].point + off_line * h * best_dir);
    if (!admissible_from_all(p, P3(on.point))) continue;
    const P3 old_point = oc.points[p];
    const auto folded = [&] {
      int n = 0;
      for (const std::int32_t k : octants_of[p - n_lat]) n += folded_cones(oc, oc.boundary[k]);
      return n;
    };
    const int folded_before = folded();
    oc.points[p] = on.point;
    if (!(worst_face() > before) || folded() > folded_before) {
      oc.points[p] = old_point;
      continue;
    }
    oc.where[p] = on.where;
    oc.snapped[p] = 3;
    ++stats.n_pushed_off_lines;
  }
}

/// A surface node p whose projection runs back against a free face of one of its face nodes
/// (worst_outward < 0) and folds cones of their boundary octants (folded_cones) moves to the
/// candidate (other_projections of its face nodes, admissible from all of them, not another
/// surface node's point) that folds fewest of those cones, if fewer (ties: the larger worst
/// worst_outward). In node order, one at a time (a move changes its neighbours' octants), so
/// the same for every thread count.
void unfold_backward(const SurfaceBoundary& s, const Projector& proj, const std::vector<std::uint8_t>& node_dirs,
                     const std::vector<double>& node_h, const BoundaryOctantOptions& opt,
                     const std::vector<std::vector<std::int32_t>>& sources,
                     std::map<std::tuple<double, double, double>, std::int32_t>& by_point, OctantComplex& oc,
                     BoundaryOctantStats& stats) {
  const std::int32_t n_lat = oc.n_lattice();
  const std::int32_t n_pts = static_cast<std::int32_t>(oc.points.size());
  std::vector<std::vector<std::int32_t>> octants_of(n_pts - n_lat);  // per surface node: its boundary octants
  for (std::size_t k = 0; k < oc.boundary.size(); ++k)
    for (const std::int32_t q : oc.boundary[k].ring) {
      std::vector<std::int32_t>& list = octants_of[oc.projection[q] - n_lat];
      if (list.empty() || list.back() != static_cast<std::int32_t>(k)) list.push_back(static_cast<std::int32_t>(k));
    }
  for (std::int32_t p = n_lat; p < n_pts; ++p) {
    const std::vector<std::int32_t>& from = sources[p - n_lat];
    const auto worst = [&](const P3& x) {
      double w = 1.0;
      for (const std::int32_t q : from) w = std::min(w, worst_outward(oc.points[q], x, node_dirs[q]));
      return w;
    };
    const P3 old_point = oc.points[p];
    double best_out = worst(old_point);
    if (!(best_out < 0)) continue;
    const auto folded = [&] {
      int n = 0;
      for (const std::int32_t k : octants_of[p - n_lat]) n += folded_cones(oc, oc.boundary[k]);
      return n;
    };
    int best = folded();
    if (best == 0) continue;
    std::optional<ClosestPoint<3>> pick;
    for (const std::int32_t q0 : from)
      for (const ClosestPoint<3>& c :
           other_projections(s, oc.points[q0], node_dirs[q0], 4.0 * node_h[q0], opt.max_normals, opt.rays)) {
        if (by_point.count(std::make_tuple(c.point[0], c.point[1], c.point[2]))) continue;
        bool ok = true;
        for (const std::int32_t q : from) ok = ok && proj.admissible(oc.points[q], c.point, node_dirs[q], c.where.patch);
        if (!ok) continue;
        oc.points[p] = c.point;
        const int n = folded();
        const double out = worst(c.point);
        if (n < best || (n == best && pick && out > best_out)) best = n, best_out = out, pick = c;
      }
    oc.points[p] = old_point;
    if (!pick) continue;
    by_point.erase(std::make_tuple(old_point[0], old_point[1], old_point[2]));
    by_point.emplace(std::make_tuple(pick->point[0], pick->point[1], pick->point[2]), p);
    oc.points[p] = pick->point;
    oc.where[p] = pick->where;
    ++stats.n_unfolded;
  }
}

}  // namespace

OctantComplexResult build_octant_complex(const Orthtree<3>& t, const Flags& in, const SurfaceBoundary& s,
                                         const BoundaryOctantOptions& opt) {
  OctantComplexResult res;
  OctantComplex& oc = res.complex;
  oc.lattice = lattice_nodes(t, &in, HangingFlags::Computed, opt.n_threads);
  // The leaves' corner ids (32 B a leaf) serve the 2D quadrants only; held here they were 8.4 MB
  // of the pipeline's heap peak in the templates (sphere966 at 995,232 tetrahedra, massif).
  decltype(oc.lattice.leaf_corners)().swap(oc.lattice.leaf_corners);
  const std::vector<FreeFacet<3>> facets = free_facets(t, LeafKeys<3>(t), in, opt.n_threads);
  // A sub-face left by an unkept finer neighbour may have corners that are no kept octant's
  // corner (the middle of a coarse edge): they become nodes too, so that the faces around them
  // (templates, boundary octants) all see them.
  add_face_corners(oc.lattice, facets);
  const std::int32_t n_lat = oc.n_lattice();
  oc.points.reserve(n_lat);
  for (const LP& p : oc.lattice.points) oc.points.push_back(position(t, p));
  oc.where.assign(n_lat, BoundaryLocation{});
  oc.projection.assign(n_lat, -1);
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    if (in[i]) oc.interior.push_back(i);

  res.stats.n_free_faces = facets.size();
  std::vector<double> node_h(n_lat, std::numeric_limits<double>::infinity());
  std::vector<std::uint8_t> node_dirs(n_lat, 0);  // outward axis directions of the free faces
  for (const FreeFacet<3>& f : facets) {
    BoundaryOctant b;
    b.leaf = f.leaf;
    b.cell = f.cell;
    b.face = f.face;
    b.ring = face_ring(oc.lattice, f.cell, f.face, b.corner_slot);
    const double h = face_size(t, f.cell);
    for (std::int32_t q : b.ring) {
      node_h[q] = std::min(node_h[q], h);
      node_dirs[q] |= std::uint8_t(1u << f.face);
    }
    oc.boundary.push_back(std::move(b));
  }

  // Project every face node (closest point, then the next local minima; paper eq. 1 with the
  // crossing rule). Equal projections share one surface node.
  Projector proj{t, in, s, opt.graze, opt.min_outward, opt.min_facing, opt.outward_all_faces, opt.graze_region,
                 opt.graze_length, opt.backward_along};
  // Each node's projection depends on the node alone: found on opt.n_threads threads, then
  // counted, shared and numbered in node order (the same nodes for every thread count).
  enum class How : std::uint8_t { none, closest, next_normal, ray, blind, problem };
  std::vector<ClosestPoint<3>> found(static_cast<std::size_t>(n_lat));
  std::vector<How> how(static_cast<std::size_t>(n_lat), How::none);
  for_each_range(static_cast<std::size_t>(n_lat), opt.n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t q = begin; q < end; ++q) {
      if (!std::isfinite(node_h[q])) continue;
      ClosestPoint<3>& cp = found[q];
      cp = s.closest_point(oc.points[q]);
      how[q] = How::closest;
      if (std::abs(worst_outward(oc.points[q], cp.point, node_dirs[q])) < opt.in_plane_cosine) {
        const std::vector<P3> dirs = ray_directions(node_dirs[q]);
        ClosestPoint<3> c;
        if (dirs.size() > 2 && ray_surface_point(s, oc.points[q], dirs[0], 4.0 * node_h[q], c) &&
            proj.admissible(oc.points[q], c.point, node_dirs[q], c.where.patch)) {
          cp = c;
          how[q] = How::ray;
          continue;
        }
      }
      if (proj.admissible(oc.points[q], cp.point, node_dirs[q], cp.where.patch)) continue;
      // The next local minima of the distance, then rays along the free faces' normals.
      const std::vector<ClosestPoint<3>> cands = s.closest_points(oc.points[q], opt.max_normals);
      std::size_t pick = cands.size();
      for (std::size_t k = 1; k < cands.size() && pick == cands.size(); ++k)
        if (proj.admissible(oc.points[q], cands[k].point, node_dirs[q], cands[k].where.patch)) pick = k;
      if (pick < cands.size()) {
        cp = cands[pick];
        how[q] = How::next_normal;
      } else if (opt.rays && ray_projection(s, proj, oc.points[q], node_dirs[q], 4.0 * node_h[q], cp)) {
        how[q] = How::ray;
      } else {
        // Keep the closest point (blind_closest): the untangling of the templates decides
        // (pipeline3d).
        how[q] = opt.blind_closest ? How::blind : How::problem;
      }
    }
  });
  std::map<std::tuple<double, double, double>, std::int32_t> by_point;
  std::vector<std::vector<std::int32_t>> sources;  // per surface node - n_lat: its face nodes
  for (std::int32_t q = 0; q < n_lat; ++q) {
    if (how[q] == How::none) continue;
    ++res.stats.n_face_nodes;
    const ClosestPoint<3>& cp = found[q];
    if (how[q] == How::next_normal) ++res.stats.n_next_normal;
    if (how[q] == How::ray) ++res.stats.n_ray;
    if (how[q] == How::blind) ++res.stats.n_blind;
    if (how[q] == How::problem) {
      res.problems.push_back({oc.points[q], "no admissible projection onto the surface", true});
      continue;
    }
    const auto key = std::make_tuple(cp.point[0], cp.point[1], cp.point[2]);
    const auto it = by_point.find(key);
    if (it != by_point.end()) {
      oc.projection[q] = it->second;
      sources[it->second - n_lat].push_back(q);
      ++res.stats.n_shared_projections;
      continue;
    }
    const std::int32_t id = static_cast<std::int32_t>(oc.points.size());
    oc.points.push_back(cp.point);
    oc.where.push_back(cp.where);
    by_point.emplace(key, id);
    sources.push_back({q});
    oc.projection[q] = id;
  }
  res.stats.n_surface_nodes = sources.size();
  if (opt.unfold_backward && res.problems.empty())
    unfold_backward(s, proj, node_dirs, node_h, opt, sources, by_point, oc, res.stats);
  oc.snapped.assign(oc.points.size(), 0);
  oc.unsnapped = oc.points;
  if (!res.problems.empty() || !opt.snap_features) return res;

  const auto surface_h = [&](std::int32_t p) {
    double h = std::numeric_limits<double>::infinity();
    for (std::int32_t q : sources[p - n_lat]) h = std::min(h, node_h[q]);
    return h;
  };
  const auto admissible_from_all = [&](std::int32_t p, const P3& target) {
    for (std::int32_t q : sources[p - n_lat])
      if (!proj.admissible(oc.points[q], target, node_dirs[q])) return false;
    return true;
  };

  // Corners: the nearest surface node within corner_radius face sizes moves onto the corner.
  const Features& feat = s.features();
  const std::int32_t n_pts = static_cast<std::int32_t>(oc.points.size());
  for (std::int32_t c = 0; c < feat.n_corners(); ++c) {
    const P3& cp = feat.corner_points()[c];
    std::int32_t best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (std::int32_t p = n_lat; p < n_pts; ++p) {
      const double d = (oc.points[p] - cp).norm();
      if (d < best_d && oc.snapped[p] != 2) best_d = d, best = p;
    }
    if (best < 0 || best_d > opt.corner_radius * surface_h(best) || !admissible_from_all(best, cp)) {
      ++res.stats.n_corners_missed;
      continue;
    }
    oc.points[best] = cp;
    oc.where[best].kind = BoundaryLocation::Kind::Corner;
    oc.where[best].feature = c;
    const std::int32_t v = feat.corners()[c];
    const std::int32_t tri = s.surface().vertex_triangles(v).front();
    const Triangle& tv = s.surface().triangle(tri);
    oc.where[best].patch = tri;
    oc.where[best].param[0] = tv[1] == v ? 1.0 : 0.0;
    oc.where[best].param[1] = tv[2] == v ? 1.0 : 0.0;
    oc.snapped[best] = 2;
    ++res.stats.n_corners_snapped;
  }

  // Feature lines: nodes within edge_radius face sizes of a line move onto it, unless a node
  // already snapped nearby (both sides of a sharp edge must not collapse onto one point).
  if (feat.n_feature_edges() > 0) {
    double h_med = 0.0;
    {
      std::vector<double> hs;
      for (std::int32_t p = n_lat; p < n_pts; ++p) hs.push_back(surface_h(p));
      std::nth_element(hs.begin(), hs.begin() + hs.size() / 2, hs.end());
      h_med = hs.empty() ? 1.0 : hs[hs.size() / 2];
    }
    const FeatureGrid grid(feat, std::max(h_med, 1e-300));
    std::vector<std::pair<double, std::int32_t>> order;  // nearest first
    std::vector<Features::LinePoint> hit(oc.points.size());
    std::vector<std::int32_t> hit_line(oc.points.size(), -1);
    for (std::int32_t p = n_lat; p < n_pts; ++p) {
      if (oc.snapped[p]) continue;
      std::int32_t line = -1;
      hit[p] = grid.nearest(oc.points[p], line);
      hit_line[p] = line;
      if (line >= 0 && hit[p].distance > 0 && hit[p].distance < opt.edge_radius * surface_h(p))
        order.push_back({hit[p].distance, p});
    }
    std::sort(order.begin(), order.end());
    // Snapped targets on a grid of spacing about a third of the face size, to keep snapped
    // nodes apart.
    std::map<std::array<long, 3>, std::vector<P3>> taken;  // bucketed by h_med
    const auto bucket = [&](const P3& x) {
      return std::array<long, 3>{static_cast<long>(std::floor(x[0] / h_med)),
                                 static_cast<long>(std::floor(x[1] / h_med)),
                                 static_cast<long>(std::floor(x[2] / h_med))};
    };
    for (std::int32_t p = n_lat; p < n_pts; ++p)
      if (oc.snapped[p]) taken[bucket(oc.points[p])].push_back(oc.points[p]);
    const auto is_crowded = [&](const P3& target, double h) {
      const auto c = bucket(target);
      for (long x = c[0] - 1; x <= c[0] + 1; ++x)
        for (long y = c[1] - 1; y <= c[1] + 1; ++y)
          for (long z = c[2] - 1; z <= c[2] + 1; ++z) {
            const auto it = taken.find({x, y, z});
            if (it == taken.end()) continue;
            for (const P3& other : it->second)
              if ((other - target).norm() < 0.3 * h) return true;
          }
      return false;
    };
    for (const auto& [d, p] : order) {
      const P3 target = hit[p].point;
      if (is_crowded(target, surface_h(p)) || !admissible_from_all(p, target)) continue;
      const ClosestPoint<3> on = s.closest_point(target);
      oc.points[p] = target;
      oc.where[p] = on.where;
      oc.where[p].kind = BoundaryLocation::Kind::FeatureEdge;
      oc.snapped[p] = 1;
      taken[bucket(target)].push_back(target);
      ++res.stats.n_edge_snapped;
    }
    // Not with the facing rule (min_facing), the pipeline's last try: fandisk L4 is valid there
    // only through four repairs, and with the pushes (5 on its first tree, 26 -> 14 places to
    // repair) the repair loop stops after one (14 -> 15 places, "made it worse").
    if (opt.off_line > 0 && opt.min_facing < 0) {
      // The outward directions of a surface node's lattice nodes' free faces, summed.
      const auto outward = [&](std::int32_t p) {
        P3 d = P3::Zero();
        for (std::int32_t q : sources[p - n_lat])
          for (int f = 0; f < Cube<3>::n_faces; ++f)
            if (node_dirs[q] >> f & 1) d += facet_normal<3>(f);
        return d;
      };
      push_off_lines(s, oc, n_lat, hit, hit_line, surface_h, is_crowded, admissible_from_all, outward, opt.off_line,
                     opt.off_line_below_deg * 3.14159265358979323846 / 180.0, res.stats);
    }
  }
  return res;
}

}  // namespace febemesh::dim3
