#pragma once
// rapidcheck generators of random closed, manifold, non-self-intersecting triangle surfaces for
// the 3D property suite (issue 5): perturbed icospheres, tori and unions of voxels, each under a
// random rotation, scaling and translation. A case is a handful of small integers, every one
// shrinking towards the simpler shape (no perturbation, fatter torus, fewer voxels, no rotation,
// unit scale), so a failure shrinks to a small geometry. A case prints itself as an OFF file,
// which is how shrunk counterexamples are kept under tests/dim3/regressions/.
//
// Why each kind is valid by construction:
// - sphere: r(u) = 1 + p(u) over the unit directions u of an icosphere, p a combination of
//   low-order polynomials with sum |c_k| <= max_perturbation < 1, so r > 0: the surface is a
//   radial graph (star-shaped about the origin), each triangle stays inside the cone of its
//   spherical triangle, and cones of different triangles meet only on shared edges;
// - torus: minor radius <= 0.5 of the major one;
// - voxels: one face-connected set of cells of a g^3 grid (g <= 4) whose boundary quads are
//   split into triangles; cells are added until no lattice edge has two diagonal cells only and
//   no lattice vertex has a disconnected set of filled or of empty cells around it (the union
//   is then a 2-manifold), and enclosed cavities are filled (one boundary component).

#include <array>
#include <ostream>
#include <string>
#include <vector>

#include <rapidcheck.h>

#include "dim3/surface.hpp"

namespace febemesh::test {

inline constexpr double max_perturbation = 0.35;

enum class ShapeKind { Sphere, Torus, Voxels };
const char* name(ShapeKind k);

/// Rigid rotation (Euler angles z-y-x in degrees), uniform scale 2^(scale_quarters / 4),
/// translation in units of 0.1.
struct Pose {
  std::array<int, 3> degrees{0, 0, 0};
  int scale_quarters = 0;
  std::array<int, 3> shift{0, 0, 0};
};

struct SurfaceSpec {
  ShapeKind kind = ShapeKind::Sphere;
  // sphere
  int subdivisions = 1;            ///< icosphere: 20 * 4^subdivisions triangles
  std::array<int, 9> harmonics{};  ///< coefficients of the radial perturbation, in units of 0.04
  // torus (major radius 1)
  int minor_step = 0;              ///< minor radius 0.5 - 0.05 * minor_step
  int major_segments = 12, minor_segments = 8;
  // voxels
  int grid = 2;
  std::vector<int> cells;          ///< filled cells, ascending (x + g * (y + g * z)), after fixing
  Pose pose;
  int level = 3;                   ///< the pipeline level the case is meshed at
};

/// The triangles, oriented outward (positive volume), with no unused vertices.
dim3::TriangleSoup to_soup(const SurfaceSpec& spec);
/// to_soup as an indexed Surface.
dim3::Surface to_surface(const SurfaceSpec& spec);
/// V - E + F the surface has by construction (2 sphere, 0 torus, 2 - 2 genus for voxels: from
/// the soup, checked against the kind in the unit test).
int expected_euler(const SurfaceSpec& spec);
/// Exact enclosed volume where known in closed form (voxels: cells x cell volume), else 0.
double exact_volume(const SurfaceSpec& spec);

/// The voxel fix-up: adds cells to `cells` (ascending indices of a g^3 grid) until the union is
/// a face-connected 2-manifold solid without cavities; keeps only the face-connected component
/// of the smallest cell. Exposed for the unit test.
std::vector<int> manifold_voxels(int grid, std::vector<int> cells);

/// The case as OFF text; the first line after "OFF" is a comment with the level and the spec.
std::string to_off(const SurfaceSpec& spec);
/// A one-line description (kind, sizes, pose) for logs and tags.
std::string describe(const SurfaceSpec& spec);

rc::Gen<Pose> gen_pose();
/// Icospheres of 1 or 2 subdivisions (80 / 320 triangles), or exactly `min_subdivisions` when
/// it is 2 or more (the coarse ones have sharper edges: see test_pipeline3d_properties.cpp).
rc::Gen<SurfaceSpec> gen_sphere_spec(int min_subdivisions = 1);
rc::Gen<SurfaceSpec> gen_torus_spec();
rc::Gen<SurfaceSpec> gen_voxel_spec();
/// One of the three kinds (sphere first: shrinking moves towards it).
rc::Gen<SurfaceSpec> gen_surface_spec();

void showValue(const SurfaceSpec& spec, std::ostream& os);

}  // namespace febemesh::test
