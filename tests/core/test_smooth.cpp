// core/smooth.hpp: the guard never lets an element invert or the minimum quality drop; the
// result is the same, bit for bit, on any number of threads.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/quality.hpp"
#include "core/smooth.hpp"
#include "core/validate.hpp"
#include "property.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;

namespace {

template <int Dim> bool on_grid_boundary(const Point<Dim>& p, double size) {
  for (int d = 0; d < Dim; ++d)
    if (p[d] == 0.0 || p[d] == size) return true;
  return false;
}

/// Interior nodes of an n-grid moved by up to `amount` cell sizes, deterministic in `seed`.
template <int Dim> Mesh<Dim> perturbed(int n, bool simplices, double amount, unsigned seed) {
  Mesh<Dim> mesh = test::grid_mesh<Dim>(n, simplices);
  unsigned s = seed * 2654435761u + 12345u;
  auto next = [&] {
    s = s * 1664525u + 1013904223u;
    return (s >> 8) / double(1 << 24) * 2.0 - 1.0;
  };
  for (auto& p : mesh.points)
    if (!on_grid_boundary<Dim>(p, n))
      for (int d = 0; d < Dim; ++d) p[d] += amount * next();
  return mesh;
}

/// The nearest point on a facet of the box [0, n]^Dim (boundary nodes sliding on the box).
template <int Dim> Point<Dim> onto_box_facet(const Point<Dim>& p, int n) {
  Point<Dim> q = p.cwiseMax(0.0).cwiseMin(double(n));
  int best = 0;
  double dist = 1e300;
  for (int d = 0; d < Dim; ++d)
    for (const double side : {0.0, double(n)})
      if (std::abs(q[d] - side) < dist) dist = std::abs(q[d] - side), best = 2 * d + (side > 0);
  q[best / 2] = best % 2 ? n : 0.0;
  return q;
}

/// 1 for the nodes on the box's edges and corners (on two facets or more), which stay.
template <int Dim> std::vector<std::uint8_t> box_edges_fixed(const Mesh<Dim>& m, int n) {
  std::vector<std::uint8_t> fixed(m.points.size(), 0);
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    int on = 0;
    for (int d = 0; d < Dim; ++d) on += m.points[i][d] == 0.0 || m.points[i][d] == n;
    fixed[i] = on >= 2;
  }
  return fixed;
}

template <int Dim> double min_quality(const Mesh<Dim>& m) {
  const auto q = scaled_jacobians<Dim>(m.solid, m.points);
  return *std::min_element(q.begin(), q.end());
}

/// smooth(start, opt) on 2 and 3 threads moves the points and counts the moves as `one` and
/// `s1`, its run on one thread, did.
template <int Dim>
void check_same_on_threads(const Mesh<Dim>& start, SmoothOptions<Dim> opt, const Mesh<Dim>& one, const SmoothStats& s1) {
  for (const int threads : {2, 3}) {
    Mesh<Dim> many = start;
    opt.n_threads = threads;
    const SmoothStats sn = smooth(many, opt);
    CAPTURE(threads);
    CHECK(many.points == one.points);
    CHECK(sn.moves_accepted == s1.moves_accepted);
    CHECK(sn.moves_rejected == s1.moves_rejected);
    CHECK(sn.min_quality_after == s1.min_quality_after);
  }
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("smoothing improves a perturbed grid and keeps the boundary", "[smooth]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    Mesh<Dim> mesh = perturbed<Dim>(4, simplices, 0.3, 7);
    REQUIRE(is_valid(mesh));
    const Mesh<Dim> before = mesh;
    const SmoothStats stats = smooth(mesh);
    CHECK(stats.iterations == 4);
    CHECK(stats.moves_accepted > 0);
    CHECK(stats.min_quality_after >= stats.min_quality_before);
    CHECK(stats.min_quality_after == min_quality(mesh));
    CHECK(min_quality(mesh) > min_quality(before));
    for (std::size_t i = 0; i < mesh.points.size(); ++i)
      if (on_grid_boundary<Dim>(before.points[i], 4)) CHECK(mesh.points[i] == before.points[i]);
    CHECK(is_valid(mesh));
  }
}

TEMPLATE_TEST_CASE_SIG("min_move: a target within rounding of the node is no move; real ones still are",
                       "[smooth]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    CAPTURE(simplices);
    // A grid whose interior nodes are off their centroids by rounding only (1e-13 of a cell).
    const Mesh<Dim> noisy = perturbed<Dim>(4, simplices, 1e-13, 5);
    SmoothOptions<Dim> opt;
    Mesh<Dim> plain = noisy;
    const SmoothStats tried = smooth(plain, opt);
    CHECK(tried.moves_accepted + tried.moves_rejected > 0);  // without it, every node is tried
    opt.min_move = 1e-10;
    Mesh<Dim> kept = noisy;
    const SmoothStats none = smooth(kept, opt);
    CHECK(none.moves_accepted == 0);
    CHECK(none.moves_rejected == 0);
    CHECK(kept.points == noisy.points);
    // Real moves are made as before: the same points as without the threshold.
    const Mesh<Dim> rough = perturbed<Dim>(4, simplices, 0.3, 7);
    Mesh<Dim> with = rough, without = rough;
    const SmoothStats sw = smooth(with, opt);
    smooth(without, SmoothOptions<Dim>{});
    CHECK(sw.moves_accepted > 0);
    CHECK(min_quality(with) > min_quality(rough));
    for (std::size_t i = 0; i < with.points.size(); ++i)
      CHECK((with.points[i] - without.points[i]).cwiseAbs().maxCoeff() < 1e-9);
    check_same_on_threads(rough, opt, with, sw);
  }
}

