// The OpenMesh adapter (STYLE.md §9): STL, OBJ and PLY are read with OpenMesh and handed on as a
// plain TriangleSoup. OpenMesh refuses faces that would make an edge non-manifold and drops
// them with a warning, so the face count is compared with what the file declares.

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "dim3/read_surface.hpp"

namespace febemesh::dim3 {

namespace {

using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/// Number of faces the file declares (-1 if it cannot tell).
long long declared_faces(const std::string& path, const std::string& ext) {
  std::ifstream in(path, std::ios::binary);
  if (ext == "stl") {
    in.seekg(0, std::ios::end);
    const auto size = static_cast<long long>(in.tellg());
    in.seekg(0);
    if (size >= 84) {
      char header[84];
      in.read(header, 84);
      std::uint32_t n = 0;
      std::memcpy(&n, header + 80, 4);  // little-endian on every platform we build for
      if (size == 84 + 50LL * n) return n;
    }
    in.clear();
    in.seekg(0);
    long long count = 0;
    for (std::string tok; in >> tok;)
      if (lower(tok) == "endfacet") ++count;
    return count;
  }
  if (ext == "obj") {
    long long count = 0;
    for (std::string line; std::getline(in, line);)
      if (line.size() > 1 && line[0] == 'f' && std::isspace(static_cast<unsigned char>(line[1]))) ++count;
    return count;
  }
  if (ext == "ply") {
    for (std::string line; std::getline(in, line);) {
      std::istringstream ss(line);
      std::string a, b;
      long long n = -1;
      ss >> a >> b >> n;
      if (a == "element" && b == "face") return n;
      if (a == "end_header") break;
    }
  }
  return -1;
}

}  // namespace

TriangleSoup read_with_openmesh(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : lower(path.substr(dot + 1));
  OmMesh mesh;
  OpenMesh::IO::Options options;
  // OpenMesh reports refused faces on omerr; the count check below turns them into an error.
  const bool err_was_enabled = omerr().is_enabled();
  omerr().disable();
  const bool ok = OpenMesh::IO::read_mesh(mesh, path, options);
  if (err_was_enabled) omerr().enable();
  if (!ok) throw InputError(path + ": OpenMesh cannot read the file (unreadable or malformed " + ext + ")");
  if (mesh.n_faces() == 0) throw InputError(path + ": empty surface (no faces)");

  const long long declared = declared_faces(path, ext);
  if (declared >= 0 && declared != static_cast<long long>(mesh.n_faces()))
    throw InputError(path + ": the file declares " + std::to_string(declared) + " faces but only " +
                     std::to_string(mesh.n_faces()) +
                     " could be added: the others are non-manifold (an edge with more than two faces) "
                     "or degenerate (repeated vertices)");

  TriangleSoup soup;
  soup.vertices.reserve(mesh.n_vertices());
  for (const auto vh : mesh.vertices()) {
    const auto& q = mesh.point(vh);
    const P3 p(q[0], q[1], q[2]);
    if (!p.allFinite())
      throw InputError(path + ": non-finite coordinate in vertex " + std::to_string(vh.idx()) + " (" +
                       std::to_string(q[0]) + ", " + std::to_string(q[1]) + ", " + std::to_string(q[2]) + ")");
    soup.vertices.push_back(p);
  }
  for (const auto fh : mesh.faces()) {
    std::vector<std::int32_t> idx;
    for (const auto vh : mesh.fv_range(fh)) idx.push_back(vh.idx());
    for (std::size_t k = 1; k + 1 < idx.size(); ++k) soup.triangles.push_back({idx[0], idx[k], idx[k + 1]});
  }
  return soup;
}

}  // namespace febemesh::dim3
