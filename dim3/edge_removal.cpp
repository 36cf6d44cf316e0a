#include "dim3/edge_removal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <queue>
#include <optional>
#include <span>
#include <utility>

#include "core/error.hpp"
#include "core/incidence_csr.hpp"
#include "core/parallel_ranges.hpp"
#include "core/point_grid.hpp"
#include "dim3/tet_optimize.hpp"

namespace febemesh::dim3 {
namespace {

using P3 = Point<3>;
using Tet = std::array<std::int32_t, 4>;
using Tri = std::array<std::int32_t, 3>;

constexpr double pi = 3.14159265358979323846;
constexpr double none = -std::numeric_limits<double>::infinity();

double orient(const P3& a, const P3& b, const P3& c, const P3& d) { return (b - a).dot((c - a).cross(d - a)); }

/// A list of ids per node that only the nodes with entries pay for: a slot a node (4 B) and a
/// vector for each node that ever had an entry. (A vector a node, 24 B each however few have
/// entries, was 8.3 MB for the tetrahedra added and the interface triangles at sphere966's
/// 995,232 tetrahedra, at edge removal's heap peak; massif.)
class NodeLists {
 public:
  void reset(std::size_t n_nodes) {
    slot_.assign(n_nodes, -1);
    lists_.clear();
  }
  std::size_t n_nodes() const { return slot_.size(); }
  /// Node v's entries, in the order they were added.
  std::span<const std::int32_t> operator[](std::int32_t v) const {
    const std::int32_t k = slot_[static_cast<std::size_t>(v)];
    if (k < 0) return {};
    return lists_[static_cast<std::size_t>(k)];
  }
  void push(std::int32_t v, std::int32_t id) { list(v).push_back(id); }
  /// Removes the first entry `id` of node v's list (it must be there).
  void erase(std::int32_t v, std::int32_t id) {
    std::vector<std::int32_t>& l = list(v);
    l.erase(std::find(l.begin(), l.end(), id));
  }

 private:
  std::vector<std::int32_t>& list(std::int32_t v) {
    std::int32_t& k = slot_[static_cast<std::size_t>(v)];
    if (k < 0) {
      k = static_cast<std::int32_t>(lists_.size());
      lists_.emplace_back();
    }
    return lists_[static_cast<std::size_t>(k)];
  }
  std::vector<std::int32_t> slot_;
  std::vector<std::vector<std::int32_t>> lists_;
};

/// The mesh as removals edit it. The input's tetrahedra are read from the mesh where they are;
/// those added live here; dead ones of either stay until the write-back, which compacts the
/// mesh's arrays in place (sphere966 L6: a full copy of the tetrahedra, their qualities and
/// per-element arrays, and a second element array built beside the first made edge removal the
/// pipeline's peak, 251.5 MB against 168.5 without it).
struct Work {
  Mesh<3>& mesh;
  const std::vector<BoundaryLocation>& where;
  const EdgeRemovalOptions& opt;
  std::int32_t n_input = 0;         ///< tetrahedra 0 .. n_input - 1 are the mesh's
  std::vector<Tet> added;           ///< tetrahedra n_input + i
  std::vector<double> added_q;      ///< their tet_search_quality
  std::vector<std::int32_t> like;   ///< the input tetrahedron whose per-element values they take
  std::vector<std::uint8_t> alive;  ///< per tetrahedron, input and added
  // The tetrahedra at each node, alive or not (dead ones are skipped where read): the input's
  // as CSR (ascending), then those added, in order. The same sequence as lists with the dead
  // erased; the lists of vectors were 60 MB of sphere966 L6's 112 MB for edge removal.
  std::vector<std::int32_t> at_start, at_list;
  NodeLists at_added;
  std::vector<Tri> faces;
  std::vector<std::uint8_t> face_alive;
  NodeLists node_faces;
  std::vector<std::uint8_t> node_dead;  ///< per node: contracted away

