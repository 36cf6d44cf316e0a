// The OpenMesh adapter (STYLE.md §9): STL (ASCII and binary) is parsed by OpenMesh's reader
// into a plain TriangleSoup through an importer of our own (SoupImporter), not into an OpenMesh
// mesh: its halfedge kernel refuses a face whose winding runs an edge the way a neighbour
// already runs it ("complex edge") and splits vertices to stay manifold, so a closed surface
// whose triangles are not consistently wound (Gmsh's STL export of OpenCASCADE solids winds
// each face by its own parametrisation) came out with boundary edges and was refused as "not
// closed". The soup keeps every face as the file gives it; validate_surface names what is
// wrong and orients what is only wound inconsistently. The face count is still compared with
// what the file declares (facets the reader itself skips). OBJ and PLY are parsed in
// read_obj.cpp and read_ply.cpp (OpenMesh 9.0's readers abort or loop on bad input).
#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
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

namespace om = OpenMesh;

/// Records the vertices and faces a reader hands over, as they come (no halfedges, so nothing
/// refused or split); everything else a reader may set (normals, colours, texture
/// coordinates, status) is dropped. A face with fewer than three corners or a corner twice
/// is kept aside as the first bad face, for the caller's message.
class SoupImporter final : public om::IO::BaseImporter {
 public:
  std::vector<P3> points;
  std::vector<std::vector<std::int32_t>> faces;
  long long first_bad_face = -1;  ///< index among the faces handed over, -1: none
  std::vector<std::int32_t> bad_corners;

  om::VertexHandle add_vertex(const om::Vec3f& p) override { return add_vertex(om::Vec3d(p[0], p[1], p[2])); }
  om::VertexHandle add_vertex(const om::Vec3d& p) override {
    points.emplace_back(p[0], p[1], p[2]);
    return om::VertexHandle(static_cast<int>(points.size()) - 1);
  }
  om::VertexHandle add_vertex() override { return add_vertex(om::Vec3d(0, 0, 0)); }
  om::FaceHandle add_face(const VHandles& corners) override {
    std::vector<std::int32_t> f;
    f.reserve(corners.size());
    for (const om::VertexHandle& v : corners) f.push_back(v.idx());
    std::vector<std::int32_t> sorted = f;
    std::sort(sorted.begin(), sorted.end());
    const bool bad = f.size() < 3 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end() ||
                     sorted.front() < 0 || sorted.back() >= static_cast<std::int32_t>(points.size());
    const long long index = n_handed_++;
    if (bad) {
      if (first_bad_face < 0) first_bad_face = index, bad_corners = f;
      return om::FaceHandle();
    }
    faces.push_back(std::move(f));
    return om::FaceHandle(static_cast<int>(faces.size()) - 1);
  }
  long long n_handed() const { return n_handed_; }

