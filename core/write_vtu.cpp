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
    std::vector<std::pair<FacetKey, ElemId>> owner;
    for (const BoundaryFacet& b : boundary_facets(mesh.solid)) owner.emplace_back(key_of(b.facet), b.elem);
    std::sort(owner.begin(), owner.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t e = 0; e < ni; ++e) {
      const FacetKey k = key_of(as_facet(mesh.interface, ElemId{static_cast<std::int32_t>(e)}));
      const auto it = std::lower_bound(owner.begin(), owner.end(), k, [](const auto& o, const FacetKey& key) { return o.first < key; });
      const bool found = it != owner.end() && it->first == k;
      level.push_back(found ? level[it->second.v] : 0);
      from_boundary.push_back(found ? from_boundary[it->second.v] : 0);
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
