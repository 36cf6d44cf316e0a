// MSH 4.1 parser: a whitespace tokenizer that tracks lines for error messages; in binary files the
// section data are read as raw fields (int32, size_t of the header's size, double) instead.

#include "core/read_msh.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

#include "core/error.hpp"

namespace febemesh {

namespace {

class Tokens {
 public:
  Tokens(std::string_view text, std::string_view source) : s_(text), source_(source) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(std::string(source_) + ":" + std::to_string(line_) + ": " + what);
  }
  bool at_end() {
    skip_space();
    return pos_ >= s_.size();
  }
  std::string_view word() {
    in_data_ = false;
    skip_space();
    if (pos_ >= s_.size()) fail("unexpected end of file");
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !is_space(s_[pos_])) ++pos_;
    return s_.substr(start, pos_ - start);
  }
  /// A double-quoted string (physical names may contain spaces).
  std::string quoted() {
    skip_space();
    if (pos_ >= s_.size() || s_[pos_] != '"') fail("expected a quoted name");
    const std::size_t start = ++pos_;
    while (pos_ < s_.size() && s_[pos_] != '"' && s_[pos_] != '\n') ++pos_;
    if (pos_ >= s_.size() || s_[pos_] != '"') fail("unterminated quoted name");
    return std::string(s_.substr(start, pos_++ - start));
  }
  /// Binary mode: data fields are raw bytes; `size_bytes` is the file's size_t width (4 or 8).
  void set_binary(int size_bytes) {
    binary_ = true;
    size_bytes_ = size_bytes;
  }
  bool binary() const { return binary_; }
  /// A field of type int (entity dimensions, entity tags, element types, flags).
  int int_field(const char* what) {
    if (!binary_) return integer<int>(what);
    std::int32_t v;
    raw(&v, sizeof v, what);
    return v;
  }
  /// A field of type size_t (counts, node and element tags).
  std::int64_t size_field(const char* what) {
    if (!binary_) return integer<std::int64_t>(what);
    std::uint64_t v = 0;
    if (size_bytes_ == 4) {
      std::uint32_t w;
      raw(&w, sizeof w, what);
      v = w;
    } else {
      raw(&v, sizeof v, what);
    }
    if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      fail(std::string(what) + " out of range");
    return static_cast<std::int64_t>(v);
  }
  double real_field(const char* what) {
    if (!binary_) return real(what);
    double v;
    raw(&v, sizeof v, what);
    return v;
  }
  /// Raw bytes of a binary file (the 1 after the header).
  void raw(void* out, std::size_t n, const char* what) {
    if (!in_data_) {
      // Binary data start on the line after the section keyword.
      while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
      if (pos_ < s_.size()) ++pos_, ++line_;
      in_data_ = true;
    }
    if (s_.size() - pos_ < n) fail("unexpected end of file in binary data (" + std::string(what) + ")");
    std::memcpy(out, s_.data() + pos_, n);
    pos_ += n;
  }
  /// Upper bound on how many fields of `bytes` each the rest of the file can hold (reserve guard).
  std::size_t remaining(std::size_t bytes) const { return (s_.size() - pos_) / std::max<std::size_t>(bytes, 1); }