  Tet tet(std::int32_t t) const {
    if (t >= n_input) return added[t - n_input];
    const VertexId* v = mesh.solid.node.data() + 4 * static_cast<std::size_t>(t);
    return {v[0].v, v[1].v, v[2].v, v[3].v};
  }
  std::int32_t n_tets() const { return n_input + static_cast<std::int32_t>(added.size()); }
  /// The input's qualities are computed again where needed (the nodes do not move here): cheaper
  /// than 8 bytes a tetrahedron for the few that are read twice.
  double q(std::int32_t t) const { return t >= n_input ? added_q[t - n_input] : quality(tet(t)); }
  double quality(const Tet& t) const {
    return tet_search_quality(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]);
  }
  bool is_feature(std::int32_t v) const {
    return static_cast<std::size_t>(v) < where.size() && where[v].patch >= 0 &&
           where[v].kind != BoundaryLocation::Kind::Smooth;
  }
  /// Calls f(t) for the live tetrahedra at node v, in order, while f returns true.
  template <class F> void for_tets_at(std::int32_t v, const F& f) const {
    for (std::int32_t i = at_start[v]; i < at_start[v + 1]; ++i)
      if (alive[at_list[i]] && !f(at_list[i])) return;
    for (const std::int32_t t : at_added[v])
      if (alive[t] && !f(t)) return;
  }
  bool connected(std::int32_t u, std::int32_t v) const {
    bool found = false;
    for_tets_at(u, [&](std::int32_t t) {
      const Tet n = tet(t);
      found = std::find(n.begin(), n.end(), v) != n.end();
      return !found;
    });
    return found;
  }
  /// Smallest cosine between triangle f's normal and the surface normals at its nodes.
  double fit(const Tri& f) const {
    double c = 1.0;
    for (const std::int32_t v : f)
      c = std::min(c, surface_alignment(mesh.points[f[0]], mesh.points[f[1]], mesh.points[f[2]], opt.surface_normal(where[v])));
    return c;
  }
  /// f ordered so that its normal points away from node o.
  Tri outward(Tri f, std::int32_t o) const {
    if (orient(mesh.points[f[0]], mesh.points[f[1]], mesh.points[f[2]], mesh.points[o]) > 0) std::swap(f[1], f[2]);
    return f;
  }

  std::int32_t add_tet(const Tet& t, std::int32_t from) {
    const std::int32_t id = n_tets();
    added.push_back(t);
    added_q.push_back(quality(t));
    like.push_back(from >= n_input ? like[from - n_input] : from);
    alive.push_back(1);
    for (const std::int32_t v : t) at_added.push(v, id);
    return id;
  }
  void kill_tet(std::int32_t t) { alive[t] = 0; }
  void add_face(const Tri& f) {
    const auto id = static_cast<std::int32_t>(faces.size());
    for (int e = 0; e < 3; ++e) longest_edge = std::max(longest_edge, (mesh.points[f[e]] - mesh.points[f[(e + 1) % 3]]).norm());
    faces.push_back(f);
    face_alive.push_back(1);
    for (const std::int32_t v : f) node_faces.push(v, id);
  }
  void kill_face(std::int32_t f) {
    face_alive[f] = 0;
    for (const std::int32_t v : faces[f]) node_faces.erase(v, f);
  }

  bool on_surface(std::int32_t v) const { return static_cast<std::size_t>(v) < where.size() && where[v].patch >= 0; }
  /// Whether a contraction may remove node u: inside, or on smooth surface; never a kept one.
  bool removable(std::int32_t u) const {
    if (node_dead[u] || (!opt.keep.empty() && opt.keep[u])) return false;
    return !on_surface(u) || where[u].kind == BoundaryLocation::Kind::Smooth;
  }

  /// The link of node x, or of edge xy (y >= 0), in the mesh closed by a cone from a node
  /// `outside` (-1) over the interface: its vertices, edges and triangles, sorted, each once.
  struct Link {
    std::vector<std::int32_t> v;
    std::vector<std::array<std::int32_t, 2>> e;
    std::vector<std::array<std::int32_t, 3>> t;
  };
  static constexpr std::int32_t outside = -1;
  Link link_of(std::int32_t x, std::int32_t y = -2) const {
    Link l;
    const auto others = [&](const auto& nodes, std::int32_t* out) {
      int k = 0;
      for (const std::int32_t u : nodes)
        if (u != x && u != y) out[k++] = u;
      return k;
    };
    const auto add = [&](std::int32_t* o, int k) {
      std::sort(o, o + k);
      for (int i = 0; i < k; ++i) l.v.push_back(o[i]);
      for (int i = 0; i < k; ++i)
        for (int j = i + 1; j < k; ++j) l.e.push_back({o[i], o[j]});
      if (k == 3) l.t.push_back({o[0], o[1], o[2]});
    };
    const auto has_y = [&](const auto& nodes) { return y < 0 || std::find(nodes.begin(), nodes.end(), y) != nodes.end(); };
    for_tets_at(x, [&](std::int32_t t) {
      const Tet n = tet(t);
      if (!has_y(n)) return true;
      std::int32_t o[3];
      add(o, others(n, o));
      return true;
    });
    for (const std::int32_t f : node_faces[x]) {
      if (!has_y(faces[f])) continue;
      std::int32_t o[3];
      const int k = others(faces[f], o);
      o[k] = outside;
      add(o, k + 1);
    }
    const auto unique = [](auto& a) {
      std::sort(a.begin(), a.end());
      a.erase(std::unique(a.begin(), a.end()), a.end());
    };
    unique(l.v);
    unique(l.e);
    unique(l.t);
    return l;
  }