  om::HalfedgeHandle add_edge(om::VertexHandle, om::VertexHandle) override { return om::HalfedgeHandle(); }
  om::FaceHandle add_face(om::HalfedgeHandle) override { return om::FaceHandle(); }
  void add_face_texcoords(om::FaceHandle, om::VertexHandle, const std::vector<om::Vec2f>&) override {}
  void add_face_texcoords(om::FaceHandle, om::VertexHandle, const std::vector<om::Vec3f>&) override {}
  void set_face_texindex(om::FaceHandle, int) override {}
  void set_point(om::VertexHandle v, const om::Vec3f& p) override {
    if (v.idx() >= 0 && static_cast<std::size_t>(v.idx()) < points.size()) points[static_cast<std::size_t>(v.idx())] = P3(p[0], p[1], p[2]);
  }
  void set_halfedge(om::VertexHandle, om::HalfedgeHandle) override {}
  void set_normal(om::VertexHandle, const om::Vec3f&) override {}
  void set_normal(om::VertexHandle, const om::Vec3d&) override {}
  void set_color(om::VertexHandle, const om::Vec3uc&) override {}
  void set_color(om::VertexHandle, const om::Vec4uc&) override {}
  void set_color(om::VertexHandle, const om::Vec3f&) override {}
  void set_color(om::VertexHandle, const om::Vec4f&) override {}
  void set_texcoord(om::VertexHandle, const om::Vec2f&) override {}
  void set_status(om::VertexHandle, const om::Attributes::StatusInfo&) override {}
  void set_next(om::HalfedgeHandle, om::HalfedgeHandle) override {}
  void set_face(om::HalfedgeHandle, om::FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(om::HalfedgeHandle, const om::Vec2f&) override {}
  void set_texcoord(om::VertexHandle, const om::Vec3f&) override {}
  void set_texcoord(om::HalfedgeHandle, const om::Vec3f&) override {}
  void set_status(om::HalfedgeHandle, const om::Attributes::StatusInfo&) override {}
  void set_color(om::EdgeHandle, const om::Vec3uc&) override {}
  void set_color(om::EdgeHandle, const om::Vec4uc&) override {}
  void set_color(om::EdgeHandle, const om::Vec3f&) override {}
  void set_color(om::EdgeHandle, const om::Vec4f&) override {}
  void set_status(om::EdgeHandle, const om::Attributes::StatusInfo&) override {}
  void set_normal(om::FaceHandle, const om::Vec3f&) override {}
  void set_normal(om::FaceHandle, const om::Vec3d&) override {}
  void set_color(om::FaceHandle, const om::Vec3uc&) override {}
  void set_color(om::FaceHandle, const om::Vec4uc&) override {}
  void set_color(om::FaceHandle, const om::Vec3f&) override {}
  void set_color(om::FaceHandle, const om::Vec4f&) override {}
  void set_status(om::FaceHandle, const om::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
  std::size_t n_vertices() const override { return points.size(); }
  std::size_t n_faces() const override { return faces.size(); }
  std::size_t n_edges() const override { return 0; }

 private:
  long long n_handed_ = 0;
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/// How many facets an STL declares (binary: its header; ASCII: its "endfacet"s), counted
/// independently of OpenMesh.
long long declared_facets(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
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
  if (ext != "stl") throw InputError(path + ": not an .stl file (OBJ, PLY and OFF have readers of their own)");
  SoupImporter soup_in;
  om::IO::Options options;
  // OpenMesh reports what it skips on omerr; the checks below turn that into an error.
  const bool err_was_enabled = omerr().is_enabled();
  omerr().disable();
  const bool ok = om::IO::IOManager().read(path, soup_in, options);
  if (err_was_enabled) omerr().enable();
  if (!ok || soup_in.faces.empty()) check_binary_stl_size(path);
  if (!ok) throw InputError(path + ": OpenMesh cannot read the file (unreadable or malformed STL)");
  if (soup_in.first_bad_face >= 0) {
    std::ostringstream corners;
    for (std::size_t k = 0; k < soup_in.bad_corners.size(); ++k) corners << (k ? " " : "") << soup_in.bad_corners[k];
    throw InputError(path + ": degenerate face " + std::to_string(soup_in.first_bad_face) + " (vertices " + corners.str() +
                     "): fewer than three corners, a corner twice or an index out of range");
  }
  if (soup_in.faces.empty()) throw InputError(path + ": empty surface (no faces)");

  TriangleSoup soup;
  soup.vertices.reserve(soup_in.points.size());
  for (std::size_t i = 0; i < soup_in.points.size(); ++i) {
    const P3& p = soup_in.points[i];
    if (!p.allFinite())
      throw InputError(path + ": non-finite coordinate in vertex " + std::to_string(i) + " (" + std::to_string(p.x()) +
                       ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) + ")");
    soup.vertices.push_back(p);
  }
  // The reader may skip a facet itself: then the counts no longer match the file.
  const long long declared = declared_facets(path);
  if (declared != soup_in.n_handed())
    throw InputError(path + ": the file declares " + std::to_string(declared) + " facets but OpenMesh read " +
                     std::to_string(soup_in.n_handed()));

  for (const std::vector<std::int32_t>& f : soup_in.faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k) soup.triangles.push_back({f[0], f[k], f[k + 1]});
  return soup;
}

}  // namespace febemesh::dim3
