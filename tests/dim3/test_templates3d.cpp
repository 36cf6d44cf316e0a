// Templates on hand-built 2:1 octrees: the interior templates tile the cube conformingly, and
// with boundary octants (projections pushed radially out of a box-shaped interior region) the
// mesh is valid: positive, conforming, interface = boundary faces, V - E + F - C = 1.

#include <catch2/catch.hpp>
#include <rapidcheck.h>

#include <cmath>
#include <map>

#include "core/free_facets.hpp"
#include "core/orthtree.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim3/templates3d.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

/// Uniform to `base` levels, then `rounds` of refinement of the leaves picked by `pick`, then
/// full 2:1 balance.
Orthtree<3> random_tree(int base, const std::vector<std::vector<bool>>& picks) {
  Orthtree<3> t;
  for (int l = 0; l < base; ++l) t = refine(t, Flags(t.n_leaves(), 1));
  for (const auto& pick : picks) {
    Flags f(t.n_leaves(), 0);
    for (std::size_t i = 0; i < t.n_leaves(); ++i) f[i] = pick.empty() ? 0 : pick[i % pick.size()] ? 1 : 0;
    t = balance_2to1(refine(t, f), BalanceKind::Full);
  }
  return balance_2to1(t, BalanceKind::Full);
}

/// Interior = every leaf inside the box [lo, hi]^3; boundary octants on its free faces with
/// projections pushed radially away from the box centre by `factor`.
OctantComplex box_complex(const Orthtree<3>& t, double lo, double hi, double factor, Flags& in) {
  in.assign(t.n_leaves(), 0);
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    const Box<3> b = geometry(t, t.leaf(i));
    in[i] = (b.lo.array() >= lo - 1e-12).all() && (b.hi.array() <= hi + 1e-12).all() ? 1 : 0;
  }
  OctantComplex oc;
  oc.lattice = lattice_nodes(t, &in);
  for (const auto& p : oc.lattice.points) oc.points.push_back(position(t, p));
  oc.where.assign(oc.points.size(), BoundaryLocation{});
  oc.projection.assign(oc.points.size(), -1);
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    if (in[i]) oc.interior.push_back(i);
  const P3 centre = P3::Constant(0.5 * (lo + hi));
  for (const FreeFacet<3>& f : free_facets(t, in)) {
    BoundaryOctant b;
    b.leaf = f.leaf;
    b.cell = f.cell;
    b.face = f.face;
    b.ring = face_ring(oc.lattice, f.cell, f.face, b.corner_slot);
    for (std::int32_t q : b.ring) {
      if (oc.projection[q] >= 0) continue;
      oc.projection[q] = static_cast<std::int32_t>(oc.points.size());
      oc.points.push_back(centre + factor * (oc.points[q] - centre));
      BoundaryLocation w;
      w.patch = 0;
      oc.where.push_back(w);
    }
    oc.boundary.push_back(std::move(b));
  }
  return oc;
}

ValidationReport check(const TetMesh& m) { return validate(m.mesh, ValidateOptions<3>{}); }

/// The same nodes, tetrahedra, attributes, interface and counts, array for array.
bool same_tets(const TetMesh& a, const TetMesh& b) {
  return a.mesh.points == b.mesh.points && a.where.size() == b.where.size() && a.mesh.solid.node == b.mesh.solid.node &&
         a.mesh.solid.offset == b.mesh.solid.offset && a.mesh.solid.type == b.mesh.solid.type &&
         a.mesh.level == b.mesh.level && a.mesh.from_boundary_cell == b.mesh.from_boundary_cell && a.cell == b.cell &&
         a.mesh.interface.node == b.mesh.interface.node && a.n_dropped_degenerate == b.n_dropped_degenerate &&
         a.n_fins_cancelled == b.n_fins_cancelled;
}

}  // namespace

TEST_CASE("quad split by the smallest id is independent of the starting corner", "[templates3d]") {
  std::vector<std::array<std::int32_t, 3>> a, b;
  triangulate_quad_by_id({7, 3, 9, 5}, a);
  triangulate_quad_by_id({9, 5, 7, 3}, b);
  REQUIRE(a.size() == 2);
  REQUIRE(b.size() == 2);
  // Both use the diagonal 3-5 (through id 3).
  for (const auto& t : a) CHECK((std::find(t.begin(), t.end(), 3) != t.end()));
  for (const auto& t : b) CHECK((std::find(t.begin(), t.end(), 3) != t.end()));
  std::vector<std::array<std::int32_t, 3>> c;
  triangulate_quad_by_id({4, 8, 8, 2}, c);  // coincident projections: a triangle
  CHECK(c.size() == 1);
}