  /// The interface nodes in a point grid (core/point_grid.hpp), built on the first concave swap
  /// that gets that far: the nodes do not move here and no new ones come, so it stays right.
  /// longest_edge (of the live interface triangles) follows the faces added since.
  double longest_edge = 0.0;
  std::optional<PointGrid<3>> grid;
  /// Whether no live interface triangle but `skip`'s two reaches into the closed tetrahedron
  /// a b back front, which a concave surface swap adds to the solid: none has a node in it, an
  /// edge through its new faces a-front-back and b-front-back, or is crossed by its new edge
  /// front-back (its other faces and edges are the old surface's). Any such triangle has its
  /// nodes within the longest interface edge of the tetrahedron's box. Touching counts.
  bool clear_outside(std::int32_t a, std::int32_t b, std::int32_t front, std::int32_t back, const std::vector<std::int32_t>& skip) {
    if (!grid) {
      std::vector<std::int32_t> interface_nodes;
      for (std::size_t v = 0; v < node_faces.n_nodes(); ++v)
        if (!node_faces[static_cast<std::int32_t>(v)].empty()) interface_nodes.push_back(static_cast<std::int32_t>(v));
      grid.emplace(mesh.points, interface_nodes);
    }
    const P3* p = mesh.points.data();
    const std::array<std::int32_t, 4> tet = {a, b, back, front};  // positive
    P3 lo = p[a], hi = p[a];
    for (const std::int32_t v : tet) lo = lo.cwiseMin(p[v]), hi = hi.cwiseMax(p[v]);
    // (A hair more: a node exactly one edge away stays in the box whatever the rounding.)
    lo.array() -= longest_edge * (1.0 + 1e-9);
    hi.array() += longest_edge * (1.0 + 1e-9);
    const auto in_tet = [&](std::int32_t x) {
      return orient(p[a], p[b], p[back], p[x]) >= 0 && orient(p[a], p[front], p[b], p[x]) >= 0 &&
             orient(p[a], p[back], p[front], p[x]) >= 0 && orient(p[b], p[front], p[back], p[x]) >= 0;
    };
    // Segment xy against triangle uvw, closed: a touch or a coplanar overlap counts.
    const auto meets = [&](std::int32_t x, std::int32_t y, std::int32_t u, std::int32_t v, std::int32_t w) {
      const double s1 = orient(p[u], p[v], p[w], p[x]), s2 = orient(p[u], p[v], p[w], p[y]);
      if ((s1 > 0 && s2 > 0) || (s1 < 0 && s2 < 0)) return false;
      const double t1 = orient(p[x], p[y], p[u], p[v]), t2 = orient(p[x], p[y], p[v], p[w]), t3 = orient(p[x], p[y], p[w], p[u]);
      return !((t1 > 0 || t2 > 0 || t3 > 0) && (t1 < 0 || t2 < 0 || t3 < 0));
    };
    const auto shares = [](std::int32_t x, std::int32_t y, std::int32_t u, std::int32_t v, std::int32_t w) {
      return x == u || x == v || x == w || y == u || y == v || y == w;
    };
    bool clear = true;
    grid->query(Box<3>{lo, hi}, [&](std::int32_t x) {
      for (const std::int32_t f : node_faces[x]) {
        if (!clear) return;
        if (std::find(skip.begin(), skip.end(), f) != skip.end()) continue;  // (a triangle is seen up to 3 times)
        const Tri& t = faces[f];
        for (int e = 0; e < 3 && clear; ++e) {
          const std::int32_t u = t[e], v = t[(e + 1) % 3];
          if (std::find(tet.begin(), tet.end(), u) == tet.end() && in_tet(u)) clear = false;
          for (const std::int32_t c : {a, b})
            if (!shares(u, v, c, front, back) && meets(u, v, c, front, back)) clear = false;
        }
        if (!shares(front, back, t[0], t[1], t[2]) && meets(front, back, t[0], t[1], t[2])) clear = false;
      }
    });
    return clear;
  }

