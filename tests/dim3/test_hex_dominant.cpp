// `--elements hex` (dim3/hex_dominant): on sphere966 at levels 3 and 4 and on a box, the
// hex-dominant mesh passes the validator (every corner Jacobian of hexes and pyramids positive,
// conforming, interface = boundary faces on the surface, Euler characteristic), its volume equals
// the volume the BE mesh encloses to round-off, it has hexes, and it is the same twice; the
// CLI writes a mesh.msh that reads back valid. The tet default is left as it was.

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/mesh_topology.hpp"
#include "core/quality.hpp"
#include "core/read_msh.hpp"
#include "core/validate.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface_checks.hpp"
#include "property.hpp"
#include "scratch_dir.hpp"
#include "surface_generators.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

/// An axis-parallel box with unequal sides (corners and feature edges), outward triangles.
SurfaceBoundary box_surface() {
  TriangleSoup soup;
  const P3 size(1.0, 0.7, 0.45);
  for (int k = 0; k < 8; ++k) soup.vertices.push_back(P3(k & 1, (k >> 1) & 1, (k >> 2) & 1).cwiseProduct(size));
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    soup.triangles.push_back({f[0], f[1], f[2]});
    soup.triangles.push_back({f[0], f[2], f[3]});
  }
  return SurfaceBoundary(Surface(soup));
}

struct TypeCounts {
  std::size_t hex = 0, pyramid = 0, tet = 0, other = 0, quads = 0, triangles = 0;
};

TypeCounts count_types(const Mesh<3>& m) {
  TypeCounts c;
  for (ElemType t : m.solid.type) {
    if (t == ElemType::Hex8) ++c.hex;
    else if (t == ElemType::Pyramid5) ++c.pyramid;
    else if (t == ElemType::Tet4) ++c.tet;
    else ++c.other;
  }
  for (ElemType t : m.interface.type) (t == ElemType::Quad4 ? c.quads : c.triangles)++;
  return c;
}

/// The tet run at `level` without edge removal (its rounds differ between the kinds: 30 deg for
/// tets, 15 for the merge, then 30 at the tetrahedra left under 15, and the optimiser's passes
/// after them move surface nodes differently), and the hex run with the same options.
std::pair<Result3d, Result3d> tet_and_hex_runs(SurfaceBoundary& s, int level) {
  Options3d opt;
  opt.level = level;
  opt.remove_edges_below_deg = 0.0;
  Result3d tet = mesh3d(s, opt);
  opt.hex_dominant = true;
  return {std::move(tet), mesh3d(s, opt)};
}

/// The two runs kept meshes made the same way (the retries and draws that decide which mesh
/// stands), so the hex run merged the tet run's tetrahedra.
bool same_path(const Result3d& a, const Result3d& b) {
  return a.thickness_refined == b.thickness_refined && a.level_raised == b.level_raised &&
         a.lattice_draw == b.lattice_draw && a.flat_retry == b.flat_retry && a.frame_refused == b.frame_refused;
}

ValidationReport validate_on(const Mesh<3>& m, const SurfaceBoundary& s) {
  ValidateOptions<3> vo;
  vo.expected_euler = s.euler_characteristic() / 2;
  vo.boundary_distance = [&](const Point<3>& p) { return s.closest_point(p).distance; };
  vo.boundary_tolerance = 1e-10 * s.bounding_box().extent().norm();
  return validate(m, vo);
}

