#pragma once
// The paper's Figures 1-12 for a run of the 2D pipeline: one legible, colour-coded SVG per
// stage (control points and curve, quadrants after subdivision, after the one-level-difference
// rule, interior quadrants, boundary quadrants, after corner pulling, after smoothing, boundary
// elements, the final mesh), and the final mesh coloured by its elements' smallest angles.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "dim2/curve_boundary.hpp"
#include "dim2/pipeline2d.hpp"

namespace febemesh::dim2 {

/// Writes the stage figures into `dir` (created); returns the file names written.
std::vector<std::filesystem::path> write_stage_figures(const Result2d& r, const CurveBoundary& curve,
                                                       const std::filesystem::path& dir);

/// figures/README.txt in `dir` (created) saying why the stage figures were not drawn.
void write_figures_skipped_note(const std::filesystem::path& dir, std::size_t n_elements, std::size_t limit);

/// The curve with its control polygon and corners (the paper's Figures 1-2).
void draw_geometry_figure(const CurveBoundary& curve, const std::filesystem::path& file);

/// The mesh with each element filled by the bin of its smallest corner angle (five bins up to
/// the best shape's: 20/30/40/50 deg for a triangle, 30/45/60/75 for a quad; a legend with the
/// counts under it, both ranges where the mesh has both kinds), element outlines up to 20,000
/// elements, the curve over it; `who` (e.g. "Gmsh") opens the title. In the curve's root box,
/// so two meshes of one curve line up.
void draw_angle_figure(const Mesh<2>& m, const CurveBoundary& curve, const std::filesystem::path& file,
                       const std::string& who);

}  // namespace febemesh::dim2
