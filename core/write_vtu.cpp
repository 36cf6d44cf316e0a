// VTU text built with std::to_chars in one buffer.

#include "core/write_vtu.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>

#include "core/error.hpp"
#include "core/mesh_topology.hpp"
#include "core/quality.hpp"

namespace febemesh {

namespace {

class Text {
 public:
  Text& operator<<(std::string_view s) {
    buf_.append(s);
    return *this;
  }
  template <class Num> Text& num(Num v) {
    char tmp[32];
    const auto res = std::to_chars(tmp, tmp + sizeof tmp, v);
    buf_.append(tmp, static_cast<std::size_t>(res.ptr - tmp));
    buf_.push_back(' ');
    return *this;
  }
  std::string take() { return std::move(buf_); }

 private:
  std::string buf_;
};

/// VTK's node order from Gmsh's: only the wedge differs (VTK's first triangle faces away from
/// the second, Gmsh's faces towards it).
int vtk_local(ElemType t, int i) {
  constexpr int prism[6] = {0, 2, 1, 3, 5, 4};
  return t == ElemType::Prism6 ? prism[i] : i;
}

template <class Num> void array(Text& out, const char* type, const char* name, int components, const std::vector<Num>& values) {
  out << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\"";
  if (components > 1) out << " NumberOfComponents=\"" << std::to_string(components) << "\"";
  out << " format=\"ascii\">\n";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out.num(values[i]);
    if ((i + 1) % 12 == 0 || i + 1 == values.size()) out << "\n";
  }
  out << "        </DataArray>\n";
}

/// The element whose facet interface element e is, for every e: the one solid element that uses
/// that facet, or -1 when none or several do (then it is not a boundary facet).
template <int Dim> std::vector<std::int32_t> interface_owners(const Mesh<Dim>& mesh) {
  const Elements &solid = mesh.solid, &inter = mesh.interface;
  std::vector<std::int32_t> out(inter.size(), -1);
  const bool polygons = Dim == 2 && std::all_of(solid.type.begin(), solid.type.end(), [](ElemType t) {
    return t == ElemType::Tri3 || t == ElemType::Quad4;
  }) && std::all_of(inter.type.begin(), inter.type.end(), [](ElemType t) { return t == ElemType::Line2; });
  if (!polygons) {
    std::vector<std::pair<FacetKey, ElemId>> owner;
    for (const BoundaryFacet& b : boundary_facets(solid)) owner.emplace_back(key_of(b.facet), b.elem);
    std::sort(owner.begin(), owner.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t e = 0; e < inter.size(); ++e) {
      const FacetKey k = key_of(as_facet(inter, ElemId{static_cast<std::int32_t>(e)}));
      const auto it = std::lower_bound(owner.begin(), owner.end(), k, [](const auto& o, const FacetKey& key) { return o.first < key; });
      if (it != owner.end() && it->first == k) out[e] = it->second.v;
    }
    return out;
  }
  // Polygons: the facets are the edges (k, k+1), so the users of edge {a, b} are among the
  // elements at its smaller node; those of the interface's smaller nodes are listed (CSR).
  std::vector<std::int32_t> slot(mesh.points.size(), -1), start, elem;
  std::int32_t n_slots = 0;
  for (std::size_t e = 0; e < inter.size(); ++e) {
    const VertexId* v = inter.nodes(ElemId{static_cast<std::int32_t>(e)});
    std::int32_t& s = slot[std::min(v[0].v, v[1].v)];
    if (s < 0) s = n_slots++;
  }
  start.assign(static_cast<std::size_t>(n_slots) + 1, 0);
  for (std::size_t e = 0; e < solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    for (int k = 0; k < solid.n_nodes_of(id); ++k)
      if (const std::int32_t s = slot[solid.nodes(id)[k].v]; s >= 0) ++start[s + 1];
  }
  for (std::int32_t i = 0; i < n_slots; ++i) start[i + 1] += start[i];
  elem.resize(start.back());
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t e = 0; e < solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    for (int k = 0; k < solid.n_nodes_of(id); ++k)
      if (const std::int32_t s = slot[solid.nodes(id)[k].v]; s >= 0) elem[fill[s]++] = id.v;
  }
  for (std::size_t e = 0; e < inter.size(); ++e) {
    const VertexId* v = inter.nodes(ElemId{static_cast<std::int32_t>(e)});
    const std::int32_t lo = std::min(v[0].v, v[1].v), hi = std::max(v[0].v, v[1].v), s = slot[lo];
    int uses = 0;
    std::int32_t user = -1;
    for (std::int32_t i = start[s]; i < start[s + 1]; ++i) {
      const ElemId id{elem[i]};
      if (i > start[s] && elem[i - 1] == id.v) continue;  // listed once per use of lo
      const int n = solid.n_nodes_of(id);
      const VertexId* w = solid.nodes(id);
      for (int k = 0; k < n; ++k) {
        const std::int32_t p = w[k].v, q = w[k + 1 == n ? 0 : k + 1].v;
        if (std::min(p, q) == lo && std::max(p, q) == hi) ++uses, user = id.v;
      }
    }
    if (uses == 1) out[e] = user;
  }
  return out;
}

}  // namespace

