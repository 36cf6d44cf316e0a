#pragma once
// VTK XML UnstructuredGrid (ASCII) for ParaView: the solid and interface elements as cells
// (solid first), cell data "quality" (Verdict scaled Jacobian), "level" and "from_boundary_cell"
// (an interface cell takes those of the solid element it bounds), "group" (1 solid, 2 interface).

#include <filesystem>
#include <string>

#include "core/mesh.hpp"

namespace febemesh {

template <int Dim> std::string vtu_string(const Mesh<Dim>& mesh);
/// Throws InputError when the file cannot be written.
template <int Dim> void write_vtu(const Mesh<Dim>& mesh, const std::filesystem::path& path);

}  // namespace febemesh
