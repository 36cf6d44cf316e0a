// tet_optimize: the search rank (no acos) orders tetrahedra like the angle-based search quality
// (its slow twin) and has its sign; the optimiser never lowers the worst dihedral angle or
// inverts a tetrahedron, and gives the same mesh when run twice and on any number of threads;
// the ranks handed from pass to pass are those a pass would compute.

#include <catch2/catch.hpp>
#include <rapidcheck.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/mesh.hpp"
#include "dim3/edge_removal.hpp"
#include "dim3/tet_optimize.hpp"
#include "property.hpp"
#include "core/test_mesh_fixtures.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

using P3 = Point<3>;

rc::Gen<P3> gen_point() {
  return rc::gen::map(rc::gen::tuple(rc::gen::inRange(-1000, 1001), rc::gen::inRange(-1000, 1001),
                                     rc::gen::inRange(-1000, 1001)),
                      [](const std::tuple<int, int, int>& t) {
                        return P3(std::get<0>(t) / 1000.0, std::get<1>(t) / 1000.0, std::get<2>(t) / 1000.0);
                      });
}

/// A jittered cube of n^3 nodes cut into six tetrahedra per cell (Kuhn, test::grid_mesh), all
/// positive: the inner nodes moved by up to jitter/2 along each axis, then every tetrahedron the
/// jitter turned over reoriented.
Mesh<3> jittered_cube(double jitter, unsigned seed, int n = 5) {
  Mesh<3> m = test::grid_mesh<3>(n - 1, true);
  m.interface.clear();
  m.level.clear();
  m.from_boundary_cell.clear();
  std::uint64_t s = seed;
  auto rnd = [&] {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) / double(1ULL << 53) - 0.5;
  };
  for (P3& p : m.points)
    if (p.minCoeff() > 0 && p.maxCoeff() < n - 1) p += jitter * P3(rnd(), rnd(), rnd());
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    VertexId* t = m.solid.node.data() + m.solid.offset[e];
    const P3 &a = m.points[t[0].v], &b = m.points[t[1].v], &c = m.points[t[2].v], &d = m.points[t[3].v];
    if ((b - a).dot((c - a).cross(d - a)) < 0) std::swap(t[2], t[3]);
  }
  return m;
}

/// 1 at the nodes on the faces of the cube [0, side]^3 (jittered_cube's boundary, which stays
/// put: no surface projection here), else 0: TetOptimizeOptions::fixed.
std::vector<std::uint8_t> cube_faces_fixed(const Mesh<3>& m, double side) {
  std::vector<std::uint8_t> fixed(m.points.size(), 0);
  for (std::size_t v = 0; v < m.points.size(); ++v)
    fixed[v] = m.points[v].minCoeff() == 0.0 || m.points[v].maxCoeff() == side ? 1 : 0;
  return fixed;
}

double min_dihedral(const Mesh<3>& m) {
  double lo = 180.0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const double q = tet_search_quality(m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]);
    lo = std::min(lo, q < 0 ? 0.0 : q * 180.0 / 3.14159265358979323846);
  }
  return lo;
}

}  // namespace

TEST_CASE("tet_search_rank has the sign of tet_search_quality and its order", "[tet_optimize][property]") {
  test::prop("sign and order", 300, [] {
    const auto p = *rc::gen::container<std::vector<P3>>(8, gen_point());
    const double q1 = tet_search_quality(p[0], p[1], p[2], p[3]), r1 = tet_search_rank(p[0], p[1], p[2], p[3]);
    const double q2 = tet_search_quality(p[4], p[5], p[6], p[7]), r2 = tet_search_rank(p[4], p[5], p[6], p[7]);
    RC_ASSERT((q1 < 0) == (r1 < 0));
    RC_ASSERT((q1 > 0) == (r1 > 0));
    if (q1 < 0) RC_ASSERT(r1 == q1);  // inverted and flat ones: the same value
    // Positive ones: the same order unless the two angles agree to rounding.
    if (q1 > 0 && q2 > 0 && std::abs(q1 - q2) > 1e-9) RC_ASSERT((q1 < q2) == (r1 < r2));
  });
}

