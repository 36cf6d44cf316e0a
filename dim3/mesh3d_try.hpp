#pragma once
// One try of the 3D pipeline at fixed options (internal to dim3: pipeline3d.cpp's tries call it):
// the first tree, then the repair loop, which classifies the octants, builds the boundary
// octants and the tetrahedra, untangles them and runs the quality stage, and where that leaves
// problems drops or refines octants around them and builds again.

#include <cstddef>
#include <string>

#include "dim3/pipeline3d.hpp"
#include "dim3/surface_boundary.hpp"

namespace febemesh::dim3 {

/// The work of one run in octants built on, and its bound (Options3d::effort): 0 until the
/// first tree is known.
struct Effort {
  std::size_t used = 0;
  std::size_t limit = 0;
  /// Where a limit given from outside comes from, for the message past it (empty: the run's
  /// own, Options3d::effort x its first tree).
  std::string limit_origin;
  bool first_tree_built = false;  ///< the run's first tree (Options3d::thickness_probe looks at it only)
  /// Why the probe did not stand, when it ran (Options3d::thickness_probe): the thickness try
  /// after a refusal would begin with the probe's tree again. Empty: no probe, or it stood.
  std::string thickness_probe_refused;
  /// Why the thin parts' try at a first tree without an interior octant did not stand, when it
  /// ran (Options3d::thickness_probe): the thin retry after the run's mesh would be that try
  /// again. Empty: not run, or it stood.
  std::string thin_early_refused;
  /// The run's tries at its level were refused (GeometryError) after building on fewer than
  /// Options3d::min_effort_octants octants: where a level raise (Options3d::raise_levels)
  /// applies, whether or not the run made it.
  bool refused_cheaply = false;
  /// The tries with the curvature and feature levels were refused and the run went on with the
  /// surface at the one level (Options3d::uniform_after_refusal): its lattice draws start there.
  bool uniform_tried = false;
  /// Why that try was refused, when it ran early (Options3d::uniform_early_faceted) and was
  /// refused: it is not run again after the others, whose refusal then gives this reason too.
  std::string uniform_refused;
};

/// One try of the pipeline with `opt` (no fallback): `s` gets the options' levels, `effort`
/// counts the octants built on (and gets its limit from the first tree when it has none). Throws
/// GeometryError when the repairs cannot make the mesh valid (unless a valid coarser mesh of
/// the try stands) and LimitError past the work bound or max_cells.
Result3d mesh3d_once(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress);

}  // namespace febemesh::dim3
