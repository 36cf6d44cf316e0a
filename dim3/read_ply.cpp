// Stanford PLY surfaces (ASCII, binary little- and big-endian), parsed here rather than by
// OpenMesh: its reader (OpenMesh 9.0) loops for ever on a header whose end_header is garbled
// (found by fuzz_ply: "Unsupported keyword" without end), and reads coordinates as float. Read:
// the "vertex" element's x, y, z (any numeric type; other properties skipped) and the "face"
// element's list "vertex_indices" (or "vertex_index"); every other element is read past.
// Polygons become triangle fans. Counts are checked against what the file can hold before
// anything is reserved. Errors name the header line, or the element and item.

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "dim3/read_surface.hpp"
#include "dim3/surface_text.hpp"

namespace febemesh::dim3 {

using namespace text;

namespace {

enum class Type { i8, u8, i16, u16, i32, u32, f32, f64, none };

Type type_of(const std::string& s) {
  if (s == "char" || s == "int8") return Type::i8;
  if (s == "uchar" || s == "uint8") return Type::u8;
  if (s == "short" || s == "int16") return Type::i16;
  if (s == "ushort" || s == "uint16") return Type::u16;
  if (s == "int" || s == "int32") return Type::i32;
  if (s == "uint" || s == "uint32") return Type::u32;
  if (s == "float" || s == "float32") return Type::f32;
  if (s == "double" || s == "float64") return Type::f64;
  return Type::none;
}

std::size_t size_of(Type t) {
  switch (t) {
    case Type::i8:
    case Type::u8: return 1;
    case Type::i16:
    case Type::u16: return 2;
    case Type::i32:
    case Type::u32:
    case Type::f32: return 4;
    case Type::f64: return 8;
    case Type::none: break;
  }
  return 0;
}

struct Property {
  std::string name;
  Type type = Type::none;        ///< the scalar's, or a list's items'
  Type count_type = Type::none;  ///< a list's count; none: a scalar
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
  int line = 0;
};

enum class Format { ascii, little, big };

/// Reads the values after the header, in order: ASCII tokens or binary scalars.
class Values {
 public:
  Values(std::string data, Format format, int first_line, const std::string& name)
      : data_(std::move(data)), format_(format), line_(first_line), name_(name) {}

  /// The next value of type t, as a double (integers exactly), or throws naming `what`.
  double next(Type t, const std::string& what) {
    if (format_ == Format::ascii) {
      while (at_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[at_])))
        if (data_[at_++] == '\n') ++line_;
      if (at_ >= data_.size()) fail(name_, line_, "truncated: the file ends before " + what);
      std::size_t end = at_;
      while (end < data_.size() && !std::isspace(static_cast<unsigned char>(data_[end]))) ++end;
      const std::string token = data_.substr(at_, end - at_);
      at_ = end;
      double v = 0;
      if (t == Type::f32 || t == Type::f64) {
        if (!parse_double(token, v)) fail(name_, line_, "bad number '" + token + "' for " + what);
      } else {
        long long i = 0;
        if (!parse_long(token, i)) fail(name_, line_, "bad integer '" + token + "' for " + what);
        v = static_cast<double>(i);
      }
      return v;
    }
    const std::size_t n = size_of(t);
    if (data_.size() - at_ < n) fail(name_, 0, "truncated: the file ends before " + what);
    std::array<unsigned char, 8> b{};
    std::memcpy(b.data(), data_.data() + at_, n);
    at_ += n;
    if (format_ == Format::big) std::reverse(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
    switch (t) {
      case Type::i8: return static_cast<std::int8_t>(b[0]);
      case Type::u8: return b[0];
      case Type::i16: return read_as<std::int16_t>(b);
      case Type::u16: return read_as<std::uint16_t>(b);
      case Type::i32: return read_as<std::int32_t>(b);
      case Type::u32: return read_as<std::uint32_t>(b);
      case Type::f32: return read_as<float>(b);
      case Type::f64: return read_as<double>(b);
      case Type::none: break;
    }
    return 0;
  }
  /// At most how many more items of an element could follow: at least `min_size` bytes each
  /// (binary), or a token and a separator (ASCII).
  long long room(std::size_t min_size) const {
    const std::size_t left = data_.size() - at_;
    return static_cast<long long>(format_ == Format::ascii ? (left + 1) / 2 : left / std::max<std::size_t>(1, min_size));
  }

 private:
  template <class T> static double read_as(const std::array<unsigned char, 8>& b) {
    T v;
    std::memcpy(&v, b.data(), sizeof v);  // little-endian host, as everywhere we build
    return static_cast<double>(v);
  }
  std::string data_;
  Format format_;
  std::size_t at_ = 0;
  int line_;
  const std::string& name_;
};

}  // namespace