TEST_CASE("tet_untangle_rank is tet_search_rank at or below 0, and 1 only above 1e-9", "[tet_optimize][property]") {
  // Random tetrahedra and slivers: a random triangle and a fourth point at a height of
  // 10^-k of its size over a random point of its plane, either side, at random scales.
  test::prop("untangle rank", 2000, [] {
    const auto p = *rc::gen::container<std::vector<P3>>(5, gen_point());
    const int k = *rc::gen::inRange(0, 16);
    const int scale = *rc::gen::inRange(-6, 7);
    const bool sliver = *rc::gen::arbitrary<bool>();
    const P3 n = (p[1] - p[0]).cross(p[2] - p[0]);
    RC_PRE(n.norm() > 1e-6);
    const P3 d = sliver ? P3(p[3] + (p[4][0] > 0 ? 1.0 : -1.0) * std::pow(10.0, -k) * n / n.norm() -
                             (p[3] - p[0]).dot(n) / n.squaredNorm() * n)
                        : p[3];
    const double f = std::pow(10.0, scale);
    const P3 a = f * p[0], b = f * p[1], c = f * p[2], e = f * d;
    const double rank = tet_search_rank(a, b, c, e), fast = tet_untangle_rank(a, b, c, e);
    RC_ASSERT((fast == 1.0 && rank > 1e-9) || fast == rank);
    if (rank <= 0) RC_ASSERT(fast == rank);
  });
  const P3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
  CHECK(tet_untangle_rank(a, b, c, d) == 1.0);  // well shaped: not ranked
  CHECK(tet_untangle_rank(a, c, b, d) == tet_search_rank(a, c, b, d));  // inverted: its rank
  const P3 flat(0.3, 0.3, 1e-12);  // positive, mean ratio below 1e-3: ranked
  CHECK(tet_untangle_rank(a, b, c, flat) == tet_search_rank(a, b, c, flat));
}

TEST_CASE("tet_search_rank of known tetrahedra", "[tet_optimize]") {
  const P3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
  // The corner tetrahedron: smallest dihedral angle acos(1/sqrt3) (at the slanted face's edges).
  const double angle = std::acos(1.0 / std::sqrt(3.0));
  CHECK(tet_search_quality(a, b, c, d) == Approx(angle));
  const double cs = std::cos(angle);
  CHECK(tet_search_rank(a, b, c, d) == Approx(1.0 - cs * cs));
  CHECK(tet_search_rank(a, c, b, d) < -1.0);  // inverted
  CHECK(tet_search_rank(a, b, P3(2, 0, 0), d) <= -1.0);  // flat
}

TEST_CASE("optimize_tets raises the worst dihedral angle, inverts nothing, is repeatable", "[tet_optimize]") {
  for (const unsigned seed : {1u, 2u, 3u}) {
    Mesh<3> m = jittered_cube(0.6, seed);
    const double before = min_dihedral(m);
    std::vector<BoundaryLocation> where(m.points.size());
    TetOptimizeOptions opt;
    opt.max_sweeps = 16;
    opt.fixed = cube_faces_fixed(m, 4.0);
    Mesh<3> again = m;
    std::vector<BoundaryLocation> where2 = where;
    const TetOptimizeStats st = optimize_tets(m, where, opt);
    optimize_tets(again, where2, opt);
    CAPTURE(seed, before, st.min_dihedral_after_deg);
    CHECK(st.inverted_after == 0);
    CHECK(st.moves > 0);
    CHECK(min_dihedral(m) > before);
    CHECK(st.min_dihedral_after_deg == Approx(min_dihedral(m)).margin(1e-6));
    CHECK(m.points == again.points);
  }
}