  /// Contracts edge uv into v (node u goes) if that raises the worst angle of u's tetrahedra
  /// by more than opt.contract_min_gain_deg, keeps every tetrahedron positive, the interface on
  /// the surface and the mesh a manifold (the link condition); returns whether it did.
  bool try_contract(std::int32_t u, std::int32_t v, EdgeRemovalStats& st) {
    if (!removable(u) || node_dead[v]) return false;
    const bool surface = on_surface(u);
    if (surface && (!on_surface(v) || !opt.surface_normal)) return false;
    // u's tetrahedra: those at v go, the others take v for u.
    std::vector<std::int32_t> at_u;
    std::vector<Tet> moved;
    double old_min = std::numeric_limits<double>::infinity(), new_min = old_min;
    bool ok = true;
    for_tets_at(u, [&](std::int32_t t) {
      at_u.push_back(t);
      old_min = std::min(old_min, q(t));
      Tet n = tet(t);
      if (std::find(n.begin(), n.end(), v) != n.end()) return true;
      std::replace(n.begin(), n.end(), u, v);
      const double qn = quality(n);
      ok = qn > 0;
      new_min = std::min(new_min, qn);
      moved.push_back(n);
      return ok;
    });
    if (!ok || moved.size() == at_u.size() || !(new_min > old_min + opt.contract_min_gain_deg * pi / 180.0)) return false;
    // u's interface triangles: the two at uv go (a surface edge), the others take v.
    const std::vector<std::int32_t> faces_u(node_faces[u].begin(), node_faces[u].end());
    std::vector<Tri> moved_faces;
    if (surface) {
      int at_uv = 0;
      double old_fit = 1.0, new_fit = 1.0;
      for (const std::int32_t f : faces_u) {
        old_fit = std::min(old_fit, fit(faces[f]));
        Tri n = faces[f];
        if (std::find(n.begin(), n.end(), v) != n.end()) {
          ++at_uv;
          continue;
        }
        std::replace(n.begin(), n.end(), u, v);
        new_fit = std::min(new_fit, fit(n));
        moved_faces.push_back(n);
      }
      // Within 25 deg of the surface normals, or no worse than before.
      if (at_uv != 2 || !(new_fit > 0 && (new_fit >= old_fit || new_fit >= 0.9))) return false;
    } else if (!faces_u.empty()) {
      return false;
    }
    // The link condition: Lk(u) and Lk(v) meet in Lk(uv) exactly (vertices and edges; no
    // triangle), and u's link is a closed surface (u is inside the closed complex).
    const Link lu = link_of(u), lv = link_of(v), luv = link_of(u, v);
    {
      std::vector<int> uses(lu.e.size(), 0);
      for (const auto& t : lu.t)
        for (int i = 0; i < 3; ++i)
          for (int j = i + 1; j < 3; ++j) {
            const std::array<std::int32_t, 2> e = {t[i], t[j]};
            ++uses[static_cast<std::size_t>(std::lower_bound(lu.e.begin(), lu.e.end(), e) - lu.e.begin())];
          }
      if (std::any_of(uses.begin(), uses.end(), [](int n) { return n != 2; })) return false;
    }
    const auto meet = [](const auto& a, const auto& b) {
      std::decay_t<decltype(a)> out;
      std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
      return out;
    };
    if (meet(lu.v, lv.v) != luv.v || meet(lu.e, lv.e) != luv.e || !meet(lu.t, lv.t).empty()) return false;
    std::size_t k = 0;
    for (const std::int32_t t : at_u) {
      const Tet n = tet(t);
      kill_tet(t);
      if (std::find(n.begin(), n.end(), v) == n.end()) add_tet(moved[k++], t);
    }
    for (const std::int32_t f : faces_u) kill_face(f);
    for (const Tri& f : moved_faces) add_face(f);
    node_dead[u] = 1;
    ++st.contracted;
    return true;
  }

