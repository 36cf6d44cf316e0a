#pragma once
// Gmsh MSH 4.1 reader (ASCII or binary) into Mesh<Dim>: what write_msh writes, and reasonable files from
// Gmsh. Elements of the physical group "solid" go to mesh.solid, of "interface" to
// mesh.interface; a file without groups of those names is split by dimension (Dim -> solid,
// Dim-1 -> interface; points and other dimensions ignored). Nodes are ordered by tag, elements
// by tag within each group. level / from_boundary_cell are left empty (MSH does not carry them).

#include <filesystem>
#include <string_view>

#include "core/mesh.hpp"

namespace febemesh {

/// Throws InputError naming `source` and the line on malformed or unsupported input.
template <int Dim> Mesh<Dim> parse_msh(std::string_view text, std::string_view source = "<msh>");
template <int Dim> Mesh<Dim> read_msh(const std::filesystem::path& path);

}  // namespace febemesh
