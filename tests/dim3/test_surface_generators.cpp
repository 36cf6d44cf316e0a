// The random-surface generators of the 3D property suite produce what they promise: closed,
// manifold, consistently and outwardly oriented, non-self-intersecting surfaces that pass the
// mesher's own input checks (dim3/surface_checks.hpp) with the expected topology and volume.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dim3/aabb_tree.hpp"
#include "dim3/read_surface.hpp"
#include "dim3/surface_checks.hpp"
#include "property.hpp"
#include "surface_generators.hpp"

using namespace febemesh;
using namespace febemesh::dim3;
using febemesh::test::ShapeKind;
using febemesh::test::SurfaceSpec;

namespace {

void check_generated(const SurfaceSpec& spec) {
  RC_TAG(test::name(spec.kind));
  Surface s = test::to_surface(spec);
  RC_ASSERT(s.n_used_vertices() == s.n_vertices());
  RC_ASSERT(boundary_edges(s).empty());
  RC_ASSERT(non_manifold_edges(s).empty());
  RC_ASSERT(non_manifold_vertices(s).empty());
  RC_ASSERT(degenerate_triangles(s).empty());
  const AabbTree tree(s.vertices(), s.triangles());
  RC_ASSERT(self_intersections(s, tree).empty());
  RC_ASSERT(is_consistently_oriented(s));
  RC_ASSERT(s.n_components() == 1);
  RC_ASSERT(s.volume() > 0.0);
  const int euler = s.euler_characteristic();
  if (spec.kind == ShapeKind::Sphere) RC_ASSERT(euler == 2);
  if (spec.kind == ShapeKind::Torus) RC_ASSERT(euler == 0);
  if (spec.kind == ShapeKind::Voxels) {
    RC_ASSERT(euler <= 2);
    RC_ASSERT(euler % 2 == 0);
    const double exact = test::exact_volume(spec);
    RC_ASSERT(std::abs(s.volume() - exact) <= 1e-12 * exact);
  }
  RC_ASSERT(test::expected_euler(spec) == euler);
  // The mesher's own acceptance: no throw, and nothing to flip (already outward).
  Surface checked = s;
  validate_surface(checked, "generated");
  RC_ASSERT(checked.triangles() == s.triangles());
  // The OFF text reads back to the same triangles and (to 17 digits) the same points.
  std::istringstream in(test::to_off(spec));
  const TriangleSoup back = read_off(in, "generated.off");
  RC_ASSERT(back.triangles == s.triangles());
  RC_ASSERT(back.vertices == s.vertices());
}

}  // namespace

TEST_CASE("generated surfaces are closed, manifold, outward and free of self-intersections",
          "[property][surface_generators]") {
  test::prop("perturbed spheres", 40, [] { check_generated(*test::gen_sphere_spec()); });
  test::prop("tori", 40, [] { check_generated(*test::gen_torus_spec()); });
  test::prop("voxel unions", 100, [] { check_generated(*test::gen_voxel_spec()); });
}

TEST_CASE("voxel fix-up: diagonal pairs get filled, cavities closed", "[surface_generators]") {
  // Two cells of a 2^3 grid sharing only an edge ((0,0,0) and (1,1,0)), or only a vertex
  // ((0,0,0) and (1,1,1)): cells are added until they share faces.
  for (const std::vector<int>& pair : {std::vector<int>{0, 3}, std::vector<int>{0, 7}}) {
    const std::vector<int> fixed = test::manifold_voxels(2, pair);
    CHECK(fixed.size() >= 3);
    CHECK(std::includes(fixed.begin(), fixed.end(), pair.begin(), pair.end()));
    SurfaceSpec spec;
    spec.kind = ShapeKind::Voxels;
    spec.grid = 2;
    spec.cells = fixed;
    const Surface s = test::to_surface(spec);
    CHECK(non_manifold_edges(s).empty());
    CHECK(non_manifold_vertices(s).empty());
    CHECK(s.n_components() == 1);
  }
  // A 3^3 shell around an empty centre: the centre is filled.
  std::vector<int> shell;
  for (int c = 0; c < 27; ++c)
    if (c != 13) shell.push_back(c);
  CHECK(test::manifold_voxels(3, shell).size() == 27);
  // A ring of 8 cells around the centre column of a 3x3x1 layer is a torus: kept as is.
  const std::vector<int> ring = {0, 1, 2, 3, 5, 6, 7, 8};
  CHECK(test::manifold_voxels(3, ring) == ring);
  SurfaceSpec spec;
  spec.kind = ShapeKind::Voxels;
  spec.grid = 3;
  spec.cells = ring;
  const Surface s = test::to_surface(spec);
  CHECK(s.euler_characteristic() == 0);
  CHECK(non_manifold_vertices(s).empty());
  CHECK(s.volume() == Approx(8.0 * 8.0 / 27.0));
}

TEST_CASE("a single voxel is a cube of 12 triangles", "[surface_generators]") {
  SurfaceSpec spec;
  spec.kind = ShapeKind::Voxels;
  spec.grid = 2;
  spec.cells = {5};
  const Surface s = test::to_surface(spec);
  CHECK(s.n_vertices() == 8);
  CHECK(s.n_triangles() == 12);
  CHECK(s.volume() == Approx(1.0));
  CHECK(s.euler_characteristic() == 2);
}