  /// Removes edge ab if a triangulation of its link raises the worst angle around it by
  /// opt.min_gain_deg; returns whether it did. A concave surface edge only with `concave_ok`.
  bool try_remove(std::int32_t a, std::int32_t b, EdgeRemovalStats& st, bool concave_ok = false) {
    // The tetrahedra around ab, each as a link edge c -> d with (a, b, c, d) positive.
    std::vector<std::int32_t> around;
    std::vector<std::pair<std::int32_t, std::int32_t>> link;
    double old_min = std::numeric_limits<double>::infinity();
    for_tets_at(a, [&](std::int32_t t) {
      const Tet n = tet(t);
      int i = -1, j = -1;
      for (int k = 0; k < 4; ++k) i = n[k] == a ? k : i, j = n[k] == b ? k : j;
      if (j < 0) return true;
      std::array<int, 4> perm = {i, j, -1, -1};
      for (int k = 0, m = 2; k < 4; ++k)
        if (k != i && k != j) perm[m++] = k;
      int inversions = 0;
      for (int x = 0; x < 4; ++x)
        for (int y = x + 1; y < 4; ++y) inversions += perm[x] > perm[y] ? 1 : 0;
      std::int32_t c = n[perm[2]], d = n[perm[3]];
      if (inversions % 2 == 1) std::swap(c, d);
      around.push_back(t);
      link.push_back({c, d});
      old_min = std::min(old_min, q(t));
      return true;
    });
    const int n_tets = static_cast<int>(around.size());
    if (n_tets < 2 || n_tets + 1 > opt.max_link) return false;
    // Chain the link edges: a cycle inside, a path at the surface.
    std::vector<std::int32_t> ring;
    {
      std::int32_t start = link[0].first;
      for (const auto& [c, d] : link) {
        (void)d;
        if (std::none_of(link.begin(), link.end(), [&](const auto& e) { return e.second == c; })) start = c;
      }
      ring.push_back(start);
      for (int k = 0; k < n_tets; ++k) {
        const auto it = std::find_if(link.begin(), link.end(), [&](const auto& e) { return e.first == ring.back(); });
        if (it == link.end()) return false;
        ring.push_back(it->second);
      }
    }
    const bool closed = ring.back() == ring.front();
    if (closed) ring.pop_back();
    const int m = static_cast<int>(ring.size());
    {
      std::vector<std::int32_t> sorted = ring;
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;  // not a simple link
    }
    // The interface triangles at ab: none inside, the two at the path's ends at the surface.
    std::vector<std::int32_t> at_ab;
    for (const std::int32_t f : node_faces[a])
      if (std::find(faces[f].begin(), faces[f].end(), b) != faces[f].end()) at_ab.push_back(f);
    if (closed != at_ab.empty()) return false;
    double old_fit = 0.0;
    bool concave = false;
    if (!closed) {
      if (!opt.surface_normal || at_ab.size() != 2 || (is_feature(a) && is_feature(b))) return false;
      const auto has = [&](std::int32_t f, std::int32_t v) { return std::find(faces[f].begin(), faces[f].end(), v) != faces[f].end(); };
      if (!((has(at_ab[0], ring.front()) && has(at_ab[1], ring.back())) ||
            (has(at_ab[1], ring.front()) && has(at_ab[0], ring.back()))))
        return false;
      // At a convex edge of the surface mesh the new tetrahedra fill less than the old ones (not
      // the tetrahedron a b ring.front() ring.back()) and reach nothing outside them. At a
      // concave one they fill that tetrahedron too, outside the old surface: taken only if no
      // interface triangle reaches into it (clear_outside, below).
      const P3* p = mesh.points.data();
      const double side = orient(p[a], p[b], p[ring.front()], p[ring.back()]);
      if (side == 0 || (side < 0 && !concave_ok)) return false;
      concave = side < 0;
      if (connected(ring.front(), ring.back())) return false;
      old_fit = std::min(fit(faces[at_ab[0]]), fit(faces[at_ab[1]]));
    }
    // Klincsek: best[i][k] the best worst angle triangulating ring[i..k] (i < k).
    const auto q3 = [&](int i, int j, int k) {
      const double qa = quality({a, ring[i], ring[j], ring[k]});
      const double qb = quality({b, ring[k], ring[j], ring[i]});
      return qa > 0 && qb > 0 ? std::min(qa, qb) : none;
    };
    std::vector<double> best(static_cast<std::size_t>(m * m), std::numeric_limits<double>::infinity());
    std::vector<int> split(static_cast<std::size_t>(m * m), -1);
    for (int len = 2; len < m; ++len)
      for (int i = 0; i + len < m; ++i) {
        const int k = i + len;
        double& bk = best[i * m + k];
        bk = none;
        for (int j = i + 1; j < k; ++j) {
          const double v = std::min({best[i * m + j], best[j * m + k], q3(i, j, k)});
          if (v > bk) bk = v, split[i * m + k] = j;
        }
      }
    const double new_min = best[m - 1];
    if (!(new_min > old_min + opt.min_gain_deg * pi / 180.0)) return false;
    std::vector<std::array<int, 3>> tris;
    std::vector<std::pair<int, int>> stack = {{0, m - 1}};
    while (!stack.empty()) {
      const auto [i, k] = stack.back();
      stack.pop_back();
      if (k - i < 2) continue;
      const int j = split[i * m + k];
      tris.push_back({i, j, k});
      stack.push_back({i, j});
      stack.push_back({j, k});
    }
    // New edges must be new: the diagonals of the triangulation.
    for (const auto& t : tris)
      for (int e = 0; e < 3; ++e) {
        const int u = t[e], v = t[(e + 1) % 3];
        const bool side = v == u + 1 || u == v + 1 || (closed && std::abs(u - v) == m - 1);
        if (!side && !(u == 0 && v == m - 1) && !(u == m - 1 && v == 0) && connected(ring[u], ring[v])) return false;
      }
    std::array<Tri, 2> new_faces{};
    if (!closed) {
      // The triangle with the chord ring.front() ring.back() is tris[0] (the root split).
      const std::int32_t o = ring[tris[0][1]];
      new_faces[0] = outward({a, ring.front(), ring.back()}, o);
      new_faces[1] = outward({b, ring.front(), ring.back()}, o);
      const double new_fit = std::min(fit(new_faces[0]), fit(new_faces[1]));
      if (!(new_fit > 0 && new_fit >= old_fit)) return false;
      if (concave && !clear_outside(a, b, ring.front(), ring.back(), at_ab)) return false;
    }
    const std::int32_t like = around[0];
    for (const auto& t : tris) {
      add_tet({a, ring[t[0]], ring[t[1]], ring[t[2]]}, like);
      add_tet({b, ring[t[2]], ring[t[1]], ring[t[0]]}, like);
    }
    for (const std::int32_t t : around) kill_tet(t);
    if (!closed) {
      for (const std::int32_t f : at_ab) kill_face(f);
      add_face(new_faces[0]);
      add_face(new_faces[1]);
      ++st.surface_swapped;
      st.concave_swapped += concave ? 1 : 0;
    }
    ++st.removed;
    return true;
  }
};

}  // namespace

