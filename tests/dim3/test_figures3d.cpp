// The 3D figures (dim3/figures3d.hpp): the polygons a plane cuts from the solid elements tile
// the mesh's section exactly, as Green's theorem over the interface's cut gives it, for
// tetrahedral and hex-dominant meshes; elements the plane only touches give no polygon; the
// files are written, and left out over the shape limit with a note saying so.

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "dim3/figures3d.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface_checks.hpp"
#include "scratch_dir.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

using P2 = Point<2>;

double signed_area(const std::vector<P2>& pts) {
  double a = 0.0;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const P2 &p = pts[k], &q = pts[(k + 1) % pts.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

/// The box [0, 1] x [0, 0.8] x [0, 0.6] as 12 triangles, outward.
TriangleSoup box_soup() {
  TriangleSoup soup;
  for (int k = 0; k < 8; ++k) soup.vertices.push_back(P3(k & 1 ? 1.0 : 0.0, k & 2 ? 0.8 : 0.0, k & 4 ? 0.6 : 0.0));
  // Each face's corners counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    soup.triangles.push_back({f[0], f[1], f[2]});
    soup.triangles.push_back({f[0], f[2], f[3]});
  }
  return soup;
}

/// The area inside the interface's cut by the plane x[axis] = at, by Green's theorem: each
/// interface face the plane crosses gives a segment, turned so that the face's outward normal
/// lies on its right (the section's boundary counter-clockwise), and the segments' shoelace
/// terms add up to the area. Independent of section_polygons (no solid element is read).
double green_area(const Mesh<3>& m, int axis, double at) {
  double twice = 0.0;
  for (std::size_t f = 0; f < m.interface.size(); ++f) {
    const ElemId id{static_cast<std::int32_t>(f)};
    const VertexId* v = m.interface.nodes(id);
    const int n = m.interface.n_nodes_of(id);
    P3 normal = P3::Zero();
    std::vector<P2> cut;
    double centre = 0.0;
    for (int k = 0; k < n; ++k) {
      const P3 &a = m.points[v[k].v], &b = m.points[v[(k + 1) % n].v];
      normal += a.cross(b);
      const double da = a[axis] - at, db = b[axis] - at;
      centre += da;
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) cut.push_back(section_coordinates(a + (da / (da - db)) * (b - a), axis));
      REQUIRE(da != 0);  // the planes of the test miss every node
    }
    if (cut.empty()) continue;
    std::vector<std::array<P2, 2>> segs;
    if (cut.size() == 2) {
      segs.push_back({cut[0], cut[1]});
    } else {
      // A quad whose corners alternate sides: its bilinear surface cuts off the two corners on
      // the other side from its centre.
      REQUIRE(cut.size() == 4);
      const bool first_with_centre = (centre < 0) == (m.points[v[0].v][axis] - at < 0);
      segs.push_back(first_with_centre ? std::array<P2, 2>{cut[0], cut[1]} : std::array<P2, 2>{cut[3], cut[0]});
      segs.push_back(first_with_centre ? std::array<P2, 2>{cut[2], cut[3]} : std::array<P2, 2>{cut[1], cut[2]});
    }
    const P2 nu = section_coordinates(normal, axis);
    for (std::array<P2, 2>& sg : segs) {
      const P2 d = sg[1] - sg[0];
      if (d.y() * nu.x() - d.x() * nu.y() < 0) std::swap(sg[0], sg[1]);
      twice += sg[0].x() * sg[1].y() - sg[1].x() * sg[0].y();
    }
  }
  return 0.5 * twice;
}

Result3d mesh_box(bool hex) {
  Surface surface(box_soup());
  validate_surface(surface, "box");
  SurfaceBoundary s(std::move(surface));
  Options3d opt;
  opt.level = 3;
  opt.n_threads = 1;
  opt.hex_dominant = hex;
  return mesh3d(s, opt);
}

}  // namespace

TEST_CASE("section_polygons of one tetrahedron: the cut triangle, nothing where the plane only touches",
          "[figures3d]") {
  Mesh<3> m;
  for (const P3& p : {P3(0, 0, 0), P3(1, 0, 0), P3(0, 1, 0), P3(0, 0, 1)}) m.add_point(p);
  m.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}});
  const auto cut = section_polygons(m, 2, 0.5);
  REQUIRE(cut.size() == 1);
  CHECK(cut[0].element == 0);
  REQUIRE(cut[0].pts.size() == 3);
  CHECK(signed_area(cut[0].pts) == Approx(0.125).epsilon(1e-12));  // counter-clockwise
  for (const P2& p : cut[0].pts) CHECK((p.x() == Approx(0.0).margin(1e-15) || p.y() == Approx(0.0).margin(1e-15) ||
                                        p.x() + p.y() == Approx(0.5)));
  // A plane through a face, an edge or a node only.
  CHECK(section_polygons(m, 2, 0.0).empty());
  CHECK(section_polygons(m, 2, 1.0).empty());
  CHECK(section_polygons(m, 0, 1.0).empty());
  CHECK(section_polygons(m, 2, 1.5).empty());
  // Through a node and the opposite face's inside: a triangle with that node as a corner.
  const auto through = section_polygons(m, 0, 0.25);
  REQUIRE(through.size() == 1);
  CHECK(signed_area(through[0].pts) == Approx(0.5 * 0.75 * 0.75));
}

