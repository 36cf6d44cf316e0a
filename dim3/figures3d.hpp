#pragma once
// Pictures of a 3D mesh for a reader without ParaView at hand: the solid cut by three planes
// through the middle of the surface (each cut element a polygon coloured by its smallest
// dihedral angle, the surface's own cut drawn over them, so that slivers and lost volume show at
// a glance), and the BE mesh seen from a corner of its box (flat shaded, hidden faces left out).

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "dim3/surface.hpp"

namespace febemesh::dim3 {

/// A solid element cut by a plane: the polygon where they meet, counter-clockwise in the plane's
/// coordinates (section_coordinates), and the element.
struct SectionPolygon {
  std::vector<Point<2>> pts;
  std::int32_t element = -1;
};

/// The plane x[axis] = at seen from the positive side of its normal: (u, v) are the next two
/// axes in cyclic order (x: (y, z), y: (z, x), z: (x, y)).
Point<2> section_coordinates(const P3& p, int axis);

/// The solid elements of m that the plane x[axis] = at cuts through: for each, the polygon whose
/// corners are where its edges cross the plane, in the order its faces join them (a face shared
/// by two elements gives both the same side, so the polygons tile the mesh's section, hexahedra
/// with faces that are not flat too; a quad face whose corners alternate sides is cut as its
/// bilinear surface is, which can split a hexahedron's cut in two polygons); where a node lies
/// on the plane, the convex hull of the crossings and such nodes. An element the plane only touches (at a node, an edge or a face,
/// its other nodes on one side) has no polygon: on a plane of element faces the section is
/// empty, so write_mesh_figures keeps its planes off the lattice's.
std::vector<SectionPolygon> section_polygons(const Mesh<3>& m, int axis, double at);

/// The surface's triangles cut by the same plane: one segment (u, v) for each triangle with
/// nodes on both sides of it.
std::vector<std::array<Point<2>, 2>> section_segments(const Surface& s, int axis, double at);

/// The plane the figures cut along `axis` at: the middle of the surface's box, moved off it by
/// 1.23% of the box so that it crosses the octants instead of running along their faces.
double section_plane(const Surface& s, int axis);

/// The solid cut by the plane x[axis] = section_plane(s, axis), drawn into `file`: each cut
/// element a polygon coloured by its smallest dihedral angle (with a legend of the counts), the
/// surface's cut over them in black; `who` (e.g. "TetGen") opens the title. Returns the number
/// of polygons; the figure is drawn only when that is at most `max_shapes` (0: no limit).
std::size_t write_section_figure(const Mesh<3>& m, const Surface& s, int axis, const std::filesystem::path& file,
                                 std::size_t max_shapes, const std::string& who = "");

/// What write_mesh_figures drew and what it left out (and why).
struct MeshFigures {
  std::vector<std::filesystem::path> written;  ///< file names in the folder
  std::vector<std::string> skipped;            ///< "section-x.svg: 81234 polygons, over the limit of 60000"
};

/// Writes section-x.svg, section-y.svg, section-z.svg (write_section_figure) and interface.svg (the BE mesh from the corner (+x, -y, +z)
/// of the box, hidden faces left out) into `dir` (created). A figure of more than `max_shapes`
/// polygons is not drawn (0: no limit); README.txt in `dir` then says which and why.
MeshFigures write_mesh_figures(const Mesh<3>& m, const Surface& s, const std::filesystem::path& dir,
                               std::size_t max_shapes);

}  // namespace febemesh::dim3