TEST_CASE("interior templates of a uniform octree tile the cube", "[templates3d]") {
  const Orthtree<3> t = random_tree(2, {});
  Flags in(t.n_leaves(), 0);
  OctantComplex oc;
  oc.lattice = lattice_nodes(t);
  for (const auto& p : oc.lattice.points) oc.points.push_back(position(t, p));
  oc.where.assign(oc.points.size(), BoundaryLocation{});
  for (std::size_t i = 0; i < t.n_leaves(); ++i) oc.interior.push_back(i);
  const TetMesh m = tetrahedralize(t, oc, {});
  CHECK(m.mesh.solid.size() == 64 * 12);
  const ValidationReport r = check(m);
  CHECK(r.inverted == 0);
  CHECK(r.nonconforming_facets == 0);
  CHECK(r.hanging_nodes == 0);
  CHECK(r.euler == 1);
  CHECK(solid_measure<3>(m.mesh) == Approx(1.0));
}

TEST_CASE("templates with boundary octants on a refined box give a valid mesh", "[templates3d]") {
  std::vector<bool> pick(37);
  for (std::size_t i = 0; i < pick.size(); ++i) pick[i] = (i * 7) % 5 == 0;
  const Orthtree<3> t = random_tree(2, {pick, pick});
  REQUIRE(is_balanced(t, BalanceKind::Full));
  Flags in;
  const OctantComplex oc = box_complex(t, 0.25, 0.75, 1.6, in);
  const TetMesh m = tetrahedralize(t, oc, {});
  ValidateOptions<3> vo;
  vo.expected_euler = 1;
  const ValidationReport r = validate(m.mesh, vo);
  INFO(r.summary());
  CHECK(r.valid);
  // The cones fill the box and the shell between it and the pushed-out projections.
  CHECK(solid_measure<3>(m.mesh) == Approx(std::pow(0.5 * 1.6, 3)));
}

TEST_CASE("templates are conforming on random 2:1 octrees", "[templates3d][property]") {
  test::prop("interior and boundary octants conform", 25, [] {
    const int rounds = *rc::gen::inRange(1, 3);
    std::vector<std::vector<bool>> picks;
    for (int r = 0; r < rounds; ++r)
      picks.push_back(*rc::gen::container<std::vector<bool>>(*rc::gen::inRange(1, 23), rc::gen::arbitrary<bool>()));
    const Orthtree<3> t = random_tree(2, picks);
    RC_ASSERT(is_balanced(t, BalanceKind::Full));
    Flags in;
    const OctantComplex oc = box_complex(t, 0.25, 0.75, 1.5, in);
    const TetMesh m = tetrahedralize(t, oc, {});
    ValidateOptions<3> vo;
    vo.expected_euler = 1;
    const ValidationReport r = validate(m.mesh, vo);
    RC_LOG() << r.summary();
    RC_ASSERT(r.valid);
    RC_ASSERT(std::abs(solid_measure<3>(m.mesh) - std::pow(0.75, 3)) < 1e-9);
    // The interior octants are built on threads: the same nodes and tetrahedra on any count.
    for (const int n_threads : {2, 3}) {
      RC_ASSERT(same_tets(tetrahedralize(t, oc, {}, n_threads), m));
    }
  });
}

TEST_CASE("the interior part kept between calls gives the mesh a fresh call gives", "[templates3d][property]") {
  // The repair's rounds move the complex's projections and build again on the same tree: the
  // second call takes the interior octants' part from the first's mesh. Its result must be the
  // fresh call's, array for array, on any thread count.
  test::prop("kept interior part", 20, [] {
    std::vector<std::vector<bool>> picks;
    for (int r = 0; r < *rc::gen::inRange(1, 3); ++r)
      picks.push_back(*rc::gen::container<std::vector<bool>>(*rc::gen::inRange(1, 23), rc::gen::arbitrary<bool>()));
    const Orthtree<3> t = random_tree(2, picks);
    Flags in;
    OctantComplex oc = box_complex(t, 0.25, 0.75, 1.5, in);
    const int n_threads = *rc::gen::inRange(1, 4);
    InteriorTets kept;
    const TetMesh first = tetrahedralize(t, oc, {}, n_threads, &kept);
    RC_ASSERT(kept.filled);
    RC_ASSERT(first.mesh.points == tetrahedralize(t, oc, {}, n_threads).mesh.points);
    // Projections pushed further out, each by its own factor.
    const std::int32_t n_lattice = oc.n_lattice();
    const P3 centre = P3::Constant(0.5);
    for (std::size_t v = static_cast<std::size_t>(n_lattice); v < oc.points.size(); ++v)
      oc.points[v] = centre + (1.0 + 0.05 * static_cast<double>(v % 7)) * (oc.points[v] - centre);
    const TetMesh again = tetrahedralize(t, oc, {}, n_threads, &kept, &first);
    const TetMesh fresh = tetrahedralize(t, oc, {}, n_threads);
    // A last mesh that does not begin with the interior tetrahedra (its first one turned
    // over) is not used: built again, the same result.
    TetMesh other = first;
    std::swap(other.mesh.solid.node[0], other.mesh.solid.node[1]);
    InteriorTets kept_other = kept;
    const TetMesh rebuilt = tetrahedralize(t, oc, {}, n_threads, &kept_other, &other);
    RC_ASSERT(same_tets(rebuilt, fresh));
    RC_ASSERT(same_tets(again, fresh));
    // And the moved projections did change the mesh (the test compares something).
    RC_ASSERT(!(again.mesh.points == first.mesh.points));
  });
}