  template <class Int> Int integer(const char* what) {
    const std::string_view w = word();
    Int v{};
    const auto res = std::from_chars(w.data(), w.data() + w.size(), v);
    if (res.ec != std::errc() || res.ptr != w.data() + w.size())
      fail("expected an integer (" + std::string(what) + "), got '" + std::string(w) + "'");
    return v;
  }
  double real(const char* what) {
    const std::string_view w = word();
    double v = 0.0;
    const auto res = std::from_chars(w.data(), w.data() + w.size(), v);
    if (res.ec != std::errc() || res.ptr != w.data() + w.size())
      fail("expected a number (" + std::string(what) + "), got '" + std::string(w) + "'");
    return v;
  }
  void expect(std::string_view token) {
    const std::string_view w = word();
    if (w != token) fail("expected " + std::string(token) + ", got '" + std::string(w) + "'");
  }
  /// Skips to the line after `token` (unknown sections).
  void skip_past(std::string_view token) {
    while (!at_end())
      if (word() == token) return;
    fail("missing " + std::string(token));
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  void skip_space() {
    while (pos_ < s_.size() && is_space(s_[pos_])) {
      if (s_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string_view s_;
  std::string_view source_;
  std::size_t pos_ = 0;
  long line_ = 1;
  bool binary_ = false;
  bool in_data_ = false;  ///< raw reads continue where the previous one stopped
  int size_bytes_ = 8;
};

std::optional<ElemType> from_gmsh(int code) {
  for (int t = 0; t <= static_cast<int>(ElemType::Pyramid5); ++t)
    if (gmsh_type(static_cast<ElemType>(t)) == code) return static_cast<ElemType>(t);
  return std::nullopt;
}

struct RawElement {
  std::int64_t tag;
  ElemType type;
  std::array<std::int64_t, 8> nodes;
};

}  // namespace

template <int Dim> Mesh<Dim> parse_msh(std::string_view text, std::string_view source) {
  Tokens tok(text, source);
  std::map<std::pair<int, int>, std::string> physical_names;   // (dim, tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_phys;  // (dim, entity) -> physical tags
  std::vector<std::pair<std::int64_t, Point<Dim>>> nodes;
  struct Block {
    int dim, entity;
    std::vector<RawElement> elements;
  };
  std::vector<Block> blocks;
  bool seen_format = false;

  while (!tok.at_end()) {
    const std::string section(tok.word());
    if (section == "$MeshFormat") {
      const std::string_view version = tok.word();
      if (version != "4.1") tok.fail("MSH version " + std::string(version) + " is not supported (need 4.1)");
      const int file_type = tok.integer<int>("file type");
      const int data_size = tok.integer<int>("data size");
      if (file_type != 0 && file_type != 1) tok.fail("file type " + std::to_string(file_type) + " (need 0 or 1)");
      if (file_type == 1) {
        if (data_size != 4 && data_size != 8) tok.fail("data size " + std::to_string(data_size) + " (need 4 or 8)");
        tok.set_binary(data_size);
        std::int32_t one = 0;
        tok.raw(&one, sizeof one, "byte order mark");
        if (one != 1) tok.fail("binary MSH in the other byte order is not supported");
      }
      tok.expect("$EndMeshFormat");
      seen_format = true;
    } else if (!seen_format) {
      tok.fail("file does not start with $MeshFormat");
    } else if (section == "$PhysicalNames") {
      const auto n = tok.integer<long>("number of physical names");
      for (long i = 0; i < n; ++i) {
        const int dim = tok.integer<int>("physical dimension");
        const int tag = tok.integer<int>("physical tag");
        physical_names[{dim, tag}] = tok.quoted();
      }
      tok.expect("$EndPhysicalNames");
    } else if (section == "$Entities") {
      std::int64_t count[4];
      for (auto& c : count) c = tok.size_field("number of entities");
      for (int dim = 0; dim < 4; ++dim) {
        for (std::int64_t i = 0; i < count[dim]; ++i) {
          const int tag = tok.int_field("entity tag");
          for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) tok.real_field("entity coordinate");
          const auto n_phys = tok.size_field("number of physical tags");
          auto& phys = entity_phys[{dim, tag}];
          for (std::int64_t k = 0; k < n_phys; ++k) phys.push_back(tok.int_field("physical tag"));
          if (dim > 0) {
            const auto n_bound = tok.size_field("number of bounding entities");
            for (std::int64_t k = 0; k < n_bound; ++k) tok.int_field("bounding entity");
          }
        }
      }
      tok.expect("$EndEntities");
    } else if (section == "$Nodes") {
      const auto n_blocks = tok.size_field("number of node blocks");
      const auto n_nodes = tok.size_field("number of nodes");
      tok.size_field("min node tag");
      tok.size_field("max node tag");
      nodes.reserve(std::min(static_cast<std::size_t>(n_nodes), tok.remaining(2)));
      for (std::int64_t b = 0; b < n_blocks; ++b) {
        const int dim = tok.int_field("entity dimension");
        tok.int_field("entity tag");
        const int parametric = tok.int_field("parametric flag");
        const auto n = tok.size_field("nodes in block");
        const std::size_t first = nodes.size();
        for (std::int64_t i = 0; i < n; ++i) nodes.emplace_back(tok.size_field("node tag"), Point<Dim>::Zero());
        for (std::int64_t i = 0; i < n; ++i) {
          double xyz[3];
          for (double& c : xyz) c = tok.real_field("node coordinate");
          for (int d = 0; d < Dim; ++d) nodes[first + static_cast<std::size_t>(i)].second[d] = xyz[d];
          if (parametric) for (int k = 0; k < dim; ++k) tok.real_field("parametric coordinate");
        }
      }
      tok.expect("$EndNodes");
    } else if (section == "$Elements") {
      const auto n_blocks = tok.size_field("number of element blocks");
      for (int k = 0; k < 3; ++k) tok.size_field("element counts");
      for (std::int64_t b = 0; b < n_blocks; ++b) {
        Block block;
        block.dim = tok.int_field("entity dimension");
        block.entity = tok.int_field("entity tag");
        const int code = tok.int_field("element type");
        const auto n = tok.size_field("elements in block");
        const auto type = from_gmsh(code);
        const bool wanted = block.dim == Dim || block.dim == Dim - 1;
        if (!type && wanted) tok.fail("element type " + std::to_string(code) + " is not supported");
        if (type && dimension(*type) != block.dim) tok.fail("element type " + std::to_string(code) + " on an entity of dimension " + std::to_string(block.dim));
        // Point elements (type 15) have one node; other unsupported types lie outside Dim-1..Dim.
        const int per = type ? n_nodes(*type) : (code == 15 ? 1 : -1);
        if (per < 0) tok.fail("element type " + std::to_string(code) + " is not supported");
        if (type && wanted) block.elements.reserve(std::min(static_cast<std::size_t>(n), tok.remaining(2 * (per + 1))));
        for (std::int64_t i = 0; i < n; ++i) {
          RawElement el{tok.size_field("element tag"), type.value_or(ElemType::Line2), {}};
          for (int k = 0; k < per; ++k) el.nodes[k] = tok.size_field("node tag");
          if (type && wanted) block.elements.push_back(el);
        }
        if (type && wanted) blocks.push_back(std::move(block));
      }
      tok.expect("$EndElements");
    } else if (section == "$PartitionedEntities") {
      tok.fail("partitioned meshes are not supported");
    } else if (section.size() > 1 && section[0] == '$') {
      tok.skip_past("$End" + section.substr(1));
    } else {
      tok.fail("unexpected '" + section + "' outside a section");
    }
  }
  if (!seen_format) tok.fail("empty file: no $MeshFormat");

  // Groups by name when the file names them, else by dimension.
  int solid_tag = -1, interface_tag = -1;
  for (const auto& [key, nm] : physical_names) {
    if (nm == "solid") {
      if (key.first != Dim) tok.fail("physical group \"solid\" has dimension " + std::to_string(key.first) + ", expected " + std::to_string(Dim));
      solid_tag = key.second;
    } else if (nm == "interface") {
      if (key.first != Dim - 1) tok.fail("physical group \"interface\" has dimension " + std::to_string(key.first) + ", expected " + std::to_string(Dim - 1));
      interface_tag = key.second;
    }
  }
  const bool by_name = solid_tag >= 0 || interface_tag >= 0;

  std::sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (std::size_t i = 1; i < nodes.size(); ++i)
    if (nodes[i].first == nodes[i - 1].first) tok.fail("node tag " + std::to_string(nodes[i].first) + " appears twice");
  auto index_of = [&](std::int64_t tag) {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), tag, [](const auto& n, std::int64_t t) { return n.first < t; });
    if (it == nodes.end() || it->first != tag) tok.fail("element refers to unknown node tag " + std::to_string(tag));
    return VertexId{static_cast<std::int32_t>(it - nodes.begin())};
  };

