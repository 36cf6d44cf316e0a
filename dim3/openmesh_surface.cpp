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
#include <vector>

#include "core/error.hpp"
#include "dim3/read_surface.hpp"

namespace febemesh::dim3 {

namespace {

using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

struct Declared {
  long long faces = -1;     ///< -1: the file does not say
  long long vertices = -1;
};

/// What the file declares, counted independently of OpenMesh.
Declared declared_counts(const std::string& path, const std::string& ext) {
  Declared out;
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
      if (size == 84 + 50LL * n) {
        out.faces = n;
        return out;
      }
    }
    in.clear();
    in.seekg(0);
    long long count = 0;
    for (std::string tok; in >> tok;)
      if (lower(tok) == "endfacet") ++count;
    out.faces = count;
    return out;
  }
  if (ext == "obj") {
    out.faces = out.vertices = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.size() < 2 || !std::isspace(static_cast<unsigned char>(line[1]))) continue;
      if (line[0] == 'f') ++out.faces;
      if (line[0] == 'v') ++out.vertices;
    }
    return out;
  }
  if (ext == "ply") {
    for (std::string line; std::getline(in, line);) {
      std::istringstream ss(line);
      std::string a, b;
      long long n = -1;
      ss >> a >> b >> n;
      if (a == "element" && b == "face") out.faces = n;
      if (a == "element" && b == "vertex") out.vertices = n;
      if (a == "end_header") break;
    }
  }
  return out;
}

/// Why OpenMesh made nothing of an STL, when it is a binary STL whose size is not what its
/// triangle count says (84 + 50 n bytes): truncated or not an STL. OpenMesh reads every such file
/// as empty (a cube's 12 triangles cut after 5, 11 or 11 and a half, or with 2 bytes more), and
/// the message was "empty surface (no faces)". A file that is text (ASCII STL) is left alone.
/// Called only once OpenMesh has failed, so a good file is not read twice.
void check_binary_stl_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const auto is_text = [](unsigned char c) {
    return c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' || (c >= 32 && c < 127);
  };
  // Text up to the end (an ASCII STL), or binary from its first other byte (a binary STL's
  // floats have some within the first triangles; its header may read "solid ...").
  char header[84] = {};
  long long size = 0;
  bool text = true;
  std::vector<char> chunk(1 << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (size < 84) std::memcpy(header + size, chunk.data(), std::min<std::size_t>(got, static_cast<std::size_t>(84 - size)));
    size += static_cast<long long>(got);
    if (std::any_of(chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(got), [&](char c) { return !is_text(static_cast<unsigned char>(c)); })) {
      text = false;
      break;
    }
  }
  if (text) return;
  in.clear();
  in.seekg(0, std::ios::end);
  size = static_cast<long long>(in.tellg());
  if (size < 84)
    throw InputError(path + ": not an STL: " + std::to_string(size) +
                     " bytes of binary data, shorter than a binary STL's 84-byte header");
  std::uint32_t n = 0;
  std::memcpy(&n, header + 80, 4);  // little-endian on every platform we build for
  const long long expected = 84 + 50LL * n;
  if (expected != size)
    throw InputError(path + ": truncated or malformed binary STL: its header declares " + std::to_string(n) +
                     " triangles (" + std::to_string(expected) + " bytes), the file has " + std::to_string(size) + " bytes");
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
  if (ext == "stl" && (!ok || mesh.n_faces() == 0)) check_binary_stl_size(path);
  if (!ok) throw InputError(path + ": OpenMesh cannot read the file (unreadable or malformed " + ext + ")");
  if (mesh.n_faces() == 0) throw InputError(path + ": empty surface (no faces)");

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
  // OpenMesh either drops a face that would make an edge non-manifold, or duplicates its
  // vertices to keep the mesh manifold: either way the counts no longer match the file.
  const Declared declared = declared_counts(path, ext);
  if (declared.faces >= 0 && declared.faces != static_cast<long long>(mesh.n_faces()))
    throw InputError(path + ": non-manifold or degenerate faces: the file declares " +
                     std::to_string(declared.faces) + " faces but only " + std::to_string(mesh.n_faces()) +
                     " could be added (the others would put more than two faces on an edge, or repeat a vertex)");
  if (declared.vertices >= 0 && declared.vertices != static_cast<long long>(mesh.n_vertices()))
    throw InputError(path + ": non-manifold: the file declares " + std::to_string(declared.vertices) +
                     " vertices but OpenMesh needed " + std::to_string(mesh.n_vertices()) +
                     " (it duplicates vertices where more than two faces meet at an edge or sheets touch)");

  for (const auto fh : mesh.faces()) {
    std::vector<std::int32_t> idx;
    for (const auto vh : mesh.fv_range(fh)) idx.push_back(vh.idx());
    for (std::size_t k = 1; k + 1 < idx.size(); ++k) soup.triangles.push_back({idx[0], idx[k], idx[k + 1]});
  }
  return soup;
}

}  // namespace febemesh::dim3