template <int Dim> std::string vtu_string(const Mesh<Dim>& mesh) {
  const std::size_t ns = mesh.solid.size(), ni = mesh.interface.size();
  std::vector<double> coords;
  coords.reserve(3 * mesh.points.size());
  for (const auto& p : mesh.points)
    for (int d = 0; d < 3; ++d) coords.push_back(d < Dim ? p[d] : 0.0);

  std::vector<std::int64_t> connectivity, offsets;
  std::vector<int> types, level, from_boundary, group;
  for (const Elements* els : {&mesh.solid, &mesh.interface}) {
    for (std::size_t e = 0; e < els->size(); ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      for (int i = 0; i < els->n_nodes_of(id); ++i) connectivity.push_back(els->nodes(id)[vtk_local(els->type[e], i)].v);
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(vtk_type(els->type[e]));
      group.push_back(els == &mesh.solid ? 1 : 2);
    }
  }
  std::vector<double> quality = scaled_jacobians<Dim>(mesh.solid, mesh.points);
  const std::vector<double> iq = scaled_jacobians<Dim>(mesh.interface, mesh.points);
  quality.insert(quality.end(), iq.begin(), iq.end());

  for (std::size_t e = 0; e < ns; ++e) {
    level.push_back(e < mesh.level.size() ? mesh.level[e] : 0);
    from_boundary.push_back(e < mesh.from_boundary_cell.size() ? mesh.from_boundary_cell[e] : 0);
  }
  if (ni != 0) {
    const std::vector<std::int32_t> owner = interface_owners<Dim>(mesh);
    for (std::size_t e = 0; e < ni; ++e) {
      level.push_back(owner[e] >= 0 ? level[owner[e]] : 0);
      from_boundary.push_back(owner[e] >= 0 ? from_boundary[owner[e]] : 0);
    }
  }

  Text out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << std::to_string(mesh.points.size()) << "\" NumberOfCells=\""
      << std::to_string(ns + ni) << "\">\n"
      << "      <Points>\n";
  array(out, "Float64", "Points", 3, coords);
  out << "      </Points>\n      <Cells>\n";
  array(out, "Int64", "connectivity", 1, connectivity);
  array(out, "Int64", "offsets", 1, offsets);
  array(out, "UInt8", "types", 1, types);
  out << "      </Cells>\n      <CellData Scalars=\"quality\">\n";
  array(out, "Float64", "quality", 1, quality);
  array(out, "Int32", "level", 1, level);
  array(out, "Int32", "from_boundary_cell", 1, from_boundary);
  array(out, "Int32", "group", 1, group);
  out << "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return out.take();
}

template <int Dim> void write_vtu(const Mesh<Dim>& mesh, const std::filesystem::path& path) {
  const std::string text = vtu_string<Dim>(mesh);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError("cannot open " + path.string() + " for writing: " + std::strerror(errno));
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (!out) throw InputError("cannot write " + path.string());
}

template std::string vtu_string<2>(const Mesh<2>&);
template std::string vtu_string<3>(const Mesh<3>&);
template void write_vtu<2>(const Mesh<2>&, const std::filesystem::path&);
template void write_vtu<3>(const Mesh<3>&, const std::filesystem::path&);

}  // namespace febemesh