EdgeRemovalStats remove_bad_edges(Mesh<3>& mesh, const std::vector<BoundaryLocation>& where, std::vector<std::int32_t>* cell,
                                  const EdgeRemovalOptions& opt) {
  Work w{mesh, where, opt, 0, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, 0.0, {}};
  // The caller's node -> tetrahedra lists, taken (EdgeRemovalOptions::incidence): freed with
  // this call whichever way it returns.
  NodeTets handed;
  if (opt.incidence) std::swap(handed, *opt.incidence);
  const std::size_t n = mesh.points.size();
  w.n_input = static_cast<std::int32_t>(mesh.solid.size());
  for (std::size_t e = 0; e < mesh.solid.size(); ++e)
    MESH_ASSERT(mesh.solid.type[e] == ElemType::Tet4 && mesh.solid.offset[e] == static_cast<std::int32_t>(4 * e),
                "remove_bad_edges needs tetrahedra");
  const double below = opt.below_deg * pi / 180.0;
  // Worst first; new tetrahedra below the bar join the list (each removal raises the worst
  // angle around its edge, so this ends; the cap is a guard).
  using Entry = std::pair<double, std::int32_t>;  // (quality, tetrahedron): the worst on top
  // The scan in fixed chunks whose lists join in chunk order: the same list on any threads.
  constexpr std::size_t chunk = 1 << 16;
  std::vector<std::vector<Entry>> bad_in((static_cast<std::size_t>(w.n_input) + chunk - 1) / chunk);
  // The search rank (no roots, no acos) picks the candidates, with a margin far above its
  // rounding; their qualities decide (sphere966 L6: 0.067 s a scan of 1.5 M tetrahedra by
  // quality, 3 scans a run).
  const double below_rank = tet_search_rank_of_angle(below) + 1e-9;
  // With ranks handed in, the scan reads them; with ranks wanted out, it keeps those it makes.
  std::vector<double>* ranks = opt.ranks;
  const bool ranked = ranks && ranks->size() == mesh.solid.size();
  if (ranks && !ranked) ranks->resize(mesh.solid.size());
  for_each_chunk(static_cast<std::size_t>(w.n_input), chunk, opt.n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      const Tet n = w.tet(static_cast<std::int32_t>(t));
      double r = 0.0;
      if (ranked) {
        r = (*ranks)[t];
      } else {
        r = tet_search_rank(mesh.points[n[0]], mesh.points[n[1]], mesh.points[n[2]], mesh.points[n[3]]);
        if (ranks) (*ranks)[t] = r;
      }
      if (!(r < below_rank)) continue;
      if (!opt.only_at.empty() && !(opt.only_at[static_cast<std::size_t>(n[0])] | opt.only_at[static_cast<std::size_t>(n[1])] |
                                    opt.only_at[static_cast<std::size_t>(n[2])] | opt.only_at[static_cast<std::size_t>(n[3])]))
        continue;
      if (const double q = w.quality(n); q < below) bad_in[c].push_back({q, static_cast<std::int32_t>(t)});
    }
  });
  std::vector<Entry> bad;
  for (const auto& b : bad_in) bad.insert(bad.end(), b.begin(), b.end());
  bad_in.clear();
  if (bad.empty()) return {};
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> todo(std::greater<>{}, std::move(bad));
  w.alive.assign(static_cast<std::size_t>(w.n_input), 1);
  if (handed.fits(n, static_cast<std::size_t>(w.n_input))) {
    // (The optimiser's lists of the same tetrahedra: building them again was about 13 ms a
    // round on one thread and 19 on two at sphere966's 995,232 tetrahedra.)
    w.at_start.swap(handed.start);
    w.at_list.swap(handed.tets);
  } else {
    handed.clear();  // (lists of another mesh: not held beside the new ones)
    incidence_csr(
        n, static_cast<std::size_t>(w.n_input),
        [&](std::size_t e, auto&& f) {
          for (const std::int32_t u : w.tet(static_cast<std::int32_t>(e))) f(u);
        },
        opt.n_threads, w.at_start, w.at_list);
  }
  w.at_added.reset(n);
  w.node_faces.reset(n);
  w.node_dead.assign(n, 0);
  const double contract_below = opt.contract_below_deg * pi / 180.0;
  const double concave_below = opt.concave_below_deg * pi / 180.0;
  for (std::size_t f = 0; f < mesh.interface.size(); ++f) {
    MESH_ASSERT(mesh.interface.type[f] == ElemType::Tri3, "remove_bad_edges needs interface triangles");
    const VertexId* v = mesh.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
    w.add_face({v[0].v, v[1].v, v[2].v});
  }
  EdgeRemovalStats st;
  const std::size_t cap = 8 * todo.size() + 16;
  for (std::size_t round = 0; !todo.empty() && round < cap; ++round) {
    // Its quality as queued: a live tetrahedron's nodes neither move nor change here (the
    // queue's value is q(t), computed once instead of up to three times a tetrahedron).
    const auto [qt, t] = todo.top();
    todo.pop();
    if (!w.alive[t] || !(qt > 0)) continue;
    const std::int32_t first_new = w.n_tets();
    const Tet nodes = w.tet(t);
    bool done = false;
    for (int i = 0; i < 4 && !done; ++i)
      for (int j = i + 1; j < 4 && !done; ++j) done = w.try_remove(nodes[i], nodes[j], st);
    // Concave surface swaps only here, where nothing else mends the tetrahedron: tried with the
    // others for every tetrahedron under below_deg they took elephant L4 from 21.42 to 18.03 deg
    // (its worst two then held surface edges of 0.0018-0.0019 among edges of 0.005-0.013).
    if (!done && qt < concave_below)
      for (int i = 0; i < 4 && !done; ++i)
        for (int j = i + 1; j < 4 && !done; ++j) done = w.try_remove(nodes[i], nodes[j], st, true);
    if (!done && qt < contract_below) {
      // Its edges, shortest first (ties in the order of the removal loop above); each way round.
      std::array<std::pair<double, std::array<int, 2>>, 6> edges;
      int e = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) edges[e++] = {(mesh.points[nodes[i]] - mesh.points[nodes[j]]).squaredNorm(), {i, j}};
      std::sort(edges.begin(), edges.end());
      for (int k = 0; k < 6 && !done; ++k) {
        const auto [i, j] = edges[k].second;
        done = w.try_contract(nodes[i], nodes[j], st) || w.try_contract(nodes[j], nodes[i], st);
      }
    }
    for (std::int32_t k = first_new; k < w.n_tets(); ++k)
      if (w.q(k) < below) todo.push({w.q(k), k});
  }
  if (st.removed == 0 && st.contracted == 0) return st;
  // The lists are done with: free them before the element arrays grow.
  std::vector<std::int32_t>().swap(w.at_list);
  std::vector<std::int32_t>().swap(w.at_start);
  w.at_added = {};
  std::vector<double>().swap(w.added_q);
  if (cell && !cell->empty()) {
    for (std::int32_t t = 0; t < w.n_tets(); ++t)
      if (!w.alive[t]) st.cells_changed.push_back((*cell)[t < w.n_input ? t : w.like[t - w.n_input]]);
    std::sort(st.cells_changed.begin(), st.cells_changed.end());
    st.cells_changed.erase(std::unique(st.cells_changed.begin(), st.cells_changed.end()), st.cells_changed.end());
  }
  // Write back in place: survivors in order, then the new ones. The new ones' per-element
  // values come from input tetrahedra, which the compaction may have moved or dropped: read
  // them first.
  std::size_t n_new = 0;
  for (std::size_t i = 0; i < w.added.size(); ++i) n_new += w.alive[w.n_input + i];
  const auto per_element = [&](auto& values) {
    using V = typename std::decay_t<decltype(values)>::value_type;
    if (values.empty()) return;
    std::vector<V> tail;
    tail.reserve(n_new);
    for (std::size_t i = 0; i < w.added.size(); ++i)
      if (w.alive[w.n_input + i]) tail.push_back(values[w.like[i]]);
    std::size_t k = 0;
    for (std::int32_t t = 0; t < w.n_input; ++t)
      if (w.alive[t]) values[k++] = values[t];
    values.resize(k);
    values.insert(values.end(), tail.begin(), tail.end());
  };
  per_element(mesh.level);
  per_element(mesh.from_boundary_cell);
  if (cell) per_element(*cell);
  if (ranks) {  // the survivors' in order, then the new ones ranked
    std::size_t k = 0;
    for (std::int32_t t = 0; t < w.n_input; ++t)
      if (w.alive[t]) (*ranks)[k++] = (*ranks)[t];
    ranks->resize(k);
    for (std::size_t i = 0; i < w.added.size(); ++i)
      if (w.alive[w.n_input + i]) {
        const Tet& n = w.added[i];
        ranks->push_back(tet_search_rank(mesh.points[n[0]], mesh.points[n[1]], mesh.points[n[2]], mesh.points[n[3]]));
      }
  }
  Elements& solid = mesh.solid;
  std::size_t k = 0;
  for (std::int32_t t = 0; t < w.n_input; ++t) {
    if (!w.alive[t]) continue;
    for (int i = 0; i < 4; ++i) solid.node[4 * k + i] = solid.node[4 * static_cast<std::size_t>(t) + i];
    ++k;
  }
  const std::size_t total = k + n_new;
  solid.type.assign(total, ElemType::Tet4);
  solid.offset.resize(total + 1);
  for (std::size_t e = 0; e <= total; ++e) solid.offset[e] = static_cast<std::int32_t>(4 * e);
  solid.node.resize(4 * k);
  solid.node.reserve(4 * total);
  for (std::size_t i = 0; i < w.added.size(); ++i)
    if (w.alive[w.n_input + i])
      for (const std::int32_t v : w.added[i]) solid.node.push_back(VertexId{v});
  Elements interface;
  for (std::size_t f = 0; f < w.faces.size(); ++f)
    if (w.face_alive[f]) interface.add(ElemType::Tri3, {VertexId{w.faces[f][0]}, VertexId{w.faces[f][1]}, VertexId{w.faces[f][2]}});
  mesh.interface = std::move(interface);
  if (st.contracted > 0) {
    // Compact the nodes: the removed ones go, the others keep their order.
    st.node_map.assign(n, -1);
    std::int32_t kept = 0;
    for (std::size_t v = 0; v < n; ++v)
      if (!w.node_dead[v]) st.node_map[v] = kept++;
    remap_nodes(st.node_map, mesh.points);
    for (Elements* elems : {&mesh.solid, &mesh.interface})
      for (VertexId& v : elems->node) {
        MESH_ASSERT(st.node_map[v.v] >= 0, "a removed node is still used");
        v.v = st.node_map[v.v];
      }
  }
  return st;
}

}  // namespace febemesh::dim3
