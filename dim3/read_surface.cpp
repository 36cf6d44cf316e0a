#include "dim3/read_surface.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <vector>

#include "core/error.hpp"
#include "dim3/surface_text.hpp"

namespace febemesh::dim3 {

using namespace text;

namespace {

std::string lower_extension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

TriangleSoup read_off(std::istream& in, const std::string& name) {
  Lines lines = content_lines(in);
  if (lines.done()) fail(name, 0, "empty file (no OFF header, no vertices, no faces)");
  auto [first, first_line] = lines.items[lines.next++];
  std::vector<std::string> tok = split(first);
  // Header: OFF, COFF, NOFF, ... (the counts may follow on the same line).
  if (tok[0].size() >= 3 && tok[0].substr(tok[0].size() - 3) == "OFF") {
    tok.erase(tok.begin());
    if (tok.empty()) {
      if (lines.done()) fail(name, first_line, "truncated: OFF header without vertex and face counts");
      std::tie(first, first_line) = lines.items[lines.next++];
      tok = split(first);
    }
  } else {
    fail(name, first_line, "not an OFF file: expected the OFF header, found '" + tok[0] + "'");
  }
  long long nv = 0, nf = 0;
  if (tok.size() < 2 || !parse_long(tok[0], nv) || !parse_long(tok[1], nf) || nv < 0 || nf < 0)
    fail(name, first_line, "expected the vertex, face and edge counts, found '" + first + "'");
  if (nv == 0 || nf == 0)
    fail(name, first_line, "empty surface: " + std::to_string(nv) + " vertices, " + std::to_string(nf) + " faces");
  constexpr long long max_count = 1LL << 28;
  if (nv > max_count || nf > max_count) fail(name, first_line, "vertex or face count too large");

  // Each vertex and face takes a line of its own: reserve no more than the file has lines for
  // (a header of a small file may declare 2^28 faces; fuzz_off: a 2.7 GB reserve).
  const auto remaining = static_cast<long long>(lines.items.size() - lines.next);
  TriangleSoup soup;
  soup.vertices.reserve(static_cast<std::size_t>(std::min(nv, remaining)));
  soup.triangles.reserve(static_cast<std::size_t>(std::min(nf, remaining)));
  auto truncated = [&](const std::string& what, long long found) {
    const int last = lines.items.empty() ? 0 : lines.items.back().second;
    fail(name, last,
         "truncated: the header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
             " faces, the file ends after " + std::to_string(found) + " " + what);
  };
  for (long long i = 0; i < nv; ++i) {
    if (lines.done()) truncated("vertices", i);
    const auto& [text, line] = lines.items[lines.next++];
    const std::vector<std::string> t = split(text);
    P3 p;
    if (t.size() < 3 || !parse_double(t[0], p[0]) || !parse_double(t[1], p[1]) || !parse_double(t[2], p[2]))
      fail(name, line, "expected 3 coordinates for vertex " + std::to_string(i) + ", found '" + text + "'");
    if (!p.allFinite())
      fail(name, line, "non-finite coordinate in vertex " + std::to_string(i) + ": '" + text + "'");
    soup.vertices.push_back(p);
  }
  for (long long f = 0; f < nf; ++f) {
    if (lines.done()) truncated("faces", f);
    const auto& [text, line] = lines.items[lines.next++];
    const std::vector<std::string> t = split(text);
    long long n = 0;
    if (t.empty() || !parse_long(t[0], n) || n < 3 || static_cast<long long>(t.size()) < n + 1)
      fail(name, line, "face " + std::to_string(f) + ": expected a vertex count >= 3 and that many indices, found '" +
                           text + "'");
    std::vector<std::int32_t> idx(n);
    for (long long k = 0; k < n; ++k) {
      long long v = 0;
      if (!parse_long(t[k + 1], v)) fail(name, line, "face " + std::to_string(f) + ": bad index '" + t[k + 1] + "'");
      if (v < 0 || v >= nv)
        fail(name, line, "face " + std::to_string(f) + ": vertex index " + std::to_string(v) +
                             " out of range (the file has " + std::to_string(nv) + " vertices)");
      idx[k] = static_cast<std::int32_t>(v);
    }
    for (long long k = 1; k + 1 < n; ++k) soup.triangles.push_back({idx[0], idx[k], idx[k + 1]});
  }
  return soup;
}

TriangleSoup read_surface(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext != "off" && ext != "stl" && ext != "obj" && ext != "ply")
    throw InputError(path + ": unknown surface format '." + ext + "' (expected .off, .stl, .obj or .ply)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  if (in.peek() == std::ifstream::traits_type::eof()) throw InputError(path + ": empty file");
  if (ext == "off") return read_off(in, path);
  if (ext == "obj") return read_obj(in, path);
  if (ext == "ply") return read_ply(in, path);
  in.close();
  return read_with_openmesh(path);
}

}  // namespace febemesh::dim3
