#pragma once
// The validity contract of DESIGN.md ("Validity and quality"), checked exactly: orientation of
// every corner, conformity, hanging nodes, interface == boundary facets, node usage, distance of
// interface nodes to the boundary, Euler characteristic. Pipeline tests call this on every output.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace febemesh {

template <int Dim> struct ValidateOptions {
  /// Expected V - E + F (2D) / V - E + F - C (3D) of the solid; unchecked when empty.
  std::optional<long> expected_euler;
  /// Distance of a point to the input boundary; interface nodes farther than
  /// boundary_tolerance are reported. Unchecked when empty.
  std::function<double(const Point<Dim>&)> boundary_distance;
  double boundary_tolerance = 1e-6;
  /// A node closer than hanging_rel_tol * (edge or facet size) to the interior of an edge or
  /// facet of which it is not a vertex is a hanging node.
  double hanging_rel_tol = 1e-6;
  /// Two nodes closer than duplicate_rel_tol * (bounding-box diagonal) are duplicates.
  double duplicate_rel_tol = 1e-12;
  /// Whether the interface elements must be the boundary facets of the solid; false for a part
  /// of a mesh, whose cut facets have none.
  bool check_interface = true;
  /// How many human-readable problems to keep.
  int max_problems = 20;
  /// Threads for the per-element, per-node and per-edge checks (boundary_distance must then be
  /// safe to call concurrently); the report is the same for every count.
  int n_threads = 1;
  /// Tests only: false groups the facets of a solid of tetrahedra, or of triangles and quads,
  /// through facet_uses (24 bytes a use, one sort), takes the 2D edges from unique_edges and
  /// looks for nodes on the facets of tetrahedra one facet at a time, the way every other solid
  /// is checked: the slow twin of the bucketed grouping and the per-tetrahedron facet queries.
  /// The same report.
  bool bucketed_facets = true;
};

/// ValidationReport::ProblemSite::kind of an interface node farther from the boundary than
/// ValidateOptions::boundary_tolerance (a pipeline that refines around the other sites skips it).
inline constexpr char off_boundary_kind[] = "an interface node is off the boundary";

struct ValidationReport {
  bool valid = false;
  std::size_t n_points = 0, n_solid = 0, n_interface = 0;

  std::size_t bad_elements = 0;          ///< wrong dimension, wrong node count or node out of range
  std::size_t inverted = 0;              ///< a corner Jacobian (tri/tet: signed measure) <= 0
  std::size_t nonconforming_facets = 0;  ///< facets used 3+ times or twice in the same orientation
  std::size_t hanging_nodes = 0;         ///< distinct nodes on the interior of another element's edge/facet
  std::size_t interface_missing = 0;     ///< boundary facets of the solid with no interface element
  std::size_t interface_extra = 0;       ///< interface elements that are not a boundary facet (or repeat one)
  std::size_t interface_reversed = 0;    ///< interface elements oriented against the outward normal
  std::size_t interface_mismatch = 0;    ///< missing + extra + reversed
  std::size_t unused_nodes = 0;
  std::size_t duplicate_nodes = 0;       ///< nodes coinciding with an earlier node
  std::size_t off_boundary_nodes = 0;    ///< interface nodes farther than the tolerance (with a callback)
  std::size_t attribute_mismatch = 0;    ///< level / from_boundary_cell sized neither 0 nor n_solid
  double max_boundary_distance = 0.0;

  long euler = 0;  ///< of the solid elements
  std::optional<long> expected_euler;

  /// The first max_problems problems, with element ids and coordinates.
  std::vector<std::string> problems;
  /// Where problems[i] is: a short kind ("a node hangs on an edge or facet") and a node at the
  /// problem (an element's first node; -1 for the counts that have no place: bad elements,
  /// attribute arrays, the Euler characteristic). A pipeline refines around these.
  struct ProblemSite {
    const char* kind = "";
    std::int32_t node = -1;
  };
  std::vector<ProblemSite> sites;
  std::size_t n_problems = 0;  ///< all problems, including those not kept

  /// One line per nonzero count, then the problems.
  std::string summary() const;
  /// Valid but for the surface's checks (the interface nodes' distance, the Euler
  /// characteristic): what `valid` is without those options. A mesh without solid elements is
  /// not valid: it meshes nothing, and the other checks pass on it (its Euler characteristic 0
  /// is a torus's: a pipeline that lost a whole thin torus passed, session 43).
  bool conforms() const {
    return n_solid > 0 && bad_elements == 0 && inverted == 0 && nonconforming_facets == 0 && hanging_nodes == 0 &&
           interface_mismatch == 0 && unused_nodes == 0 && duplicate_nodes == 0 && attribute_mismatch == 0;
  }
};

template <int Dim> ValidationReport validate(const Mesh<Dim>& mesh, const ValidateOptions<Dim>& options = {});

/// A hash of everything validate reads of a mesh: the points' bits, the solid's and the
/// interface's elements, the attribute arrays. A report made for a mesh applies to a mesh with
/// the same hash (a caller that validated it already hands the report on with the hash).
template <int Dim> std::uint64_t content_hash(const Mesh<Dim>& mesh);
template <int Dim> bool is_valid(const Mesh<Dim>& mesh, const ValidateOptions<Dim>& options = {});

/// Euler characteristic of the solid elements alone: V - E + F (2D), V - E + F - C (3D),
/// V counting only the nodes the solid uses. Tetrahedra are counted on n_threads threads, node
/// by node, in runs of nodes whose tetrahedra are listed together: at most run_uses node uses a
/// run (0: a quarter of them, at least 2^20; a test sets it small).
template <int Dim> long euler_characteristic(const Mesh<Dim>& mesh, int n_threads = 1, std::size_t run_uses = 0);
/// The same count by sorting every edge and facet (any element types; the slow twin of the
/// tetrahedra-only count euler_characteristic uses when it can).
template <int Dim> long euler_characteristic_ref(const Mesh<Dim>& mesh);

}  // namespace febemesh