TEST_CASE("section_polygons: a thin saddle-shaped hexahedron's cut falls apart in two polygons", "[figures3d]") {
  // Bottom corners at z 0, 0.2, 0, 0.2 (a saddle), the top 0.02 above: the plane z = 0.09 runs
  // through the low corners' corners of both faces, which its bilinear faces cut off.
  Mesh<3> m;
  const double zb[4] = {0.0, 0.2, 0.0, 0.2};
  const double xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const double lift : {0.0, 0.02})
    for (int k = 0; k < 4; ++k) m.add_point(P3(xy[k][0], xy[k][1], zb[k] + lift));
  m.solid.add(ElemType::Hex8, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}, VertexId{4}, VertexId{5}, VertexId{6},
                               VertexId{7}});
  const auto cut = section_polygons(m, 2, 0.09);
  REQUIRE(cut.size() == 2);
  for (const SectionPolygon& p : cut) {
    CHECK(p.element == 0);
    CHECK(p.pts.size() == 4);
    CHECK(signed_area(p.pts) > 0);
  }
  // One around the corner (0, 0), one around (1, 1), in either order.
  const auto mean = [](const std::vector<P2>& pts) {
    P2 c = P2::Zero();
    for (const P2& p : pts) c += p;
    return P2(c / static_cast<double>(pts.size()));
  };
  const P2 a = mean(cut[0].pts), b = mean(cut[1].pts);
  const bool first_low = a.norm() < b.norm();
  CHECK(((first_low ? a : b) - P2(0, 0)).norm() < 0.5);
  CHECK(((first_low ? b : a) - P2(1, 1)).norm() < 0.5);
}

TEST_CASE("section_polygons tile the section of a meshed box, tetrahedral and hex-dominant", "[figures3d]") {
  for (const bool hex : {false, true}) {
    const Result3d r = mesh_box(hex);
    const Mesh<3>& m = r.fe.mesh;
    INFO((hex ? "hex-dominant, " : "tetrahedral, ") << m.solid.size() << " elements");
    const double box_section[3] = {0.8 * 0.6, 0.6 * 1.0, 1.0 * 0.8};
    for (int axis = 0; axis < 3; ++axis) {
      for (const double share : {0.137, 0.5123, 0.871}) {
        const double at = share * (axis == 0 ? 1.0 : axis == 1 ? 0.8 : 0.6);
        const auto polys = section_polygons(m, axis, at);
        REQUIRE(!polys.empty());
        double sum = 0.0;
        for (const SectionPolygon& p : polys) {
          const double a = signed_area(p.pts);
          CHECK(a > 0);
          sum += a;
        }
        const double green = green_area(m, axis, at);
        INFO("axis " << axis << " at " << at << ": " << polys.size() << " polygons, " << sum << " against " << green);
        // Tiled without gaps or overlaps: the two sums agree to rounding.
        CHECK(std::abs(sum - green) <= 1e-9 * box_section[axis]);
        // And the mesh's section is the box's, within the mesh's volume error.
        CHECK(sum == Approx(box_section[axis]).epsilon(0.02));
      }
    }
  }
}

TEST_CASE("section_segments: the cut of the surface, one segment a crossed triangle", "[figures3d]") {
  const Surface s(box_soup());
  const auto segs = section_segments(s, 2, 0.3);
  double length = 0.0;
  for (const auto& sg : segs) length += (sg[1] - sg[0]).norm();
  CHECK(segs.size() == 8);  // two triangles a side face
  CHECK(length == Approx(2 * (1.0 + 0.8)));
  CHECK(section_segments(s, 2, 0.7).empty());
}

TEST_CASE("write_mesh_figures writes the sections and the BE view, and says what it left out", "[figures3d]") {
  const Result3d r = mesh_box(false);
  const Surface s(box_soup());
  const test::ScratchDir scratch("figures3d");
  const auto dir = scratch.path() / "figures";
  const MeshFigures all = write_mesh_figures(r.fe.mesh, s, dir, 0);
  CHECK(all.written.size() == 4);
  CHECK(all.skipped.empty());
  for (const char* name : {"section-x.svg", "section-y.svg", "section-z.svg", "interface.svg"}) {
    std::ifstream in(dir / name);
    std::stringstream text;
    text << in.rdbuf();
    CHECK(text.str().find("<svg") != std::string::npos);
    CHECK(text.str().find("<polygon") != std::string::npos);
  }
  CHECK(!std::filesystem::exists(dir / "README.txt"));
  std::filesystem::remove_all(dir);
  const MeshFigures few = write_mesh_figures(r.fe.mesh, s, dir, 5);
  CHECK(few.written.empty());
  REQUIRE(few.skipped.size() == 4);
  CHECK(few.skipped[0].find("section-x.svg: ") == 0);
  CHECK(few.skipped[3].find("interface.svg: ") == 0);
  std::ifstream note(dir / "README.txt");
  std::stringstream text;
  text << note.rdbuf();
  CHECK(text.str().find("over the limit of 5") != std::string::npos);
  CHECK(!std::filesystem::exists(dir / "section-x.svg"));
}
