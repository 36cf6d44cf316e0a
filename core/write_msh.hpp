#pragma once
// Gmsh MSH 4.1 ASCII writer (DESIGN.md "Contracts"): physical group "solid" (dimension Dim,
// tag 1) and "interface" (dimension Dim-1, tag 2), one entity per group carrying its physical
// tag, all nodes on the solid entity. Node tag = index + 1; solid element e has tag e + 1,
// interface element e tag n_solid + e + 1; one element block per (group, type). Doubles use the
// shortest representation that round-trips, so the bytes are deterministic and reading back
// gives the same points bit for bit.

#include <filesystem>
#include <string>

#include "core/mesh.hpp"

namespace febemesh {

template <int Dim> std::string msh_string(const Mesh<Dim>& mesh);
/// Throws InputError when the file cannot be written.
template <int Dim> void write_msh(const Mesh<Dim>& mesh, const std::filesystem::path& path);

}  // namespace febemesh
