#pragma once
// The paper's Figures 1-12 for a run of the 2D pipeline: one legible, colour-coded SVG per
// stage (control points and curve, quadrants after subdivision, after the one-level-difference
// rule, interior quadrants, boundary quadrants, after corner pulling, after smoothing, boundary
// elements, the final mesh).

#include <cstddef>
#include <filesystem>
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

}  // namespace febemesh::dim2