TriangleSoup read_ply(std::istream& in, const std::string& name) {
  // The header: text lines up to end_header (at most 10,000 of them).
  std::string line;
  int number = 0;
  const auto next_line = [&]() -> bool {
    if (!std::getline(in, line)) return false;
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next_line() || line != "ply") fail(name, 1, "not a PLY file: the first line is not 'ply'");
  Format format = Format::ascii;
  bool has_format = false;
  std::vector<Element> elements;
  for (;;) {
    if (number > 10000) fail(name, number, "no end_header in the first 10,000 lines");
    if (!next_line()) fail(name, number, "truncated header: no end_header");
    const std::vector<std::string> t = split(line);
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") break;
    if (t[0] == "format") {
      if (t.size() < 3 || t[2] != "1.0") fail(name, number, "unsupported format line '" + line + "'");
      if (t[1] == "ascii") format = Format::ascii;
      else if (t[1] == "binary_little_endian") format = Format::little;
      else if (t[1] == "binary_big_endian") format = Format::big;
      else fail(name, number, "unknown format '" + t[1] + "'");
      has_format = true;
    } else if (t[0] == "element") {
      long long n = 0;
      if (t.size() != 3 || !parse_long(t[2], n) || n < 0) fail(name, number, "expected 'element NAME COUNT', found '" + line + "'");
      elements.push_back({t[1], n, {}, number});
    } else if (t[0] == "property") {
      if (elements.empty()) fail(name, number, "a property before any element");
      Property p;
      if (t.size() == 5 && t[1] == "list") {
        p.count_type = type_of(t[2]), p.type = type_of(t[3]), p.name = t[4];
        if (p.count_type == Type::none || p.type == Type::none || p.count_type == Type::f32 || p.count_type == Type::f64)
          fail(name, number, "bad list property '" + line + "'");
      } else if (t.size() == 3) {
        p.type = type_of(t[1]), p.name = t[2];
        if (p.type == Type::none) fail(name, number, "unknown property type '" + t[1] + "'");
      } else {
        fail(name, number, "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME', found '" + line + "'");
      }
      elements.back().properties.push_back(p);
    } else {
      fail(name, number, "unknown header keyword '" + t[0] + "'");
    }
  }
  if (!has_format) fail(name, number, "no format line in the header");
  Values values(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()), format, number + 1, name);

  TriangleSoup soup;
  bool has_vertices = false, has_faces = false;
  long long nv = 0, n_faces = 0;
  std::vector<std::int32_t> idx;
  for (const Element& e : elements) {
    std::size_t min_size = 0;
    for (const Property& p : e.properties) min_size += size_of(p.count_type == Type::none ? p.type : p.count_type);
    if (e.count > values.room(min_size))
      fail(name, e.line, "element " + e.name + " declares " + std::to_string(e.count) + " items, more than the file holds");
    const bool vertex = e.name == "vertex", face = e.name == "face";
    std::array<int, 3> xyz{-1, -1, -1};
    int list = -1;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      if (vertex && p.count_type == Type::none && p.name.size() == 1 && p.name[0] >= 'x' && p.name[0] <= 'z')
        xyz[static_cast<std::size_t>(p.name[0] - 'x')] = static_cast<int>(k);
      if (face && p.count_type != Type::none && (p.name == "vertex_indices" || p.name == "vertex_index")) list = static_cast<int>(k);
    }
    if (vertex) {
      if (std::find(xyz.begin(), xyz.end(), -1) != xyz.end()) fail(name, e.line, "the vertex element lacks x, y or z");
      has_vertices = true, nv = e.count;
      soup.vertices.reserve(static_cast<std::size_t>(e.count));
    }
    if (face) {
      if (list < 0) fail(name, e.line, "the face element has no list property vertex_indices");
      has_faces = true, n_faces = e.count;
    }
    for (long long i = 0; i < e.count; ++i) {
      const std::string item = e.name + " " + std::to_string(i);
      P3 p = P3::Zero();
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const Property& prop = e.properties[k];
        if (prop.count_type == Type::none) {
          const double v = values.next(prop.type, item + " (" + prop.name + ")");
          for (int d = 0; d < 3; ++d)
            if (vertex && xyz[static_cast<std::size_t>(d)] == static_cast<int>(k)) p[d] = v;
          continue;
        }
        const double n = values.next(prop.count_type, item + " (" + prop.name + " count)");
        if (!(n >= 0) || n > 1e6) fail(name, e.line, item + ": list count " + std::to_string(n) + " out of range");
        const bool corners = face && static_cast<int>(k) == list;
        if (corners && n < 3) fail(name, e.line, item + ": fewer than three corners");
        idx.clear();
        for (long long j = 0; j < static_cast<long long>(n); ++j) {
          const double v = values.next(prop.type, item + " (" + prop.name + ")");
          if (!corners) continue;
          if (!(v >= 0 && v < static_cast<double>(nv)) || !has_vertices || v != std::floor(v)) {
            const std::string shown = std::abs(v) < 9e18 && v == std::floor(v) ? std::to_string(static_cast<long long>(v))
                                                                                : std::to_string(v);
            fail(name, e.line, item + ": vertex index " + shown + " out of range (the file has " + std::to_string(nv) +
                                   " vertices before it)");
          }
          const auto u = static_cast<std::int32_t>(v);
          if (std::find(idx.begin(), idx.end(), u) != idx.end())
            fail(name, e.line, item + ": vertex " + std::to_string(u) + " appears twice");
          idx.push_back(u);
        }
        for (std::size_t j = 1; j + 1 < idx.size(); ++j) soup.triangles.push_back({idx[0], idx[j], idx[j + 1]});
      }
      if (vertex) {
        if (!p.allFinite()) fail(name, e.line, "non-finite coordinate in vertex " + std::to_string(i));
        soup.vertices.push_back(p);
      }
    }
  }
  if (!has_vertices || !has_faces || nv == 0 || n_faces == 0)
    fail(name, 0, "empty surface: " + std::to_string(nv) + " vertices, " + std::to_string(n_faces) + " faces");
  return soup;
}

}  // namespace febemesh::dim3