TEST_CASE("optimize_tets gives the same mesh on 1, 2 and 3 threads", "[tet_optimize][threads]") {
  // 13^3 nodes: more than a thousand active ones, so that the sweeps run on several threads.
  // The cube's edges and corners stay; with a projection, the nodes of its faces slide on them.
  const int n = 13;
  const double hi = n - 1;
  for (const bool slide : {false, true}) {
    const Mesh<3> start = jittered_cube(0.6, 4, n);
    std::vector<BoundaryLocation> where(start.points.size());
    TetOptimizeOptions opt;
    opt.max_sweeps = 8;
    opt.fixed.assign(start.points.size(), 0);
    for (std::size_t v = 0; v < start.points.size(); ++v) {
      int on = 0;
      for (int d = 0; d < 3; ++d) on += start.points[v][d] == 0.0 || start.points[v][d] == hi;
      opt.fixed[v] = on >= (slide ? 2 : 1) ? 1 : 0;
      if (on == 1) where[v].patch = 0;
    }
    if (slide) {
      opt.project = [hi](const P3& p) {
        P3 q = p.cwiseMax(0.0).cwiseMin(hi);
        int best = 0;
        double dist = 1e300;
        for (int d = 0; d < 3; ++d)
          for (const double side : {0.0, hi})
            if (std::abs(q[d] - side) < dist) dist = std::abs(q[d] - side), best = 2 * d + (side > 0);
        q[best / 2] = best % 2 ? hi : 0.0;
        BoundaryLocation w;
        w.patch = best;
        return std::make_pair(q, w);
      };
    }
    Mesh<3> one = start;
    std::vector<BoundaryLocation> where1 = where;
    const TetOptimizeStats s1 = optimize_tets(one, where1, opt);
    CAPTURE(slide);
    REQUIRE(s1.moves > 1000);
    for (const int threads : {2, 3}) {
      Mesh<3> many = start;
      std::vector<BoundaryLocation> wheren = where;
      opt.n_threads = threads;
      const TetOptimizeStats sn = optimize_tets(many, wheren, opt);
      CAPTURE(threads);
      CHECK(many.points == one.points);
      CHECK(sn.moves == s1.moves);
      CHECK(sn.sweeps == s1.sweeps);
      CHECK(sn.min_dihedral_after_deg == s1.min_dihedral_after_deg);
      bool same_where = true;
      for (std::size_t v = 0; v < where.size(); ++v)
        same_where = same_where && wheren[v].patch == where1[v].patch;
      CHECK(same_where);
    }
  }
}

TEST_CASE("optimize_tets slides feature-line nodes along their lines only", "[tet_optimize]") {
  // The cube's edges are the feature lines: their inner nodes, shifted along them, slide; the
  // corners and the nodes inside its faces stay put.
  const int n = 5;
  const double hi = n - 1;
  Mesh<3> m = jittered_cube(0.6, 5, n);
  std::vector<BoundaryLocation> where(m.points.size());
  TetOptimizeOptions opt;
  opt.max_sweeps = 16;
  opt.fixed.assign(m.points.size(), 0);
  opt.on_line.assign(m.points.size(), 0);
  std::vector<int> free_axis(m.points.size(), -1);
  std::size_t n_line = 0;
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    int on = 0, axis = -1;
    for (int d = 0; d < 3; ++d) {
      if (m.points[v][d] == 0.0 || m.points[v][d] == hi) ++on;
      else axis = d;
    }
    opt.fixed[v] = on == 1 || on == 3 ? 1 : 0;
    if (on != 2) continue;
    free_axis[v] = axis;
    m.points[v][axis] += (v % 2 ? 0.3 : -0.3);
    where[v].patch = 0;
    where[v].kind = BoundaryLocation::Kind::FeatureEdge;
    opt.on_line[v] = 1;
    ++n_line;
  }
  REQUIRE(n_line == 12 * (n - 2));
  const double before = min_dihedral(m);
  opt.project = [](const P3& p) { return std::make_pair(p, BoundaryLocation{}); };  // unused here
  opt.slide = [hi](const P3& x0, const BoundaryLocation& w0, const P3& x) {
    LineSlide s;
    s.point = x0;
    s.where = w0;
    for (int d = 0; d < 3; ++d)
      if (x0[d] != 0.0 && x0[d] != hi) s.point[d] = std::clamp(x[d], 0.0, hi), s.tangent[d] = 1.0;
    return s;
  };
  const Mesh<3> start = m;
  const TetOptimizeStats st = optimize_tets(m, where, opt);
  CHECK(st.inverted_after == 0);
  CHECK(min_dihedral(m) > before);
  std::size_t moved = 0;
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    if (free_axis[v] < 0) continue;
    for (int d = 0; d < 3; ++d)
      if (d != free_axis[v]) CHECK(m.points[v][d] == start.points[v][d]);  // still on its edge
    CHECK(where[v].kind == BoundaryLocation::Kind::FeatureEdge);
    moved += m.points[v] != start.points[v] ? 1 : 0;
  }
  CHECK(moved > 0);
}