/// Everything the contract asks of one hex-dominant mesh; returns the hex share.
double check_hex_dominant(SurfaceBoundary& s, int level) {
  Options3d opt;
  opt.level = level;
  opt.hex_dominant = true;
  const Result3d r = mesh3d(s, opt);
  const Mesh<3>& m = r.fe.mesh;
  const TypeCounts c = count_types(m);
  INFO("level " << level << ": " << c.hex << " hexes, " << c.pyramid << " pyramids, " << c.tet << " tets, "
                << c.quads << " interface quads, " << c.triangles << " interface triangles");
  REQUIRE(m.solid.size() > 0);
  CHECK(c.other == 0);
  CHECK(c.hex == r.hex.n_hex);
  CHECK(c.pyramid == r.hex.n_pyramid);
  CHECK(c.tet == r.hex.n_tet);
  CHECK(c.quads == r.hex.n_interface_quads);
  CHECK(c.triangles == r.hex.n_interface_triangles);

  const ValidationReport v = validate_on(m, s);
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(v.inverted == 0);
  CHECK(v.nonconforming_facets == 0);
  CHECK(v.hanging_nodes == 0);
  CHECK(v.interface_mismatch == 0);
  CHECK(v.unused_nodes == 0);

  // Every corner of every element, not only the validator's summary.
  double min_sj = 1.0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const auto p = element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, m.points);
    REQUIRE(min_corner_jacobian<3>(m.solid.type[e], p.span()) > 0.0);
    const double sj = scaled_jacobian<3>(m.solid.type[e], p.span());
    if (m.solid.type[e] == ElemType::Hex8) CHECK(sj >= opt.hex.min_hex_scaled_jacobian);
    min_sj = std::min(min_sj, sj);
  }
  CHECK(min_sj > 0.0);

  // Shared quads count once per side with the same two diagonals: what the elements fill is
  // what the BE mesh encloses, to round-off.
  const double fe = solid_measure<3>(m), be = interface_enclosed_measure<3>(m);
  CHECK(std::abs(fe - be) <= 1e-11 * std::abs(be));
  CHECK(std::abs(r.hex.total_volume - fe) <= 1e-11 * std::abs(fe));
  CHECK(r.hex.n_hex > 0);
  WARN("level " << level << ": hex share " << r.hex.hex_share() << " by count, " << r.hex.hex_volume_share()
                << " by volume; min scaled Jacobian " << min_sj);
  return r.hex.hex_share();
}

}  // namespace

TEST_CASE("hex-dominant sphere966 at levels 3 and 4 is valid and mostly hexes", "[hex_dominant]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  // Measured: 232 of 232 at level 3, 2142 of 2156 at level 4.
  CHECK(check_hex_dominant(s, 3) > 0.9);
  CHECK(check_hex_dominant(s, 4) > 0.9);
}

TEST_CASE("hex-dominant box is valid, with corners and feature edges", "[hex_dominant]") {
  SurfaceBoundary s = box_surface();
  CHECK(check_hex_dominant(s, 3) > 0.0);
  CHECK(check_hex_dominant(s, 4) > 0.0);
}

TEST_CASE("hex-dominant meshes are the same twice", "[hex_dominant]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  Options3d opt;
  opt.level = 3;
  opt.hex_dominant = true;
  const Result3d a = mesh3d(s, opt), b = mesh3d(s, opt);
  const Mesh<3>& ma = a.fe.mesh;
  const Mesh<3>& mb = b.fe.mesh;
  REQUIRE(ma.points.size() == mb.points.size());
  for (std::size_t v = 0; v < ma.points.size(); ++v) REQUIRE(ma.points[v] == mb.points[v]);
  CHECK(ma.solid.type == mb.solid.type);
  CHECK(ma.solid.offset == mb.solid.offset);
  CHECK(ma.solid.node == mb.solid.node);
  CHECK(ma.interface.type == mb.interface.type);
  CHECK(ma.interface.node == mb.interface.node);
}

TEST_CASE("the tet default makes no hexes; the hex mode keeps the tet mesh's surface nodes", "[hex_dominant]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  const auto [tet, hex] = tet_and_hex_runs(s, 3);
  const TypeCounts c = count_types(tet.fe.mesh);
  CHECK(c.tet == tet.fe.mesh.solid.size());
  CHECK(c.triangles == tet.fe.mesh.interface.size());
  CHECK(tet.hex.n_elements() == 0);
  // Same construction underneath: the hexes and pyramids are unions of the tets' cones, so the
  // BE nodes are the same points (the volumes differ where a surface quad is not planar).
  const auto interface_points = [](const Mesh<3>& m) {
    std::vector<std::array<double, 3>> out;
    for (VertexId v : m.interface.node) out.push_back({m.points[v.v][0], m.points[v.v][1], m.points[v.v][2]});
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  CHECK(interface_points(hex.fe.mesh) == interface_points(tet.fe.mesh));
}

// Merging two cones into a pyramid over a warped quad (a boundary octant's side) measures the
// dihedral angles at the quad's edges against its mean normal: rotor level 3 went from 17.74 deg
// (tets) to 8.55 (hex-dominant) before HexDominantOptions::min_dihedral_deg; with it 15.07.
TEST_CASE("hex-dominant merges keep the smallest dihedral angle of the tets (rotor level 3)", "[hex_dominant][data]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/rotor.off");
  Options3d opt;
  opt.level = 3;
  opt.remove_edges_below_deg = 0.0;  // the tetrahedra the merges start from
  opt.lattice_draws = 0;             // one lattice for the three runs (their angles differ)
  const double tet = summarize_quality<3>(mesh3d(s, opt).fe.mesh).min_angle_deg;
  opt.hex_dominant = true;
  const Result3d r = mesh3d(s, opt);
  const double hex = summarize_quality<3>(r.fe.mesh).min_angle_deg;
  INFO("tets " << tet << " deg, hex-dominant " << hex << " deg");
  CHECK(validate_on(r.fe.mesh, s).valid);
  CHECK(r.hex.n_hex > 0);
  CHECK(hex >= std::min(opt.hex.min_dihedral_deg, tet) - 1e-9);
  // Without the rule the same merges go below it: the test sees the rule at work.
  opt.hex.min_dihedral_deg = 0.0;
  CHECK(summarize_quality<3>(mesh3d(s, opt).fe.mesh).min_angle_deg < std::min(15.0, tet) - 1.0);
}