  std::vector<RawElement> solid, interface;
  for (auto& block : blocks) {
    bool is_solid = false, is_interface = false;
    if (by_name) {
      const auto it = entity_phys.find({block.dim, block.entity});
      if (it != entity_phys.end()) {
        for (const int p : it->second) {
          is_solid |= block.dim == Dim && p == solid_tag;
          is_interface |= block.dim == Dim - 1 && p == interface_tag;
        }
      }
    } else {
      is_solid = block.dim == Dim;
      is_interface = block.dim == Dim - 1;
    }
    auto& dest = is_solid ? solid : interface;
    if (is_solid || is_interface) dest.insert(dest.end(), block.elements.begin(), block.elements.end());
  }

  Mesh<Dim> mesh;
  mesh.points.reserve(nodes.size());
  for (const auto& n : nodes) mesh.points.push_back(n.second);
  for (auto* group : {&solid, &interface}) {
    std::stable_sort(group->begin(), group->end(), [](const RawElement& a, const RawElement& b) { return a.tag < b.tag; });
    Elements& dest = group == &solid ? mesh.solid : mesh.interface;
    for (const RawElement& el : *group) {
      VertexId ids[8];
      for (int k = 0; k < n_nodes(el.type); ++k) ids[k] = index_of(el.nodes[k]);
      dest.add(el.type, ids, n_nodes(el.type));
    }
  }
  return mesh;
}

template <int Dim> Mesh<Dim> read_msh(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open " + path.string());
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_msh<Dim>(ss.str(), path.string());
}

template Mesh<2> parse_msh<2>(std::string_view, std::string_view);
template Mesh<3> parse_msh<3>(std::string_view, std::string_view);
template Mesh<2> read_msh<2>(const std::filesystem::path&);
template Mesh<3> read_msh<3>(const std::filesystem::path&);

}  // namespace febemesh
