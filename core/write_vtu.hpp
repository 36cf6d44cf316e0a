#pragma once
// VTK XML UnstructuredGrid (ASCII, or raw appended binary) for ParaView: the solid and interface elements as cells
// (solid first), cell data "quality" (Verdict scaled Jacobian), "level" and "from_boundary_cell"
// (an interface cell takes those of the solid element it bounds), "group" (1 solid, 2 interface).

#include <filesystem>
#include <string>

#include "core/mesh.hpp"

namespace febemesh {

/// Ascii: every array as text (Float32 quality to six decimals). Binary: VTK's raw appended
/// data (header_type UInt64, little-endian): the same arrays, the quality as a float; about half
/// the bytes, and ParaView reads it as it reads the text.
enum class VtuEncoding { Ascii, Binary };

template <int Dim> std::string vtu_string(const Mesh<Dim>& mesh, VtuEncoding encoding = VtuEncoding::Ascii);
/// Throws InputError when the file cannot be written.
template <int Dim>
void write_vtu(const Mesh<Dim>& mesh, const std::filesystem::path& path, VtuEncoding encoding = VtuEncoding::Ascii);

}  // namespace febemesh
