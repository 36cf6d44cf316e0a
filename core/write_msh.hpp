#pragma once
// Gmsh MSH 4.1 ASCII writer (DESIGN.md "Contracts"): physical group "solid" (dimension Dim,
// tag 1) and "interface" (dimension Dim-1, tag 2), one entity per group carrying its physical
// tag, all nodes on the solid entity. Node tag = index + 1; solid element e has tag e + 1,
// interface element e tag n_solid + e + 1; one element block per (group, type). Doubles use the
// shortest representation that round-trips, so the bytes are deterministic and reading back
// gives the same points bit for bit.
// MshEncoding::Binary writes the same sections as MSH 4.1 binary (file type 1, data size 8,
// native little-endian): integers as int32, counts and tags as 64-bit size_t, coordinates as
// doubles; $PhysicalNames stays text, as in Gmsh's own binary files.

#include <filesystem>
#include <string>

#include "core/mesh.hpp"

namespace febemesh {

enum class MshEncoding { Ascii, Binary };

template <int Dim> std::string msh_string(const Mesh<Dim>& mesh, MshEncoding encoding = MshEncoding::Ascii);
/// Throws InputError when the file cannot be written. The text's node and element lines are
/// formatted on n_threads threads, in blocks written in order (the same bytes for every count).
template <int Dim>
void write_msh(const Mesh<Dim>& mesh, const std::filesystem::path& path, MshEncoding encoding = MshEncoding::Ascii,
               int n_threads = 1);

}  // namespace febemesh
