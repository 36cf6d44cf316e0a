#pragma once
// Reading closed triangle surfaces: OFF, OBJ and PLY (ASCII and binary) are parsed here, in
// double precision, so that every problem is seen and named with its line (OpenMesh 9.0's OBJ
// reader aborts on a bad face and its PLY reader loops on a garbled header; both read floats);
// STL (ASCII and binary) by OpenMesh's reader into a soup of our own (openmesh_surface.cpp:
// every face as the file gives it, none dropped or split), whose face count is checked against
// what the file declares. Polygons are split into triangle fans. Bad input throws InputError
// "<path>[:<line>]: <reason>". Topology and geometry checks come after (surface_checks.hpp).

#include <istream>
#include <string>

#include "dim3/surface.hpp"

namespace febemesh::dim3 {

/// Reads `path` by extension (.off, .stl, .obj, .ply; case-insensitive).
TriangleSoup read_surface(const std::string& path);

/// Parses OFF text; `name` prefixes the error messages.
TriangleSoup read_off(std::istream& in, const std::string& name);

/// Parses Wavefront OBJ text (read_obj.cpp); `name` prefixes the error messages.
TriangleSoup read_obj(std::istream& in, const std::string& name);

/// Parses PLY, ASCII or binary (read_ply.cpp); `in` opened in binary mode.
TriangleSoup read_ply(std::istream& in, const std::string& name);

/// STL through OpenMesh (the adapter; OpenMesh types stay in its .cpp).
TriangleSoup read_with_openmesh(const std::string& path);

}  // namespace febemesh::dim3