TEMPLATE_TEST_CASE_SIG("fixed nodes do not move", "[smooth]", ((int Dim), Dim), 2, 3) {
  Mesh<Dim> mesh = perturbed<Dim>(3, true, 0.2, 3);
  const Mesh<Dim> before = mesh;
  SmoothOptions<Dim> opt;
  opt.fixed.assign(mesh.points.size(), 1);
  const SmoothStats stats = smooth(mesh, opt);
  CHECK(stats.moves_accepted == 0);
  CHECK(mesh.points == before.points);
}

TEMPLATE_TEST_CASE_SIG("boundary nodes slide with a projection", "[smooth]", ((int Dim), Dim), 2, 3) {
  const int n = 4;
  Mesh<Dim> mesh = test::grid_mesh<Dim>(n, true);
  // Crowd the boundary nodes of the lower facet towards x = 0 (stay on the facet).
  for (auto& p : mesh.points)
    if (p[1] == 0.0 && p[0] > 0.0 && p[0] < n) p[0] *= 0.5;
  REQUIRE(is_valid(mesh));
  const double q_before = min_quality(mesh);
  // Projection onto the nearest facet of the box [0, n]^Dim (n is a constant: no capture).
  auto project = [](const Point<Dim>& p) { return onto_box_facet<Dim>(p, n); };
  SmoothOptions<Dim> opt;
  opt.project = project;
  opt.fixed = box_edges_fixed(mesh, n);  // box corners and edges stay
  smooth(mesh, opt);
  ValidateOptions<Dim> vopt;
  vopt.boundary_distance = [&](const Point<Dim>& p) { return (project(p) - p).norm(); };
  vopt.boundary_tolerance = 1e-12;
  const ValidationReport r = validate(mesh, vopt);
  INFO(r.summary());
  CHECK(r.valid);
  CHECK(min_quality(mesh) > q_before);
}

TEMPLATE_TEST_CASE_SIG("smoothing never inverts an element", "[smooth][property]", ((int Dim), Dim), 2, 3) {
  febemesh::test::prop("no inversion, no quality drop", 40, [](unsigned seed, bool simplices) {
    const double amount = *rc::gen::inRange(5, 60) / 100.0;  // up to 0.6 cells: folded meshes too
    Mesh<Dim> mesh = perturbed<Dim>(3, simplices, amount, seed);
    std::vector<char> was_valid;
    for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
      const auto ep = element_points<Dim>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
      was_valid.push_back(min_corner_jacobian<Dim>(mesh.solid.type[e], ep.span()) > 0.0);
    }
    const SmoothStats stats = smooth(mesh);
    RC_ASSERT(stats.min_quality_after >= stats.min_quality_before);
    for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
      const auto ep = element_points<Dim>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
      if (was_valid[e]) RC_ASSERT(min_corner_jacobian<Dim>(mesh.solid.type[e], ep.span()) > 0.0);
    }
  });
}

TEMPLATE_TEST_CASE_SIG("smoothing gives the same points on 1, 2 and 3 threads", "[smooth][threads]", ((int Dim), Dim), 2, 3) {
  // Grids with more than a thousand interior nodes, so that the sweeps run on several threads.
  const int n = Dim == 2 ? 40 : 12;
  for (const bool simplices : {false, true}) {
    for (const bool slide : {false, true}) {
      const Mesh<Dim> start = perturbed<Dim>(n, simplices, 0.3, 11);
      SmoothOptions<Dim> opt;
      if (slide) {  // boundary nodes slide on the box's facets, its edges and corners stay
        opt.project = [n](const Point<Dim>& p) { return onto_box_facet<Dim>(p, n); };
        opt.fixed = box_edges_fixed(start, n);
      }
      Mesh<Dim> one = start;
      const SmoothStats s1 = smooth(one, opt);
      CAPTURE(simplices, slide);
      REQUIRE(s1.moves_accepted > 0);
      check_same_on_threads(start, opt, one, s1);
    }
  }
}

