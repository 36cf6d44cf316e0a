// Reading surfaces: every closed data file reads with the right counts and topology; bad inputs
// are refused with the file name and the reason; inverted surfaces are fixed.

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "dim3/read_surface.hpp"
#include "dim3/surface.hpp"
#include "dim3/surface_boundary.hpp"
#include "dim3/surface_checks.hpp"
#include "scratch_dir.hpp"

using namespace febemesh;
using namespace febemesh::dim3;
namespace fs = std::filesystem;

namespace {

const std::string data3d = std::string(FEBEMESH_DATA_DIR) + "/3d/";
const std::string bad_dir = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/bad_inputs/";

/// Vertex and face counts from an OFF header (skipping comments), independent of read_off.
std::pair<long, long> off_header_counts(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  bool header = false;
  while (std::getline(in, line)) {
    if (const auto h = line.find('#'); h != std::string::npos) line.resize(h);
    std::istringstream ss(line);
    std::string first;
    if (!(ss >> first)) continue;
    if (!header && first == "OFF") {
      header = true;
      continue;
    }
    long nv = std::stol(first), nf = 0;
    ss >> nf;
    return {nv, nf};
  }
  return {-1, -1};
}

std::string refusal(const std::string& path) {
  try {
    Surface s(read_surface(path));
    validate_surface(s, path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The unit cube, outward, as 8 vertices and 12 triangles.
const double cube_v[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const int cube_f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                           {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

/// The cube as OBJ, ASCII PLY (coordinates of `ply_type`), ASCII STL and binary STL: files
/// STEM.obj, STEM.ply, STEM-ascii.stl and STEM-binary.stl in `dir`, corner k of face f being
/// vertex corner(f, k).
template <class Corner>
std::array<fs::path, 4> write_cube(const fs::path& dir, const std::string& stem, const std::string& ply_type,
                                   const Corner& corner) {
  const fs::path obj = dir / (stem + ".obj"), ply = dir / (stem + ".ply"), ascii = dir / (stem + "-ascii.stl"),
                 binary = dir / (stem + "-binary.stl");
  std::ofstream o(obj), p(ply), a(ascii), b(binary, std::ios::binary);
  p << "ply\nformat ascii 1.0\nelement vertex 8\nproperty " << ply_type << " x\nproperty " << ply_type << " y\nproperty "
    << ply_type << " z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : cube_v) {
    o << "v " << v[0] << " " << v[1] << " " << v[2] << "\n";
    p << v[0] << " " << v[1] << " " << v[2] << "\n";
  }
  a << "solid " << stem << "\n";
  char header[80] = {};
  const std::string title = "binary " + stem;
  std::memcpy(header, title.data(), std::min<std::size_t>(title.size(), sizeof header));
  b.write(header, 80);
  const std::uint32_t n = 12;
  b.write(reinterpret_cast<const char*>(&n), 4);
  for (int f = 0; f < 12; ++f) {
    o << "f " << corner(f, 0) + 1 << " " << corner(f, 1) + 1 << " " << corner(f, 2) + 1 << "\n";
    p << "3 " << corner(f, 0) << " " << corner(f, 1) << " " << corner(f, 2) << "\n";
    a << " facet normal 0 0 0\n  outer loop\n";
    float values[12] = {};
    for (int k = 0; k < 3; ++k) {
      const double* q = cube_v[corner(f, k)];
      a << "   vertex " << q[0] << " " << q[1] << " " << q[2] << "\n";
      for (int d = 0; d < 3; ++d) values[3 + 3 * k + d] = static_cast<float>(q[d]);
    }
    a << "  endloop\n endfacet\n";
    b.write(reinterpret_cast<const char*>(values), sizeof values);
    const std::uint16_t attr = 0;
    b.write(reinterpret_cast<const char*>(&attr), 2);
  }
  a << "endsolid " << stem << "\n";
  return {obj, ply, ascii, binary};
}

}  // namespace

TEST_CASE("every closed data surface reads with its counts and topology", "[read_surface]") {
  // Euler characteristic 2 - 2g summed over components, as measured (anchor: genus 4 through its
  // holes, elephant: genus 3, rotor: a torus).
  const std::map<std::string, int> expected_chi = {{"anchor.off", -6},   {"elephant.off", -4},
                                                   {"fandisk.off", 2},   {"rotor.off", 0},
                                                   {"sphere966.off", 2}, {"spool.off", 2}};
  for (const auto& [file, chi] : expected_chi) {
    INFO(file);
    const std::string path = data3d + file;
    Surface s(read_surface(path));
    const auto [nv, nf] = off_header_counts(path);
    CHECK(s.n_vertices() == nv);
    CHECK(s.n_triangles() == nf);
    validate_surface(s, path);
    CHECK(s.n_triangles() == nf);
    CHECK(s.euler_characteristic() == chi);
    CHECK(s.volume() > 0.0);
    CHECK(is_consistently_oriented(s));
    CHECK(boundary_edges(s).empty());
    CHECK(s.n_edges() * 2 == s.n_triangles() * 3);
  }
}

TEST_CASE("the open cylinder is refused as not closed with its boundary-edge count", "[read_surface]") {
  const std::string path = data3d + "open-cylinder.off";
  Surface s(read_surface(path));
  const auto n_open = boundary_edges(s).size();
  CHECK(n_open > 0);
  const std::string msg = refusal(path);
  INFO(msg);
  CHECK(msg.find(path) == 0);
  CHECK(msg.find("surface is not closed: " + std::to_string(n_open) + " boundary edges") != std::string::npos);
}

TEST_CASE("an inverted sphere is accepted and turned outward", "[read_surface]") {
  Surface original(read_surface(data3d + "sphere966.off"));
  validate_surface(original, "sphere966.off");
  const double v0 = original.volume();
  const test::ScratchDir dir("read_surface");
  const fs::path flipped = dir.path() / "flipped-sphere.off";
  {
    std::ofstream out(flipped);
    out << "OFF\n" << original.n_vertices() << " " << original.n_triangles() << " 0\n";
    out.precision(17);
    for (const P3& p : original.vertices()) out << p.x() << " " << p.y() << " " << p.z() << "\n";
    for (const Triangle& t : original.triangles()) out << "3 " << t[0] << " " << t[2] << " " << t[1] << "\n";
  }
  Surface s(read_surface(flipped.string()));
  CHECK(s.volume() < 0.0);
  validate_surface(s, flipped.string());
  CHECK(s.volume() == Approx(v0).epsilon(1e-12));
  CHECK(is_consistently_oriented(s));
}

TEST_CASE("validate_surface returns the tree of the surface as oriented", "[read_surface]") {
  // The tree a fresh build of the oriented surface makes, corner for corner, whether the
  // surface came oriented (the tree of the self-intersection test, kept) or not (built again
  // after the flips); SurfaceBoundary takes it instead of building its own.
  Surface original(read_surface(data3d + "sphere966.off"));
  Surface inverted = original;
  std::vector<bool> all(static_cast<std::size_t>(inverted.n_triangles()), true);
  inverted.flip(all);
  for (Surface* s : {&original, &inverted}) {
    const AabbTree tree = validate_surface(*s, "sphere966.off");
    const AabbTree fresh(s->vertices(), s->triangles());
    REQUIRE(tree.n_triangles() == fresh.n_triangles());
    CHECK(tree.n_nodes() == fresh.n_nodes());
    std::size_t differ = 0;
    for (std::int32_t t = 0; t < s->n_triangles(); ++t) {
      const Triangle& tr = s->triangle(t);
      for (int k = 0; k < 3; ++k)
        differ += tree.points(t)[k] != fresh.points(t)[k] || tree.points(t)[k] != s->vertex(tr[k]) ? 1 : 0;
    }
    CHECK(differ == 0);
    CHECK(tree.bounds().lo == fresh.bounds().lo);
    CHECK(tree.bounds().hi == fresh.bounds().hi);
    const SurfaceBoundary b(*s, validate_surface(*s, "again"));
    const P3 probe = s->bounding_box().center() + P3(0.31, -0.17, 0.05);
    CHECK(b.closest_point(probe).point == SurfaceBoundary(*s).closest_point(probe).point);
  }
}

TEST_CASE("a sphere with a cavity: the inner shell is oriented inward", "[read_surface]") {
  Surface sphere(read_surface(data3d + "sphere966.off"));
  validate_surface(sphere, "sphere966.off");
  const P3 c = sphere.bounding_box().center();
  TriangleSoup soup{sphere.vertices(), sphere.triangles()};
  const int n = sphere.n_vertices();
  for (const P3& p : sphere.vertices()) soup.vertices.push_back(c + 0.5 * (p - c));
  for (const Triangle& t : sphere.triangles()) soup.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});  // same
  Surface s(std::move(soup));
  REQUIRE(s.n_components() == 2);
  validate_surface(s, "shell");
  CHECK(s.volume() == Approx(sphere.volume() * (1.0 - 0.125)).epsilon(1e-9));
  CHECK(s.component_volume(0) > 0.0);
  CHECK(s.component_volume(1) < 0.0);
}

TEST_CASE("bad inputs are refused with the file name and the reason", "[read_surface]") {
  const std::map<std::string, std::string> reason = {
      {"non-manifold.off", "non-manifold: 1 edge"},
      {"self-intersecting.off", "self-intersecting"},
      {"nan.off", "non-finite coordinate"},
      {"index-out-of-range.off", "vertex index 7 out of range"},
      {"empty.off", "empty file"},
      {"truncated.off", "truncated"},
      {"non-manifold.obj", "non-manifold"},
  };
  for (const auto& [file, why] : reason) {
    const std::string path = bad_dir + file;
    const std::string msg = refusal(path);
    INFO(file << ": " << msg);
    CHECK(msg.find(path) == 0);
    CHECK(msg.find(why) != std::string::npos);
  }
  CHECK(refusal(bad_dir + "truncated.off").find("truncated.off:8:") != std::string::npos);
  CHECK(refusal(bad_dir + "index-out-of-range.off").find(":9:") != std::string::npos);
}

TEST_CASE("STL (ASCII and binary), OBJ and PLY read through OpenMesh", "[read_surface]") {
  const test::ScratchDir dir("read_surface");
  const auto [obj, ply, ascii, binary] = write_cube(dir.path(), "cube", "float", [](int f, int k) { return cube_f[f][k]; });
  // A binary STL whose header begins with "solid", as some exporters write it.
  const fs::path solid_binary = dir.path() / "cube-binary-solid.stl";
  {
    std::ifstream in(binary, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    bytes.replace(0, 11, "solid cube ");
    std::ofstream(solid_binary, std::ios::binary) << bytes;
  }
  for (const fs::path& path : {obj, ply, ascii, binary, solid_binary}) {
    INFO(path);
    Surface s(read_surface(path.string()));
    CHECK(s.n_triangles() == 12);
    CHECK(s.n_used_vertices() == 8);
    validate_surface(s, path.string());
    CHECK(s.volume() == Approx(1.0));
    CHECK(s.euler_characteristic() == 2);
  }
  // Cut short, or too short for a header: said so (OpenMesh read both as empty, and the
  // message was "empty surface (no faces)").
  const fs::path cut = dir.path() / "cube-binary-cut.stl", stub = dir.path() / "stub.stl";
  {
    std::ifstream in(binary, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, 84 + 50 * 5 + 10);
    std::ofstream(stub, std::ios::binary) << bytes.substr(0, 50);
  }
  const auto refusal = [](const fs::path& path) {
    try {
      (void)read_surface(path.string());
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(refusal(cut), Catch::StartsWith(cut.string()) &&
                               Catch::Contains("truncated or malformed binary STL: its header declares 12 triangles (684 bytes), the file has 344 bytes"));
  CHECK_THAT(refusal(stub), Catch::Contains("not an STL: 50 bytes of binary data"));
}

TEST_CASE("STL, OBJ and PLY whose triangles are wound inconsistently are read whole and oriented", "[read_surface]") {
  // The cube with faces 1, 4, 7 and 10 wound the other way, as Gmsh's STL export of an
  // OpenCASCADE solid winds each face by its own parametrisation: closed and orientable. Read
  // into an OpenMesh mesh these faces were refused or their vertices split ("complex edge"),
  // and the surface was refused as not closed.
  const auto corner = [](int f, int k) {
    const bool flip = f % 3 == 1;
    return flip && k > 0 ? cube_f[f][3 - k] : cube_f[f][k];
  };
  const test::ScratchDir dir("read_surface");
  const auto [obj, ply, ascii, binary] = write_cube(dir.path(), "wound", "double", corner);
  for (const fs::path& path : {obj, ply, ascii, binary}) {
    INFO(path);
    Surface s(read_surface(path.string()));
    CHECK(s.n_triangles() == 12);
    CHECK(s.n_used_vertices() == 8);
    CHECK(boundary_edges(s).empty());
    CHECK_FALSE(is_consistently_oriented(s));
    validate_surface(s, path.string());
    CHECK(is_consistently_oriented(s));
    CHECK(s.volume() == Approx(1.0));
    CHECK(s.euler_characteristic() == 2);
  }
}

TEST_CASE("OBJ and PLY are read in double precision and their faults named with the line", "[read_surface]") {
  const auto refusal = [](const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
    try {
      Surface s(read_surface(path.string()));
      validate_surface(s, path.string());
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string obj_cube, ply_cube;
  for (const auto& v : cube_v) obj_cube += "v " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
  const auto obj_faces = [](int bad, const std::string& corner) {
    std::string out;
    for (int f = 0; f < 12; ++f)
      out += "f " + (f == bad ? corner : std::to_string(cube_f[f][0] + 1)) + " " + std::to_string(cube_f[f][1] + 1) + " " +
             std::to_string(cube_f[f][2] + 1) + "\n";
    return out;
  };
  const test::ScratchDir dir("read_surface");
  const fs::path obj = dir.path() / "faulty.obj", ply = dir.path() / "faulty.ply";
  // Lines 1-8 are the vertices, 9-20 the faces.
  CHECK_THAT(refusal(obj, obj_cube + obj_faces(5, "6")), Catch::StartsWith(obj.string() + ":14: face 5: vertex 6 appears twice"));
  CHECK_THAT(refusal(obj, obj_cube + obj_faces(2, "0")), Catch::Contains(":11: face 2: vertex index 0 (OBJ counts vertices from 1)"));
  CHECK_THAT(refusal(obj, obj_cube + obj_faces(3, "9")), Catch::Contains(":12: face 3: vertex index 9 out of range (the file has 8 vertices)"));
  CHECK_THAT(refusal(obj, obj_cube + obj_faces(0, "-9")), Catch::Contains(":9: face 0: vertex index -9 reaches before the first vertex"));
  CHECK_THAT(refusal(obj, obj_cube + "f 1 2\n"), Catch::Contains(":9: face 0: fewer than three corners"));
  CHECK_THAT(refusal(obj, "v 0 0 nan\n" + obj_faces(-1, "")), Catch::Contains(":1: non-finite coordinate in vertex 0"));
  CHECK_THAT(refusal(obj, "# nothing\n"), Catch::Contains("empty surface: 0 vertices, 0 faces"));
  // Negative indices count back from the last vertex; other statements are skipped.
  std::string relative = "o cube\nvt 0 0\n" + obj_cube + "vn 0 0 1\ns off\n";
  for (int f = 0; f < 12; ++f)
    relative += "f " + std::to_string(cube_f[f][0] - 8) + "/1/1 " + std::to_string(cube_f[f][1] - 8) + "//1 " +
                std::to_string(cube_f[f][2] + 1) + "/1\n";
  CHECK(refusal(obj, relative).empty());
  // Double precision (OpenMesh read 0.1000000000001 as 0.10000000149011612).
  {
    std::ofstream(obj) << "v 0.1000000000001 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    const TriangleSoup soup = read_surface(obj.string());
    CHECK(soup.vertices[0].x() == 0.1000000000001);
  }
  const std::string header = "ply\nformat ascii 1.0\ncomment a cube\nelement vertex 8\nproperty double x\nproperty double y\n"
                             "property double z\nproperty uchar red\nelement face 12\nproperty list uchar int vertex_indices\n"
                             "end_header\n";
  for (const auto& v : cube_v) ply_cube += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + " 255\n";
  std::string ply_faces;
  for (int f = 0; f < 12; ++f) ply_faces += "3 " + std::to_string(cube_f[f][0]) + " " + std::to_string(cube_f[f][1]) + " " + std::to_string(cube_f[f][2]) + "\n";
  CHECK(refusal(ply, header + ply_cube + ply_faces).empty());
  CHECK_THAT(refusal(ply, "ply\nformat ascii 1.0\nelement vertex 8\n"), Catch::Contains("truncated header: no end_header"));
  CHECK_THAT(refusal(ply, "ply\nformat ascii 1.0\nelement vertex 8\nend_hea\n"), Catch::Contains(":4: unknown header keyword 'end_hea'"));
  CHECK_THAT(refusal(ply, "solid x\n"), Catch::Contains(":1: not a PLY file"));
  CHECK_THAT(refusal(ply, header + ply_cube + "3 0 1 8" + ply_faces.substr(ply_faces.find('\n'))),
             Catch::Contains("face 0: vertex index 8 out of range"));
  CHECK_THAT(refusal(ply, header + ply_cube + ply_faces.substr(0, ply_faces.size() - 2)),
             Catch::Contains(":31: truncated: the file ends before face 11 (vertex_indices)"));
  std::string big = header;
  big.replace(big.find("element face 12"), 15, "element face 999999999");
  CHECK_THAT(refusal(ply, big + ply_cube + ply_faces), Catch::Contains(":9: element face declares 999999999 items, more than the file holds"));
  // Binary, big-endian, float coordinates and a short list count.
  {
    std::ofstream b(ply, std::ios::binary);
    b << "ply\nformat binary_big_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
    const auto put = [&](auto value) {
      char bytes[sizeof value];
      std::memcpy(bytes, &value, sizeof value);
      std::reverse(bytes, bytes + sizeof value);
      b.write(bytes, sizeof value);
    };
    for (const auto& v : cube_v)
      for (int d = 0; d < 3; ++d) put(static_cast<float>(v[d]));
    for (int f = 0; f < 12; ++f) {
      b.put(3);
      for (int k = 0; k < 3; ++k) put(static_cast<std::int32_t>(cube_f[f][k]));
    }
  }
  Surface s(read_surface(ply.string()));
  validate_surface(s, ply.string());
  CHECK(s.n_triangles() == 12);
  CHECK(s.volume() == Approx(1.0));
}

TEST_CASE("a Gmsh STL export wound face by face (examples/3d/block.stl) is read whole and oriented", "[read_surface]") {
  const std::string path = std::string(FEBEMESH_SOURCE_DIR) + "/examples/3d/block.stl";
  Surface s(read_surface(path));
  CHECK(s.n_triangles() == 4996);
  CHECK(s.n_used_vertices() == 2494);
  CHECK(boundary_edges(s).empty());
  CHECK(non_manifold_edges(s).empty());
  CHECK_FALSE(is_consistently_oriented(s));
  validate_surface(s, path);
  CHECK(is_consistently_oriented(s));
  // A block with a vertical bore meeting a cross bore (three openings into one junction, with
  // the bore's own two: genus 3) and a pocket and a dimple (no handles).
  CHECK(s.euler_characteristic() == -4);
  CHECK(s.volume() > 1.5);
  CHECK(s.volume() < 1.92);  // the 2 x 1.2 x 0.8 box less its cuts
}
