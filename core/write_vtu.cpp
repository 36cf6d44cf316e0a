// VTU text built with std::to_chars in one buffer; with VtuEncoding::Binary the arrays as raw
// appended data.

#include "core/write_vtu.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <limits>
#include <memory>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/spill_buffer.hpp"
#include "core/mesh_topology.hpp"
#include "core/quality.hpp"

namespace febemesh {

namespace {

/// Text built with std::to_chars; with a file it spills every few MiB (SpillBuffer).
class Text : public SpillBuffer {
 public:
  explicit Text(std::FILE* file = nullptr, std::string path = {})
      : SpillBuffer(file, std::move(path), file ? chunk + (1 << 16) : 0) {}
  Text& operator<<(std::string_view s) {
    put(s);
    return *this;
  }
  /// Raw bytes (the appended block of a binary file).
  void bytes(const void* p, std::size_t n) { put(std::string_view(static_cast<const char*>(p), n)); }
  template <class Num> Text& num(Num v) {
    append_number(v);
    put(' ');
    return *this;
  }
};

/// A value in [-1, 1] rounded to six decimals, written by integer arithmetic ("-0.5", "0.734512",
/// "1"); anything else (NaN) as the shortest text of the float. Issue 8: to_chars of the quality
/// was 110 M (double) then 73 M (float) instructions of sphere966 level 5's 8.2 G; a colour map
/// shows no seventh decimal.
struct Fixed6 {
  double v;
};
template <> Text& Text::num(Fixed6 x) {
  if (!(std::abs(x.v) <= 1.0)) return num(static_cast<float>(x.v));
  long m = std::lround(std::abs(x.v) * 1e6);
  char digits[16];
  int n = 0;
  if (x.v < 0 && m != 0) digits[n++] = '-';
  digits[n++] = static_cast<char>('0' + m / 1000000);
  m %= 1000000;
  if (m != 0) {
    digits[n++] = '.';
    for (long p = 100000; m != 0; p /= 10) {
      digits[n++] = static_cast<char>('0' + m / p);
      m %= p;
    }
  }
  digits[n++] = ' ';
  *this << std::string_view(digits, static_cast<std::size_t>(n));
  return *this;
}

/// VTK's node order from Gmsh's: only the wedge differs (VTK's first triangle faces away from
/// the second, Gmsh's faces towards it).
int vtk_local(ElemType t, int i) {
  constexpr int prism[6] = {0, 2, 1, 3, 5, 4};
  return t == ElemType::Prism6 ? prism[i] : i;
}

/// VTK's name of the value type T.
template <class T> constexpr const char* vtk_value_type() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  else if constexpr (std::is_same_v<T, float>) return "Float32";
  else if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  else if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  else if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
  else static_assert(sizeof(T) == 0, "no VTK type");
}

/// How write_vtu_text writes its arrays. ASCII: in place, as text. Binary (VtuEncoding::Binary,
/// VTK's raw appended data): a first pass writes the XML with each array's offset into the
/// appended block (and no values), a second pass the block alone: for each array its size in
/// bytes (UInt64) and its values, little-endian as the machine's.
struct Pass {
  bool binary = false;
  bool block = false;        ///< the second pass: values only
  std::uint64_t offset = 0;  ///< the appended block's size so far (first pass)
};

/// A DataArray of `count` values of type T, value(i) for i = 0, 1, ... in order (twelve to a
/// line in ASCII; Float32 rounded to six decimals there, Fixed6). XML goes to `xml`, the
/// binary block to `out`.
template <class T, class Value>
void array(Text& xml, Text& out, Pass& pass, const char* name, int components, std::size_t count, Value&& value) {
  if (!pass.block) {
    xml << "        <DataArray type=\"" << vtk_value_type<T>() << "\" Name=\"" << name << "\"";
    if (components > 1) xml << " NumberOfComponents=\"" << std::to_string(components) << "\"";
  }
  if (pass.binary && !pass.block) {
    xml << " format=\"appended\" offset=\"" << std::to_string(pass.offset) << "\"/>\n";
    pass.offset += sizeof(std::uint64_t) + count * sizeof(T);
    return;
  }
  if (pass.binary) {
    static_assert(std::endian::native == std::endian::little, "the file says LittleEndian");
    const std::uint64_t n_bytes = count * sizeof(T);
    out.bytes(&n_bytes, sizeof n_bytes);
    constexpr std::size_t batch = 4096;
    T values[batch];
    for (std::size_t i = 0; i < count;) {
      const std::size_t n = std::min(batch, count - i);
      for (std::size_t k = 0; k < n; ++k, ++i) values[k] = static_cast<T>(value(i));
      out.bytes(values, n * sizeof(T));
      out.maybe_flush();
    }
    return;
  }
  xml << " format=\"ascii\">\n";
  for (std::size_t i = 0, on_line = 0; i < count; ++i) {
    if constexpr (std::is_same_v<T, float>) xml.num(Fixed6{static_cast<double>(value(i))});
    else xml.num(value(i));
    if (++on_line == 12 || i + 1 == count) {
      xml << "\n";
      xml.maybe_flush();
      on_line = 0;
    }
  }
  xml << "        </DataArray>\n";
}

/// The solid elements at each node with a slot (slot[v] >= 0; nodes with negative ids have
/// none), as CSR: slot s's are elem[start[s] .. start[s + 1]), in element order, an element
/// once per use of the node.
void elements_at_slots(const Elements& solid, const std::vector<std::int32_t>& slot, std::int32_t n_slots,
                       std::vector<std::int32_t>& start, std::vector<std::int32_t>& elem) {
  const auto slot_of = [&](VertexId v) { return v.v >= 0 ? slot[static_cast<std::size_t>(v.v)] : -1; };
  start.assign(static_cast<std::size_t>(n_slots) + 1, 0);
  for (std::size_t e = 0; e < solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    for (int k = 0; k < solid.n_nodes_of(id); ++k)
      if (const std::int32_t s = slot_of(solid.nodes(id)[k]); s >= 0) ++start[s + 1];
  }
  for (std::int32_t i = 0; i < n_slots; ++i) start[i + 1] += start[i];
  elem.resize(start.back());
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t e = 0; e < solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    for (int k = 0; k < solid.n_nodes_of(id); ++k)
      if (const std::int32_t s = slot_of(solid.nodes(id)[k]); s >= 0) elem[fill[s]++] = id.v;
  }
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
    // A facet with key k belongs to elements at its smallest node k.v[0]; those of the interface
    // facets' smallest nodes are listed (CSR) and their facets with key k counted: one use is a
    // boundary facet (boundary_facets' rule), with that owner. Issue 8: boundary_facets of the
    // whole solid and a sort were 606 M instructions of sphere966 level 5's 1.07 G in write_vtu.
    std::int32_t top = -1;
    bool ids_ok = true;
    for (const VertexId v : solid.node) top = std::max(top, v.v);
    for (const VertexId v : inter.node) top = std::max(top, v.v), ids_ok = ids_ok && v.v >= 0;
    std::vector<FacetKey> keys(inter.size());
    for (std::size_t e = 0; e < inter.size(); ++e) keys[e] = key_of(as_facet(inter, ElemId{static_cast<std::int32_t>(e)}));
    if (ids_ok) {
      std::vector<std::int32_t> slot(static_cast<std::size_t>(top) + 1, -1), start, elem;
      std::int32_t n_slots = 0;
      for (const FacetKey& k : keys) {
        std::int32_t& s = slot[static_cast<std::size_t>(k.v[0])];
        if (s < 0) s = n_slots++;
      }
      elements_at_slots(solid, slot, n_slots, start, elem);
      for (std::size_t e = 0; e < inter.size(); ++e) {
        const std::int32_t s = slot[static_cast<std::size_t>(keys[e].v[0])];
        int uses = 0;
        std::int32_t user = -1;
        for (std::int32_t i = start[s]; i < start[s + 1]; ++i) {
          const ElemId id{elem[i]};
          if (i > start[s] && elem[i - 1] == id.v) continue;  // listed once per use of the node
          // Only an element with every node of the key can have a facet with that key.
          const VertexId* w = solid.nodes(id);
          const int n = solid.n_nodes_of(id);
          bool has_all = true;
          for (int j = 1; j < 4 && keys[e].v[j] >= 0 && has_all; ++j)
            has_all = std::any_of(w, w + n, [&](VertexId v) { return v.v == keys[e].v[j]; });
          if (!has_all) continue;
          for (int f = 0; f < n_facets(solid.type[elem[i]]); ++f)
            if (key_of(facet_of(solid, id, f)) == keys[e]) ++uses, user = id.v;
        }
        if (uses == 1) out[e] = user;
      }
      return out;
    }
    std::vector<std::pair<FacetKey, ElemId>> owner;
    for (const BoundaryFacet& b : boundary_facets(solid)) owner.emplace_back(key_of(b.facet), b.elem);
    std::sort(owner.begin(), owner.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t e = 0; e < inter.size(); ++e) {
      const FacetKey& k = keys[e];
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
  elements_at_slots(solid, slot, n_slots, start, elem);
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

/// array<Wide>, but in binary array<Narrow> when `narrow` (every value fits it): node ids and
/// offsets as Int32, the small cell data as UInt8 (the text keeps its types, and its bytes).
template <class Wide, class Narrow, class Value>
void array_narrowed(Text& xml, Text& out, Pass& pass, bool narrow, const char* name, std::size_t count, Value&& value) {
  if (pass.binary && narrow) array<Narrow>(xml, out, pass, name, 1, count, value);
  else array<Wide>(xml, out, pass, name, 1, count, value);
}

// Every array is generated from the mesh as it is written: the value arrays and the text were
// ~2x the mesh at the CLI's memory peak. Connectivity and offsets walk the elements in order
// (solid, then interface) with a cursor that the array's index follows. The XML goes to `xml`
// and the binary block to `out` (Pass); `owner`: interface_owners.
template <int Dim>
void write_vtu_text(Text& xml, Text& out, Pass& pass, const Mesh<Dim>& mesh, const std::vector<std::int32_t>& owner) {
  const std::size_t ns = mesh.solid.size(), ni = mesh.interface.size(), n = ns + ni;
  const Elements* const parts[2] = {&mesh.solid, &mesh.interface};
  auto element = [&](std::size_t c) { return c < ns ? std::pair{parts[0], c} : std::pair{parts[1], c - ns}; };
  // The owners' level and from_boundary_cell for the interface cells.
  auto level_of = [&](std::size_t e) { return e < mesh.level.size() ? int(mesh.level[e]) : 0; };
  auto from_boundary_of = [&](std::size_t e) {
    return e < mesh.from_boundary_cell.size() ? int(mesh.from_boundary_cell[e]) : 0;
  };

  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << std::to_string(mesh.points.size()) << "\" NumberOfCells=\""
      << std::to_string(n) << "\">\n"
      << "      <Points>\n";
  array<double>(xml, out, pass, "Points", 3, 3 * mesh.points.size(), [&](std::size_t i) {
    const int d = static_cast<int>(i % 3);
    return d < Dim ? mesh.points[i / 3][d] : 0.0;
  });
  xml << "      </Points>\n      <Cells>\n";
  std::size_t n_conn = 0;
  for (std::size_t c = 0; c < n; ++c) {
    const auto [els, e] = element(c);
    n_conn += static_cast<std::size_t>(els->n_nodes_of(ElemId{static_cast<std::int32_t>(e)}));
  }
  {
    std::size_t cell = 0;
    int local = 0;
    const bool narrow = mesh.points.size() <= std::size_t(std::numeric_limits<std::int32_t>::max());
    array_narrowed<std::int64_t, std::int32_t>(xml, out, pass, narrow, "connectivity", n_conn, [&](std::size_t) {
      for (;; local = 0, ++cell) {
        const auto [els, e] = element(cell);
        const ElemId id{static_cast<std::int32_t>(e)};
        const int nn = els->n_nodes_of(id);
        if (local == nn) continue;
        const auto v = static_cast<std::int64_t>(els->nodes(id)[vtk_local(els->type[e], local)].v);
        if (++local == nn) local = 0, ++cell;
        return v;
      }
    });
  }
  {
    std::int64_t end = 0;
    const bool narrow = n_conn <= std::size_t(std::numeric_limits<std::int32_t>::max());
    array_narrowed<std::int64_t, std::int32_t>(xml, out, pass, narrow, "offsets", n, [&](std::size_t c) {
      const auto [els, e] = element(c);
      end += els->n_nodes_of(ElemId{static_cast<std::int32_t>(e)});
      return end;
    });
  }
  array<std::uint8_t>(xml, out, pass, "types", 1, n, [&](std::size_t c) {
    const auto [els, e] = element(c);
    return vtk_type(els->type[e]);
  });
  xml << "      </Cells>\n      <CellData Scalars=\"quality\">\n";
  array<float>(xml, out, pass, "quality", 1, n, [&](std::size_t c) {
    const auto [els, e] = element(c);
    const auto ep = element_points<Dim>(*els, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
    return scaled_jacobian<Dim>(els->type[e], ep.span());
  });
  array_narrowed<std::int32_t, std::uint8_t>(xml, out, pass, true, "level", n, [&](std::size_t c) {
    if (c < ns) return level_of(c);
    const std::int32_t o = owner[c - ns];
    return o >= 0 ? level_of(static_cast<std::size_t>(o)) : 0;
  });
  array_narrowed<std::int32_t, std::uint8_t>(xml, out, pass, true, "from_boundary_cell", n, [&](std::size_t c) {
    if (c < ns) return from_boundary_of(c);
    const std::int32_t o = owner[c - ns];
    return o >= 0 ? from_boundary_of(static_cast<std::size_t>(o)) : 0;
  });
  array_narrowed<std::int32_t, std::uint8_t>(xml, out, pass, true, "group", n, [&](std::size_t c) { return c < ns ? 1 : 2; });
  xml << "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n";
}

/// The whole file into `out`: the XML, and with a binary encoding the appended block.
template <int Dim> void write_vtu_to(Text& out, const Mesh<Dim>& mesh, VtuEncoding encoding) {
  std::vector<std::int32_t> owner;
  if (mesh.interface.size() != 0) owner = interface_owners<Dim>(mesh);
  Pass pass;
  pass.binary = encoding == VtuEncoding::Binary;
  write_vtu_text<Dim>(out, out, pass, mesh, owner);
  if (pass.binary) {
    out << "  <AppendedData encoding=\"raw\">\n   _";
    Text no_xml;  // the second pass writes values only
    pass.block = true;
    write_vtu_text<Dim>(no_xml, out, pass, mesh, owner);
    out << "\n  </AppendedData>\n";
  }
  out << "</VTKFile>\n";
}

}  // namespace

template <int Dim> std::string vtu_string(const Mesh<Dim>& mesh, VtuEncoding encoding) {
  Text out;
  write_vtu_to<Dim>(out, mesh, encoding);
  return out.take();
}

template <int Dim> void write_vtu(const Mesh<Dim>& mesh, const std::filesystem::path& path, VtuEncoding encoding) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw InputError("cannot open " + path.string() + " for writing: " + std::strerror(errno));
  Text out(file.get(), path.string());
  write_vtu_to<Dim>(out, mesh, encoding);
  out.flush();
  if (std::fflush(file.get()) != 0) throw InputError("cannot write " + path.string() + ": " + std::strerror(errno));
}

template std::string vtu_string<2>(const Mesh<2>&, VtuEncoding);
template std::string vtu_string<3>(const Mesh<3>&, VtuEncoding);
template void write_vtu<2>(const Mesh<2>&, const std::filesystem::path&, VtuEncoding);
template void write_vtu<3>(const Mesh<3>&, const std::filesystem::path&, VtuEncoding);

}  // namespace febemesh
