#pragma once
// The paper's general algorithm (steps 1-7) in 2D: quadrant generation (subdivision by the
// mesh control parameters, 2:1 balance, interior quadrants), boundary quadrants by
// projection, corner pulling, smoothing, the BE mesh and the FE mesh from templates.
// Where the construction finds the tree too coarse (a feature thinner than the quadrants, a
// projection with no admissible segment, an inverted element), the quadrants around the place
// are refined and the construction is redone, up to the maximum level.

#include <functional>
#include <string>
#include <vector>

#include "core/orthtree.hpp"
#include "core/stage_timer.hpp"
#include "dim2/boundary_quadrants.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/templates2d.hpp"

namespace febemesh::dim2 {

struct Options2d {
  double level = no_level;           ///< global level at the curve; no_level = the file's or automatic
  ElementKind elements = ElementKind::Tri;
  int smoothing_iterations = 4;      ///< the paper recommends about four
  bool slide_boundary = false;       ///< let boundary nodes slide along the curve while smoothing
  int improve_rounds = 4;            ///< rounds of edge flips + angle-guarded smoothing (0 = paper only)
  bool slide_in_quality_pass = true; ///< the quality pass may slide interface nodes along the curve
  double buffer = 0.35;              ///< drop interior quadrants nearer the curve than this x size
  int max_level = 16;                ///< no quadrant finer than this (repairs included)
  int max_repairs = 12;              ///< local refinements when the construction needs them
  std::size_t max_cells = 20000000;  ///< refuse larger trees (LimitError) instead of exhausting memory
  /// With given levels the thickness and curvature floors go at most
  /// CurveBoundary::floor_boost_default levels beyond them; when the run is refused with chains
  /// projecting onto two loops (parts thinner than the quadrants), it is made once more with the
  /// floors up to this many levels beyond (Result2d::thin_parts_refined). <= 4: never.
  double thin_retry_boost = 8.0;
  /// Split boxes outside the solid to the level field too (they hold no element; off: they stay
  /// whole and the balance grades them, the same mesh from a smaller tree). For tests.
  bool split_outside = false;
  int n_threads = 1;                 ///< threads for refinement, classification and smoothing; results do not depend on it
  bool keep_stages = true;           ///< keep the intermediate trees and complexes for figures
  /// Stages are dropped (and the unpulled complex is not rebuilt) when the mesh has more FE
  /// elements than this: figures of 10^5 quadrants are unreadable and cost more than meshing.
  std::size_t keep_stages_max_elements = static_cast<std::size_t>(-1);
};

struct Result2d {
  // Stages, kept when Options2d::keep_stages and the mesh is small enough (stages_kept).
  bool stages_kept = false;
  Orthtree<2> subdivided;           ///< after check_and_subdivide_quadrant
  Orthtree<2> balanced;             ///< after the one-level-difference rule
  Orthtree<2> tree;                 ///< final tree (after repairs)
  Flags interior;                   ///< interior quadrants of `tree` after buffer and pinch rules
  QuadrantComplex before_pulling;   ///< boundary quadrants before corner pulling
  QuadrantComplex complex;          ///< after corner pulling
  // Result.
  FeBeMesh fe;                      ///< smoothed FE mesh + BE mesh
  BoundaryQuadrantStats stats;
  // Counts of the stages, kept or not (report.json).
  std::size_t n_subdivided = 0;          ///< leaves after the subdivision
  std::size_t n_balanced = 0;            ///< leaves after the first 2:1 balance
  std::size_t n_boundary_quadrants = 0;  ///< of the complex the mesh was made from
  std::size_t n_buffer_dropped = 0;
  std::size_t n_pinches_dropped = 0;
  int n_repairs = 0;
  bool thin_parts_refined = false;  ///< made by Options2d::thin_retry_boost's retry
  std::vector<Problem> repaired;    ///< what the repairs were for
  std::size_t n_smoothing_rejected = 0;
  std::size_t n_flips = 0;          ///< edge flips of the quality pass
  std::size_t n_angle_moves = 0;    ///< node moves of the corner-angle optimisation
  std::vector<StageTime> times;
};

using Progress = std::function<void(const std::string&)>;

/// Runs the whole pipeline; throws GeometryError when a repair would exceed max_level (after the
/// thin-parts retry, Options2d::thin_retry_boost) and LimitError when the tree would exceed
/// max_cells.
Result2d mesh2d(const CurveBoundary& curve, const Options2d& opt, const Progress& progress = {});

}  // namespace febemesh::dim2