namespace {

/// tet_search_rank of every tetrahedron of m, in element order.
std::vector<double> ranks_of(const Mesh<3>& m) {
  std::vector<double> r;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    r.push_back(tet_search_rank(m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]));
  }
  return r;
}

}  // namespace

TEST_CASE("ranks handed between sweeps and edge removal are a pass's own, and change nothing", "[tet_optimize][edge_removal]") {
  // The pipeline's order: sweeps, then edge removal rounds each followed by sweeps; once
  // ranking every tetrahedron in each pass, once handing the ranks on. Same mesh, bit for bit,
  // and the ranks handed out are tet_search_rank's at the end of every pass.
  for (const unsigned seed : {5u, 6u}) {
    const int n = 9;
    const Mesh<3> start = jittered_cube(0.7, seed, n);
    std::vector<BoundaryLocation> where(start.points.size());
    TetOptimizeOptions to;
    to.max_sweeps = 6;
    to.fixed = cube_faces_fixed(start, n - 1.0);
    EdgeRemovalOptions eo;
    eo.below_deg = 30.0;
    eo.contract_below_deg = 20.0;
    for (const int threads : {1, 2}) {
      Mesh<3> plain = start, handed = start;
      std::vector<BoundaryLocation> where_plain = where, where_handed = where;
      TetOptimizeOptions to_plain = to, to_handed = to;
      to_plain.n_threads = to_handed.n_threads = threads;
      EdgeRemovalOptions eo_plain = eo, eo_handed = eo;
      std::vector<double> ranks;
      to_handed.ranks = &ranks;
      eo_handed.ranks = &ranks;
      std::size_t moves = 0, removed = 0;
      CAPTURE(seed, threads);
      for (int pass = 0; pass < 3; ++pass) {
        const TetOptimizeStats a = optimize_tets(plain, where_plain, to_plain);
        const TetOptimizeStats b = optimize_tets(handed, where_handed, to_handed);
        CAPTURE(pass);
        CHECK(a.moves == b.moves);
        CHECK(a.min_dihedral_after_deg == b.min_dihedral_after_deg);
        REQUIRE(handed.points == plain.points);
        CHECK(ranks == ranks_of(handed));
        moves += a.moves;
        const EdgeRemovalStats ea = remove_bad_edges(plain, where_plain, nullptr, eo_plain);
        const EdgeRemovalStats eb = remove_bad_edges(handed, where_handed, nullptr, eo_handed);
        remap_nodes(ea.node_map, to_plain.fixed);
        remap_nodes(ea.node_map, where_plain);
        remap_nodes(eb.node_map, to_handed.fixed);
        remap_nodes(eb.node_map, where_handed);
        CHECK(ea.removed == eb.removed);
        CHECK(ea.contracted == eb.contracted);
        REQUIRE(handed.solid.node == plain.solid.node);
        REQUIRE(handed.points == plain.points);
        CHECK(ranks == ranks_of(handed));
        removed += ea.removed + ea.contracted;
      }
      // The sequence did something to hand on.
      CHECK(moves > 0);
      CHECK(removed > 0);
    }
  }
}

