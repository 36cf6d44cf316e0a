// Wavefront OBJ surfaces, parsed here rather than by OpenMesh: its reader (OpenMesh 9.0 as
// Debian builds it, assertions on) aborts the process on a face without a valid corner ("f 1 0
// 1": `!vhandles.empty()`, found by fuzz_obj), and reads coordinates as float. Read: "v x y z [w]" vertices and
// "f i j k ..." faces, a corner written i, i/t, i//n or i/t/n, a negative i counting back from
// the last vertex read; every other statement (vt, vn, g, o, s, usemtl, mtllib, l, p, ...) is
// skipped. Polygons become triangle fans. Errors name the line.

#include <cstdint>
#include <string>
#include <vector>

#include "dim3/read_surface.hpp"
#include "dim3/surface_text.hpp"

namespace febemesh::dim3 {

using namespace text;

TriangleSoup read_obj(std::istream& in, const std::string& name) {
  const Lines lines = content_lines(in);
  TriangleSoup soup;
  struct Face {
    std::size_t first;  ///< into corners
    int line;
  };
  std::vector<Face> faces;
  std::vector<long long> corners;  // 0-based, checked against the vertex count at the end
  for (const auto& [content, line] : lines.items) {
    const std::vector<std::string> t = split(content);
    if (t[0] == "v") {
      P3 p;
      if (t.size() < 4 || !parse_double(t[1], p[0]) || !parse_double(t[2], p[1]) || !parse_double(t[3], p[2]))
        fail(name, line, "expected 3 coordinates for vertex " + std::to_string(soup.vertices.size()) + ", found '" +
                             content + "'");
      if (!p.allFinite())
        fail(name, line, "non-finite coordinate in vertex " + std::to_string(soup.vertices.size()) + ": '" + content + "'");
      soup.vertices.push_back(p);
    } else if (t[0] == "f") {
      const std::string face = "face " + std::to_string(faces.size());
      if (t.size() < 4) fail(name, line, face + ": fewer than three corners: '" + content + "'");
      faces.push_back({corners.size(), line});
      for (std::size_t k = 1; k < t.size(); ++k) {
        long long v = 0;
        if (!parse_long(t[k].substr(0, t[k].find('/')), v))
          fail(name, line, face + ": bad vertex index '" + t[k] + "'");
        if (v == 0) fail(name, line, face + ": vertex index 0 (OBJ counts vertices from 1)");
        // Negative: relative to the vertices read so far (-1 the last).
        corners.push_back(v > 0 ? v - 1 : static_cast<long long>(soup.vertices.size()) + v);
        if (corners.back() < 0)
          fail(name, line, face + ": vertex index " + std::to_string(v) + " reaches before the first vertex");
      }
    }
  }
  if (soup.vertices.empty() || faces.empty())
    fail(name, 0, "empty surface: " + std::to_string(soup.vertices.size()) + " vertices, " + std::to_string(faces.size()) +
                      " faces");
  const auto nv = static_cast<long long>(soup.vertices.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::size_t end = f + 1 < faces.size() ? faces[f + 1].first : corners.size();
    std::vector<std::int32_t> idx;
    for (std::size_t k = faces[f].first; k < end; ++k) {
      if (corners[k] >= nv)
        fail(name, faces[f].line, "face " + std::to_string(f) + ": vertex index " + std::to_string(corners[k] + 1) +
                                      " out of range (the file has " + std::to_string(nv) + " vertices)");
      for (const std::int32_t u : idx)
        if (u == corners[k])
          fail(name, faces[f].line, "face " + std::to_string(f) + ": vertex " + std::to_string(u + 1) + " appears twice");
      idx.push_back(static_cast<std::int32_t>(corners[k]));
    }
    for (std::size_t k = 1; k + 1 < idx.size(); ++k) soup.triangles.push_back({idx[0], idx[k], idx[k + 1]});
  }
  return soup;
}

}  // namespace febemesh::dim3
