#include "dim3/surface_checks.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numeric>
#include <optional>
#include <queue>
#include <sstream>

#include "core/error.hpp"

namespace febemesh::dim3 {

namespace {

std::string fmt(const P3& p) {
  std::ostringstream os;
  os << std::setprecision(9) << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

std::string fmt_edge(const Surface& s, std::int32_t e) {
  return fmt(s.vertex(s.edge(e)[0])) + "-" + fmt(s.vertex(s.edge(e)[1]));
}

std::string fmt_triangle(const Surface& s, std::int32_t t) {
  const Triangle& tr = s.triangle(t);
  return "triangle " + std::to_string(t) + " " + fmt(s.vertex(tr[0])) + " " + fmt(s.vertex(tr[1])) + " " +
         fmt(s.vertex(tr[2]));
}

bool share_vertex(const Triangle& a, const Triangle& b) {
  for (std::int32_t v : a)
    if (v == b[0] || v == b[1] || v == b[2]) return true;
  return false;
}

bool pair_intersects(const Surface& s, std::int32_t t, std::int32_t u) {
  const Triangle& a = s.triangle(t);
  const Triangle& b = s.triangle(u);
  if (share_vertex(a, b)) return false;
  const P3 ta[3] = {s.vertex(a[0]), s.vertex(a[1]), s.vertex(a[2])};
  const P3 tb[3] = {s.vertex(b[0]), s.vertex(b[1]), s.vertex(b[2])};
  return triangles_intersect(ta, tb);
}

std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

std::vector<std::int32_t> boundary_edges(const Surface& s) {
  std::vector<std::int32_t> out;
  for (std::int32_t e = 0; e < s.n_edges(); ++e)
    if (s.edge_triangles(e).size() == 1) out.push_back(e);
  return out;
}

std::vector<std::int32_t> non_manifold_edges(const Surface& s) {
  std::vector<std::int32_t> out;
  for (std::int32_t e = 0; e < s.n_edges(); ++e)
    if (s.edge_triangles(e).size() > 2) out.push_back(e);
  return out;
}

std::vector<std::int32_t> non_manifold_vertices(const Surface& s) {
  std::vector<std::int32_t> out;
  std::vector<std::int32_t> parent;
  for (std::int32_t v = 0; v < s.n_vertices(); ++v) {
    const auto tris = s.vertex_triangles(v);
    if (tris.empty()) continue;
    parent.resize(tris.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto local = [&](std::int32_t t) {
      return static_cast<std::int32_t>(std::lower_bound(tris.begin(), tris.end(), t) - tris.begin());
    };
    for (std::int32_t e : s.vertex_edges(v)) {
      const auto around = s.edge_triangles(e);
      for (std::size_t k = 1; k < around.size(); ++k) {
        const std::int32_t a = find_root(parent, local(around[0])), b = find_root(parent, local(around[k]));
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
    int groups = 0;
    for (std::size_t i = 0; i < parent.size(); ++i)
      if (find_root(parent, static_cast<std::int32_t>(i)) == static_cast<std::int32_t>(i)) ++groups;
    if (groups > 1) out.push_back(v);
  }
  return out;
}

std::vector<std::int32_t> degenerate_triangles(const Surface& s) {
  std::vector<std::int32_t> out;
  for (std::int32_t t = 0; t < s.n_triangles(); ++t) {
    const Triangle& tr = s.triangle(t);
    const P3 &a = s.vertex(tr[0]), &b = s.vertex(tr[1]), &c = s.vertex(tr[2]);
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!((b - a).cross(c - a).norm() > 1e-12 * longest2)) out.push_back(t);
  }
  return out;
}

std::vector<std::pair<std::int32_t, std::int32_t>> self_intersections(const Surface& s, const AabbTree& tree) {
  std::vector<std::pair<std::int32_t, std::int32_t>> out;
  for (std::int32_t t = 0; t < s.n_triangles(); ++t) {
    Box<3> box = Box<3>::empty();
    for (std::int32_t v : s.triangle(t)) box.expand(s.vertex(v));
    tree.for_each_in_box(box, [&](std::int32_t u) {
      if (u > t && pair_intersects(s, t, u)) out.emplace_back(t, u);
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<std::int32_t, std::int32_t>> self_intersections_ref(const Surface& s) {
  std::vector<std::pair<std::int32_t, std::int32_t>> out;
  for (std::int32_t t = 0; t < s.n_triangles(); ++t)
    for (std::int32_t u = t + 1; u < s.n_triangles(); ++u)
      if (pair_intersects(s, t, u)) out.emplace_back(t, u);
  return out;
}

bool is_consistently_oriented(const Surface& s) {
  for (std::int32_t e = 0; e < s.n_edges(); ++e) {
    const auto tris = s.edge_triangles(e);
    if (tris.size() == 2 && s.runs_forward(tris[0], e) == s.runs_forward(tris[1], e)) return false;
  }
  return true;
}

std::vector<int> nesting_depths(const Surface& s, const AabbTree& tree) {
  const int nc = s.n_components();
  std::vector<int> depth(nc, 0);
  if (nc <= 1) return depth;
  // A point well inside the largest triangle of each component.
  std::vector<std::int32_t> seed(nc, -1);
  for (std::int32_t t = 0; t < s.n_triangles(); ++t) {
    const std::int32_t c = s.component(t);
    if (seed[c] < 0 || s.triangle_area(t) > s.triangle_area(seed[c])) seed[c] = t;
  }
  const double reach = 4.0 * s.bounding_box().extent().norm() + 1.0;
  for (int c = 0; c < nc; ++c) {
    const Triangle& tr = s.triangle(seed[c]);
    const P3 origin = (s.vertex(tr[0]) + s.vertex(tr[1]) + s.vertex(tr[2])) / 3.0;
    bool decided = false;
    for (const P3& dir : ray_directions()) {
      std::vector<int> hits(nc, 0);
      bool degenerate = false;
      const P3 far = origin + reach * dir;
      tree.for_each_on_segment(origin, far, [&](std::int32_t t) {
        if (s.component(t) == c || degenerate) return;
        const auto& q = tree.points(t);
        const Crossing x = segment_triangle(origin, far, q[0], q[1], q[2]);
        if (x == Crossing::Degenerate) degenerate = true;
        if (x == Crossing::Proper) ++hits[s.component(t)];
      });
      if (degenerate) continue;
      for (int o = 0; o < nc; ++o) depth[c] += hits[o] % 2;
      decided = true;
      break;
    }
    if (!decided)
      throw GeometryError("cannot decide the nesting of surface component " + std::to_string(c) +
                          ": every ray grazes an edge");
  }
  return depth;
}

int orient_outward(Surface& s, const std::string& name, AabbTree* tree) {
  const int nt = s.n_triangles();
  std::vector<bool> flip(nt, false), seen(nt, false);
  // Breadth-first over manifold edges: each neighbour must run the shared edge the other way.
  for (std::int32_t start = 0; start < nt; ++start) {
    if (seen[start]) continue;
    seen[start] = true;
    std::queue<std::int32_t> todo;
    todo.push(start);
    while (!todo.empty()) {
      const std::int32_t t = todo.front();
      todo.pop();
      for (int i = 0; i < 3; ++i) {
        const std::int32_t e = s.triangle_edge(t, i);
        const std::int32_t u = s.opposite_triangle(e, t);
        if (u < 0) continue;
        const bool want_flip = flip[t] != (s.runs_forward(t, e) == s.runs_forward(u, e));
        if (!seen[u]) {
          seen[u] = true;
          flip[u] = want_flip;
          todo.push(u);
        } else if (flip[u] != want_flip) {
          throw InputError(name + ": the surface is not orientable (a Moebius-like band through the edge " +
                           fmt_edge(s, e) + ")");
        }
      }
    }
  }
  int n_flipped = static_cast<int>(std::count(flip.begin(), flip.end(), true));
  if (n_flipped > 0) s.flip(flip);

  std::optional<AabbTree> own;
  if (!tree || n_flipped > 0) own.emplace(s.vertices(), s.triangles());
  const std::vector<int> depth = nesting_depths(s, own ? *own : *tree);
  std::vector<bool> flip_component(s.n_components(), false);
  bool any = false;
  for (int c = 0; c < s.n_components(); ++c) {
    const bool cavity = depth[c] % 2 == 1;
    flip_component[c] = (s.component_volume(c) < 0.0) != cavity;
    any = any || flip_component[c];
  }
  if (any) {
    std::vector<bool> which(nt, false);
    for (std::int32_t t = 0; t < nt; ++t) which[t] = flip_component[s.component(t)];
    n_flipped += static_cast<int>(std::count(which.begin(), which.end(), true));
    s.flip(which);
  }
  if (tree && n_flipped > 0) *tree = AabbTree(s.vertices(), s.triangles());
  return n_flipped;
}

AabbTree validate_surface(Surface& s, const std::string& name) {
  if (s.n_triangles() == 0) throw InputError(name + ": empty surface (no triangles)");
  {
    // The predicates multiply up to three lengths (orient3d) and compare squared ones: at
    // 1e200 or 1e-200 across they overflow or underflow, and every triangle looked degenerate
    // ("12 degenerate (zero-area) triangle(s)" for a cube 1e200 across). Said as it is instead.
    const Box<3> b = s.bounding_box();
    const double largest = std::max(b.lo.cwiseAbs().maxCoeff(), b.hi.cwiseAbs().maxCoeff());
    const double across = b.extent().maxCoeff();
    std::ostringstream os;
    os << std::setprecision(3);
    if (largest > max_surface_coordinate) {
      os << name << ": coordinates up to " << largest << " exceed the largest accepted magnitude " << max_surface_coordinate
         << " (scale the surface)";
      throw InputError(os.str());
    }
    if (!(across >= min_surface_extent)) {
      os << name << ": the surface is " << across << " across, under the smallest accepted extent " << min_surface_extent
         << " (scale the surface)";
      throw InputError(os.str());
    }
  }
  if (const auto bad = non_manifold_edges(s); !bad.empty())
    throw InputError(name + ": non-manifold: " + std::to_string(bad.size()) +
                     " edge(s) with more than two triangles, e.g. the edge " + fmt_edge(s, bad[0]) + " has " +
                     std::to_string(s.edge_triangles(bad[0]).size()));
  if (const auto bad = boundary_edges(s); !bad.empty())
    throw InputError(name + ": surface is not closed: " + std::to_string(bad.size()) +
                     " boundary edges, e.g. the edge " + fmt_edge(s, bad[0]));
  if (const auto bad = non_manifold_vertices(s); !bad.empty())
    throw InputError(name + ": non-manifold: " + std::to_string(bad.size()) +
                     " vertex(es) where separate sheets of the surface meet, e.g. " + fmt(s.vertex(bad[0])));
  if (const auto bad = degenerate_triangles(s); !bad.empty())
    throw InputError(name + ": " + std::to_string(bad.size()) + " degenerate (zero-area) triangle(s), e.g. " +
                     fmt_triangle(s, bad[0]));
  AabbTree tree(s.vertices(), s.triangles());
  if (const auto bad = self_intersections(s, tree); !bad.empty())
    throw InputError(name + ": self-intersecting: " + std::to_string(bad.size()) +
                     " pair(s) of triangles intersect, e.g. " + fmt_triangle(s, bad[0].first) + " and " +
                     fmt_triangle(s, bad[0].second));
  orient_outward(s, name, &tree);
  return tree;
}

}  // namespace febemesh::dim3