TEST_CASE("smoothing's one-pass neighbour lists (one thread) = the counted ones (threads)", "[smooth][threads]") {
  // On one thread the node neighbour lists of triangles, quads and lines are written in one
  // pass; on several they are counted first. A degenerate triangle (a node twice) lists that
  // node as its own neighbour twice in both; a grid of more than a thousand interior nodes so
  // that the lists and sweeps run on several threads.
  const int n = 40;
  for (const bool slide : {false, true}) {
    Mesh<2> start = perturbed<2>(n, true, 0.3, 7);
    // An interior node (the first element's first interior node) twice, with a neighbour.
    std::size_t e = 0;
    while (on_grid_boundary<2>(start.points[start.solid.nodes(ElemId{static_cast<std::int32_t>(e)})[0].v], n)) ++e;
    const VertexId* ev = start.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const VertexId a = ev[0], b = ev[1];
    start.solid.add(ElemType::Tri3, {a, a, b});
    SmoothOptions<2> opt;
    if (slide) {
      opt.project = [](const Point<2>& p) { return onto_box_facet<2>(p, n); };
      opt.fixed = box_edges_fixed(start, n);
    }
    Mesh<2> one = start;
    const SmoothStats s1 = smooth(one, opt);
    CAPTURE(slide);
    REQUIRE(s1.moves_accepted > 0);
    check_same_on_threads(start, opt, one, s1);
  }
}

TEMPLATE_TEST_CASE_SIG("states evaluated when first read move the points as the up-front ones; at_rest nodes are within rounding",
                       "[smooth][threads]", ((int Dim), Dim), 2, 3) {
  // Half the grid rough (0.3 cells), half off its centroids by rounding only (1e-13): most of
  // the quiet half's nodes settle at their first visit, reading no state.
  const int n = Dim == 2 ? 40 : 12;
  for (const bool simplices : {false, true}) {
    const Mesh<Dim> rough = perturbed<Dim>(n, simplices, 0.3, 13), quiet = perturbed<Dim>(n, simplices, 1e-13, 17);
    Mesh<Dim> start = quiet;
    for (std::size_t v = 0; v < start.points.size(); ++v)
      if (start.points[v][0] < 0.5 * n) start.points[v] = rough.points[v];
    // The 2D pipeline's options: every boundary node fixed, sweeps in parts, rounding share.
    SmoothOptions<Dim> opt;
    opt.fixed.assign(start.points.size(), 0);
    for (std::size_t v = 0; v < start.points.size(); ++v) opt.fixed[v] = on_grid_boundary<Dim>(quiet.points[v], n);
    opt.boundary_fixed = true;
    opt.parts = 4;
    opt.min_move = 1e-10;
    for (const int threads : {1, 2}) {
      CAPTURE(simplices, threads);
      opt.n_threads = threads;
      opt.min_quality = true;
      opt.at_rest = nullptr;
      Mesh<Dim> upfront = start;
      const SmoothStats su = smooth(upfront, opt);
      REQUIRE(su.moves_accepted > 0);
      opt.min_quality = false;
      std::vector<std::uint8_t> at_rest(3, 7);  // replaced
      opt.at_rest = &at_rest;
      Mesh<Dim> lazy = start;
      const SmoothStats sl = smooth(lazy, opt);
      CHECK(lazy.points == upfront.points);
      CHECK(sl.moves_accepted == su.moves_accepted);
      CHECK(sl.moves_rejected == su.moves_rejected);
      CHECK(sl.min_quality_after == 0.0);  // not computed
      if constexpr (Dim == 3) {
        CHECK(at_rest.empty());  // neighbours from lists, not gathered from polygons
      } else {
        REQUIRE(at_rest.size() == lazy.points.size());
        // Each node at rest: the centroid of its polygon neighbours (ascending) within rounding.
        std::size_t n_rest = 0;
        for (std::size_t v = 0; v < lazy.points.size(); ++v) {
          CHECK(at_rest[v] <= 1);
          if (at_rest[v] != 1) continue;
          ++n_rest;
          CHECK(!opt.fixed[v]);
          std::vector<std::int32_t> nbrs;
          for (std::size_t e = 0; e < lazy.solid.size(); ++e) {
            const VertexId* ev = lazy.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
            const int m = lazy.solid.n_nodes_of(ElemId{static_cast<std::int32_t>(e)});
            for (int k = 0; k < m; ++k)
              if (ev[k].v == static_cast<std::int32_t>(v)) nbrs.push_back(ev[(k + 1) % m].v), nbrs.push_back(ev[(k + m - 1) % m].v);
          }
          std::sort(nbrs.begin(), nbrs.end());
          nbrs.erase(std::unique(nbrs.begin(), nbrs.end()), nbrs.end());
          Point<Dim> target = Point<Dim>::Zero();
          for (const std::int32_t w : nbrs) target += lazy.points[static_cast<std::size_t>(w)];
          target /= static_cast<double>(nbrs.size());
          CHECK(within_rounding<Dim>(lazy.points, static_cast<std::int32_t>(v), nbrs, target, opt.min_move));
        }
        // Some: the rough half's moves spread over the sweeps and wake most of the quiet half.
        const auto n_free = static_cast<std::size_t>(std::count(opt.fixed.begin(), opt.fixed.end(), 0));
        CHECK(n_rest > 0);
        CHECK(n_rest < n_free);
        // All quiet: every free node at rest, none moved.
        Mesh<Dim> still = quiet;
        const SmoothStats sq = smooth(still, opt);
        CHECK(sq.moves_accepted == 0);
        CHECK(still.points == quiet.points);
        CHECK(static_cast<std::size_t>(std::count(at_rest.begin(), at_rest.end(), 1)) == n_free);
      }
    }
  }
}