// Edge removal (dim3/edge_removal.hpp) in a hex-dominant run: the cells whose tetrahedra it
// replaced are not template cones any more, so make_hex_dominant keeps them tetrahedra and
// splits the quads they share. Measured (spool level 3): min dihedral 13.55 deg without it,
// 15.00 with it (4 edges removed), 3144 -> 3128 hexes; since the sliding passes free the snapped
// nodes now on a face (session 20) spool level 3 needs no removal, fandisk level 3 removes 2
// edges (CLI, 15.06 deg).
// A small input with many removals (268 edges removed, 73 contracted at level 3; 0.6 s in a
// release build, where fandisk level 3, with 2, took 20 s).
TEST_CASE("hex-dominant: cells changed by edge removal stay tetrahedra (thin torus level 3)", "[hex_dominant]") {
  SurfaceBoundary s =
      SurfaceBoundary::from_file(std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/torus-thin-ring-euler.off");
  Options3d opt;
  opt.level = 3;
  opt.buffer_last = false;  // the mesh of the buffer rule's try, which the counts above are of
  opt.lattice_draws = 0;    // one lattice for both runs
  opt.hex_dominant = true;
  opt.remove_edges_below_deg = 0.0;
  const Result3d without = mesh3d(s, opt);
  opt.remove_edges_below_deg = Options3d{}.remove_edges_below_deg;
  const Result3d r = mesh3d(s, opt);
  REQUIRE(r.n_edges_removed > 0);
  REQUIRE(!r.fe.cells_changed.empty());
  CHECK(std::is_sorted(r.fe.cells_changed.begin(), r.fe.cells_changed.end()));
  const Mesh<3>& m = r.fe.mesh;
  REQUIRE(r.fe.cell.size() == m.solid.size());
  std::size_t in_changed = 0;
  for (std::size_t e = 0; e < m.solid.size(); ++e)
    if (std::binary_search(r.fe.cells_changed.begin(), r.fe.cells_changed.end(), r.fe.cell[e])) {
      CHECK(m.solid.type[e] == ElemType::Tet4);
      ++in_changed;
    }
  CHECK(in_changed >= r.fe.cells_changed.size());
  const ValidationReport v = validate_on(m, s);
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(r.hex.n_hex > 0);
  const double before = summarize_quality<3>(without.fe.mesh).min_angle_deg;
  const double after = summarize_quality<3>(m).min_angle_deg;
  INFO("min dihedral " << before << " -> " << after << " deg; hexes " << without.hex.n_hex << " -> " << r.hex.n_hex);
  CHECK(after > before);
}

// The hex run ranks its own mesh: a hex-dominant mesh's volume is not its tetrahedra's (warped
// quads), so where the tet mesh loses a little under Options3d::draw_max_volume_error the hex
// mesh can lose more than it and take a lattice draw the tet run does not (the property below
// found this torus, seed 1073: 10.83% lost on the first lattice, 6.05% on draw 1). The merges'
// angle bound holds against the tetrahedra merged, those of the draw.
TEST_CASE("hex-dominant: a hex mesh losing more volume than its tets takes its own lattice draw", "[hex_dominant]") {
  SurfaceBoundary s =
      SurfaceBoundary::from_file(std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/torus-seed1073-hex-draw.off");
  const auto [tet, r] = tet_and_hex_runs(s, 3);
  CHECK(tet.lattice_draw == 0);
  CHECK(r.lattice_draw == 1);
  CHECK(!same_path(r, tet));
  const ValidationReport v = validate_on(r.fe.mesh, s);
  INFO(v.summary());
  CHECK(v.valid);
  const double hex_min = summarize_quality<3>(r.fe.mesh).min_angle_deg;
  CHECK(hex_min >= std::min(Options3d{}.hex.min_dihedral_deg, r.hex.tets_min_dihedral_deg) - 1e-9);
  CHECK(r.hex.tets_min_dihedral_deg < summarize_quality<3>(tet.fe.mesh).min_angle_deg);
}

TEST_CASE("mesh3d --elements hex writes a valid mesh.msh with hexes", "[hex_dominant][cli]") {
  const test::ScratchDir scratch("test_hex_dominant");
  const std::filesystem::path out = scratch.path() / "out";
  const std::string input = std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off";
  const std::string cmd =
      std::string(FEBEMESH_CLI) + " mesh3d " + input + " --level 3 --elements hex --quiet -o " + out.string();
  const int status = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
  const Mesh<3> m = read_msh<3>(out / "mesh.msh");
  SurfaceBoundary s = SurfaceBoundary::from_file(input);
  const ValidationReport v = validate_on(m, s);
  INFO(v.summary());
  CHECK(v.valid);
  const TypeCounts c = count_types(m);
  CHECK(c.hex > 0);
  CHECK(c.quads > 0);
  std::ifstream is(out / "report.json");
  const nlohmann::json rep = nlohmann::json::parse(is);
  CHECK(rep["options"]["elements"] == "hex");
  CHECK(rep["hex_dominant"]["hexahedra"].get<std::size_t>() == c.hex);
  CHECK(rep["hex_dominant"]["hex_share"].get<double>() > 0.0);
  CHECK(rep["validation"]["valid"].get<bool>());
}

// What the hex-dominant mesh relies on the validator for: a quad face against a pyramid's base
// conforms; the same quad against two triangles (a hex beside two tets) does not; a hex with one
// corner folded in is inverted although its volume is positive.
namespace {

/// A unit cube hex and, on its x = 1 face, a pyramid (apex at x = 1.5) or the pyramid's two
/// tets; the interface is the solid's boundary facets.
Mesh<3> hex_and_cap(bool split_cap) {
  Mesh<3> m;
  for (int k = 0; k < 8; ++k) m.add_point(P3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  const VertexId apex = m.add_point(P3(1.5, 0.5, 0.5));
  const auto v = [](int i) { return VertexId{i}; };
  m.solid.add(ElemType::Hex8, {v(0), v(1), v(3), v(2), v(4), v(5), v(7), v(6)});
  // x-high face 1 3 7 5 is counter-clockwise seen from outside the hex, that is from the apex:
  // the pyramid's base in Gmsh order.
  if (split_cap) {
    m.solid.add(ElemType::Tet4, {v(1), v(7), v(5), apex});
    m.solid.add(ElemType::Tet4, {v(1), v(3), v(7), apex});
  } else {
    m.solid.add(ElemType::Pyramid5, {v(1), v(3), v(7), v(5), apex});
  }
  for (const BoundaryFacet& b : boundary_facets(m.solid))
    m.interface.add(b.facet.type, b.facet.node.data(), b.facet.n);
  return m;
}

}  // namespace

TEST_CASE("the validator: quad against pyramid base conforms, against two triangles does not", "[hex_dominant]") {
  const Mesh<3> good = hex_and_cap(false);
  for (std::size_t e = 0; e < good.solid.size(); ++e) {
    const auto p = element_points<3>(good.solid, ElemId{static_cast<std::int32_t>(e)}, good.points);
    REQUIRE(min_corner_jacobian<3>(good.solid.type[e], p.span()) > 0.0);
  }
  const ValidationReport v = validate(good);
  INFO(v.summary());
  CHECK(v.valid);

  const Mesh<3> bad = hex_and_cap(true);
  const ValidationReport w = validate(bad);
  CHECK_FALSE(w.valid);
  CHECK(w.nonconforming_facets >= 1);

  Mesh<3> folded = hex_and_cap(false);
  folded.points[6] = P3(0.3, 0.3, 0.3);  // corner (0, 1, 1) pulled inside: that corner inverts
  const auto p = element_points<3>(folded.solid, ElemId{0}, folded.points);
  CHECK(signed_measure<3>(ElemType::Hex8, p.span()) > 0.0);
  CHECK(validate(folded).inverted >= 1);
}

// The same contract on random perturbed icospheres (320 triangles, the shapes the tet pipeline is
// asserted valid on, surface_generators.hpp) at level 3.
TEST_CASE("hex-dominant meshes of perturbed spheres are valid", "[hex_dominant][property]") {
  test::prop("perturbed spheres (320 triangles), --elements hex", 6, [] {
    const test::SurfaceSpec spec = *test::gen_sphere_spec(2);
    RC_LOG() << test::describe(spec) << "\n";
    Surface surface = test::to_surface(spec);
    validate_surface(surface, "generated");
    SurfaceBoundary s(std::move(surface));
    Options3d opt;
    opt.level = spec.level;
    opt.hex_dominant = true;
    const Result3d r = mesh3d(s, opt);
    const Mesh<3>& m = r.fe.mesh;
    const ValidationReport v = validate_on(m, s);
    RC_LOG() << v.summary() << "\n";
    RC_ASSERT(v.valid);
    for (std::size_t e = 0; e < m.solid.size(); ++e) {
      const auto p = element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, m.points);
      RC_ASSERT(min_corner_jacobian<3>(m.solid.type[e], p.span()) > 0.0);
    }
    const double fe = solid_measure<3>(m), be = interface_enclosed_measure<3>(m);
    RC_ASSERT(std::abs(fe - be) <= 1e-10 * std::abs(be));
    RC_ASSERT(r.hex.n_hex + r.hex.n_pyramid + r.hex.n_tet == m.solid.size());
  });
}

// Tori and voxel unions: the tet pipeline does not always manage them (test_pipeline3d_properties
// runs them [!mayfail]); what hex_dominant owes is a valid mesh whenever the tet mesh is valid.
TEST_CASE("hex-dominant meshes of tori and voxel unions are valid when the tet mesh is", "[hex_dominant][property]") {
  const auto when_tets_valid = [](const rc::Gen<test::SurfaceSpec>& gen) {
    return [gen] {
      const test::SurfaceSpec spec = *gen;
      RC_LOG() << test::describe(spec) << "\n";
      Surface surface = test::to_surface(spec);
      validate_surface(surface, "generated");
      SurfaceBoundary s(std::move(surface));
      Options3d opt;
      opt.level = spec.level;
      // The tetrahedra hex_dominant merges: without edge removal, which it does not take.
      opt.remove_edges_below_deg = 0.0;
      Result3d tet;
      try {
        tet = mesh3d(s, opt);
      } catch (const GeometryError&) {
        RC_DISCARD("the tet pipeline refused");
      } catch (const LimitError&) {
        RC_DISCARD("the tet pipeline refused");
      }
      RC_PRE(validate_on(tet.fe.mesh, s).valid);
      opt.hex_dominant = true;
      const Result3d r = mesh3d(s, opt);
      const ValidationReport v = validate_on(r.fe.mesh, s);
      RC_LOG() << v.summary() << "\n";
      RC_ASSERT(v.valid);
      const double fe = solid_measure<3>(r.fe.mesh), be = interface_enclosed_measure<3>(r.fe.mesh);
      RC_ASSERT(std::abs(fe - be) <= 1e-10 * std::abs(be));
      // The merges keep the smallest dihedral angle of the tets they start from, up to
      // HexDominantOptions::min_dihedral_deg. Those are the tet run's only when both runs took
      // the same path: the thickness retry stands when it loses less volume, and a hex mesh's
      // volume is not its tets' (warped quads), so the runs can keep different meshes
      // (shrunk voxel union, session 17: first meshes 7.45% / 6.99%, retries 7.46% / 6.81%:
      // the hex run kept its first mesh, the tet run its retry; 13.68 deg against 26.91), and
      // the lattice draws follow the volume lost past Options3d::draw_max_volume_error (a
      // torus, seed 1073: the hex mesh lost 10.83%, the tets under 10%, so the hex run stood
      // on draw 1, whose tetrahedra reach 13.38 deg, the tet run on its first lattice at 16.23;
      // regressions/torus-seed1073-hex-draw.off above).
      const double tet_min = summarize_quality<3>(tet.fe.mesh).min_angle_deg;
      const double hex_min = summarize_quality<3>(r.fe.mesh).min_angle_deg;
      RC_ASSERT(hex_min >= std::min(opt.hex.min_dihedral_deg, r.hex.tets_min_dihedral_deg) - 1e-9);
      if (same_path(r, tet)) RC_ASSERT(hex_min >= std::min(opt.hex.min_dihedral_deg, tet_min) - 1e-9);
    };
  };
  test::prop("tori, --elements hex", 4, when_tets_valid(test::gen_torus_spec()));
  test::prop("voxel unions, --elements hex", 4, when_tets_valid(test::gen_voxel_spec()));
}