TEST_CASE("untangling without ranking the positive tetrahedra moves the nodes ranking them all moves", "[tet_optimize]") {
  // untangle_only ranks only the tetrahedra at or below 0 (tet_untangle_rank) unless ranks are
  // handed back, which ranks them all: the same moves either way, on 1 and 2 threads.
  for (const unsigned seed : {3u, 4u}) {
    const int n = 7;
    Mesh<3> start = jittered_cube(0.3, seed, n);
    // Every fifth inner node pushed 0.8 away: its tetrahedra turn over.
    int pushed = 0;
    for (std::size_t v = 0; v < start.points.size(); ++v)
      if (start.points[v].minCoeff() > 0 && start.points[v].maxCoeff() < n - 1 && v % 5 == 0)
        start.points[v] += P3(0.8, -0.5, 0.6), ++pushed;
    REQUIRE(pushed > 5);
    std::vector<BoundaryLocation> where(start.points.size());
    TetOptimizeOptions to;
    to.untangle_only = true;
    to.max_sweeps = 30;
    to.fixed = cube_faces_fixed(start, n - 1.0);
    for (const int threads : {1, 2}) {
      Mesh<3> plain = start, ranked = start;
      std::vector<BoundaryLocation> where_plain = where, where_ranked = where;
      TetOptimizeOptions to_plain = to, to_ranked = to;
      to_plain.n_threads = to_ranked.n_threads = threads;
      std::vector<double> ranks;
      to_ranked.ranks = &ranks;
      const TetOptimizeStats a = optimize_tets(plain, where_plain, to_plain);
      const TetOptimizeStats b = optimize_tets(ranked, where_ranked, to_ranked);
      CAPTURE(seed, threads, a.inverted_before, a.inverted_after);
      CHECK(a.inverted_before > 0);
      CHECK(a.inverted_after < a.inverted_before);
      CHECK(a.moves > 0);
      CHECK(a.moves == b.moves);
      CHECK(a.sweeps == b.sweeps);
      CHECK(a.inverted_before == b.inverted_before);
      CHECK(a.inverted_after == b.inverted_after);
      CHECK(plain.points == ranked.points);
    }
  }
}

TEST_CASE("optimize_tets keeps each node in its bounds box; empty boxes bound nothing", "[tet_optimize]") {
  for (const unsigned seed : {1u, 2u}) {
    const Mesh<3> start = jittered_cube(0.6, seed);
    std::vector<BoundaryLocation> where(start.points.size());
    TetOptimizeOptions opt;
    opt.max_sweeps = 16;
    opt.fixed = cube_faces_fixed(start, 4.0);
    // Unbounded, the optimiser moves nodes further than 0.02.
    Mesh<3> free_mesh = start;
    std::vector<BoundaryLocation> w1 = where;
    optimize_tets(free_mesh, w1, opt);
    double far = 0.0;
    for (std::size_t v = 0; v < start.points.size(); ++v)
      far = std::max(far, (free_mesh.points[v] - start.points[v]).cwiseAbs().maxCoeff());
    CHECK(far > 0.02);
    // Empty boxes: the same mesh as without bounds.
    Mesh<3> empty_boxes = start;
    std::vector<BoundaryLocation> w2 = where;
    TetOptimizeOptions with_empty = opt;
    with_empty.bounds.assign(start.points.size(), Box<3>::empty());
    optimize_tets(empty_boxes, w2, with_empty);
    CHECK(empty_boxes.points == free_mesh.points);
    // Boxes of +-0.02 around the start: every node stays in its own, none inverts.
    Mesh<3> bounded = start;
    std::vector<BoundaryLocation> w3 = where;
    TetOptimizeOptions tight = opt;
    for (const P3& p : start.points) {
      Box<3> b;
      b.lo = p.array() - 0.02;
      b.hi = p.array() + 0.02;
      tight.bounds.push_back(b);
    }
    const TetOptimizeStats st = optimize_tets(bounded, w3, tight);
    CAPTURE(seed);
    CHECK(st.inverted_after == 0);
    CHECK(st.moves > 0);
    for (std::size_t v = 0; v < start.points.size(); ++v) CHECK(tight.bounds[v].contains(bounded.points[v]));
  }
}
