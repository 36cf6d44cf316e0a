// Experiment: why do the boundary octants of a 3D tree fold? (issue 6, `diagnose3d`)
//
// The pipeline's first tree for a surface at a level (subdivision, 2:1 balance, interior
// octants with the buffer, pinch and island rules), its boundary octants by projection and the
// raw tetrahedra from the templates, before any untangling. For every inverted tetrahedron of a
// boundary octant we look at the octant's face nodes and their projections and sort the octant
// by the first thing wrong with it:
//   backward  - a node's projection runs against the octant's face normal (cos < 0): the node's
//               closest point was chosen for another of its free faces;
//   away      - a projection lands on surface facing away from the face (normal cos < 0): the
//               far sheet of a part thinner than the octant, or a lip;
//   long      - a projection longer than 1.5 face sizes;
//   other     - all projections go out and land facing the face: shear between neighbours.
// Usage: diagnose3d SURFACE LEVEL [THICKNESS_CELLS] [options]  (--help lists them)
// --pipeline runs the whole pipeline instead; with --quality it sorts the final mesh's tetrahedra
// under 10 degrees (--below DEG) by where they come from (print_quality_diagnosis), and with
// --dump N prints the N worst with their edges and their nodes' stars.
// THICKNESS_CELLS sets Options3d::thickness_cells (the thickness level from the first tree, no
// retry), capped at LEVEL + --thickness-extra N (default 2); --snap snaps to features here too.
// --opposing drops the interior octants at nodes with opposing free faces (remove_opposing,
// Options3d::drop_opposing; here and with --pipeline; FEBEMESH_DUMP_OPPOSING=1 with --dump N
// lists the first N such nodes of the first tree and their free faces).
// --unfold turns on BoundaryOctantOptions::unfold_backward (here and with --pipeline). The
// counts also give the face nodes with free faces on both sides of an axis (no single
// projection leaves through both) and the folded octants with such a node.
// --single (with --pipeline): one try, without the fallbacks (no buffer, no feature snapping,
// facing projections, level raise, thickness retry); --nosnap: no feature snapping there;
// --feature-extra L: SurfaceOptions::feature_extra_levels (default 1), the level field's
// feature level above the global one; --near X Y Z R with --dump: only octants near a point.
// --root-shift X Y Z: SurfaceOptions::root_shift (the lattice moved against the surface).
// --graze-region: BoundaryOctantOptions::graze_region (and Options3d's, for the untangling):
// the graze allowance only at the interior region's boundary; --graze-length L its graze_length.
// --sampled: SurfaceOptions::thickness_sampled (the thickness level from a grid of rays per
// triangle). Environment, first tree: FEBEMESH_DUMP_CELLS=1 with --near lists the leaves there
// (level, side, kept, dropped as a pinch or an island); FEBEMESH_DUMP_DROPPED=1 lists every leaf
// the pinch and island rules dropped; FEBEMESH_PROBE="X Y Z" prints a point's local minima of
// the distance and whether the segments to them enter kept octants or cross the surface.
// FEBEMESH_FOLD_STATS=1 (rotor.off only: its axis is x) tallies the boundary octants, folded and
// not, by region (plate, wall, blades), by whether their nodes' projections land on opposite
// sheets ("split") and by how the face meets the surface; in the wall also by the local thickness
// in octants; FEBEMESH_FOLD_WHERE=1 lists the folded wall octants. --flat-buffer B, --max-level L
// and --worse-repairs N set Options3d::flat_buffer, max_level and worse_repairs.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <vector>
#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>

#include "core/cube_faces.hpp"
#include "core/local_repair.hpp"
#include "core/orthtree.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim3/fidelity3d.hpp"
#include <chrono>
#include "dim3/boundary_octants.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface_boundary.hpp"
#include "dim3/templates3d.hpp"
#include "dim3/tet_optimize.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

/// The six dihedral angles (degrees) of a tetrahedron, at edges 01 02 03 12 13 23.
std::array<double, 6> tet_dihedral_angles_deg(const P3& a, const P3& b, const P3& c, const P3& d) {
  const P3 p[4] = {a, b, c, d};
  static const int edge_nodes[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  std::array<double, 6> out{};
  for (int k = 0; k < 6; ++k) {
    const int i = edge_nodes[k][0], j = edge_nodes[k][1];
    int o[2], n = 0;
    for (int l = 0; l < 4; ++l)
      if (l != i && l != j) o[n++] = l;
    const P3 e = (p[j] - p[i]).normalized();
    P3 u = p[o[0]] - p[i], w = p[o[1]] - p[i];
    u -= u.dot(e) * e;
    w -= w.dot(e) * e;
    const double nn = u.norm() * w.norm();
    out[k] = nn > 0 ? std::acos(std::clamp(u.dot(w) / nn, -1.0, 1.0)) * 180.0 / 3.14159265358979 : 0.0;
  }
  return out;
}


/// Why are the 3D meshes' smallest dihedral angles small? (issue 6) For the final mesh of the
/// pipeline: how many tetrahedra fall under 5/10/15 degrees, which cells they come from
/// (interior octants or boundary octants), what their nodes are (interior, smooth surface,
/// feature line, corner) and whether their worst edge is an edge of the surface mesh.
void print_quality_diagnosis(const Result3d& r, const SurfaceBoundary& s, int dump, double below) {
  const Mesh<3>& m = r.fe.mesh;
  const std::vector<BoundaryLocation>& where = r.fe.where;
  std::size_t n_interior_cells = 0;
  for (auto f : r.interior) n_interior_cells += f ? 1 : 0;
  const auto kind = [&](std::int32_t v) {
    if (static_cast<std::size_t>(v) >= where.size() || where[v].patch < 0) return 0;  // interior
    return 1 + static_cast<int>(where[v].kind);  // 1 smooth, 2 feature line, 3 corner
  };
  std::set<std::pair<std::int32_t, std::int32_t>> surface_edges;
  for (std::size_t f = 0; f < m.interface.size(); ++f) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = v[k].v, b = v[(k + 1) % 3].v;
      surface_edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  double min_feature_deg = 180.0;  // the surface's sharpest edge: a bound for tets with two faces on it
  for (std::int32_t e : s.features().feature_edges())
    min_feature_deg = std::min(min_feature_deg, 180.0 - s.features().dihedral(e) * 180.0 / 3.14159265358979);
  const double bars[] = {2, 5, 10, 15};
  std::size_t n_under[4] = {0, 0, 0, 0};
  std::map<std::string, std::size_t> by_kind;
  struct Bad { double deg; std::size_t e; };
  std::vector<Bad> worst;
  static const int edge_nodes[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const P3 p[4] = {m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]};
    const std::array<double, 6> ang = tet_dihedral_angles_deg(p[0], p[1], p[2], p[3]);
    const int worst_edge = static_cast<int>(std::min_element(ang.begin(), ang.end()) - ang.begin());
    const double deg = ang[worst_edge];
    for (int b = 0; b < 4; ++b) n_under[b] += deg < bars[b] ? 1 : 0;
    if (deg >= below) continue;
    worst.push_back({deg, e});
    int nk[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; ++k) ++nk[kind(v[k].v)];
    const std::int32_t a = v[edge_nodes[worst_edge][0]].v, b = v[edge_nodes[worst_edge][1]].v;
    const bool on_surface = surface_edges.count({std::min(a, b), std::max(a, b)}) > 0;
    const bool boundary_cell = r.fe.cell[e] >= static_cast<std::int32_t>(n_interior_cells);
    char key[160];
    std::snprintf(key, sizeof key, "%s cell, nodes int/smooth/feature/corner %d/%d/%d/%d, worst edge %s",
                  boundary_cell ? "boundary" : "interior", nk[0], nk[1], nk[2], nk[3],
                  on_surface ? "on the surface" : "inside");
    ++by_kind[key];
  }
  std::printf("QUALITY %zu tets: under 2/5/10/15 deg: %zu/%zu/%zu/%zu; sharpest feature edge %.1f deg\n", m.solid.size(),
              n_under[0], n_under[1], n_under[2], n_under[3], min_feature_deg);
  for (const auto& [k, n] : by_kind) std::printf("  %6zu  %s\n", n, k.c_str());
  std::sort(worst.begin(), worst.end(), [](const Bad& x, const Bad& y) { return x.deg < y.deg; });
  for (std::size_t i = 0; i < worst.size() && static_cast<int>(i) < dump; ++i) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(worst[i].e)});
    std::printf("  tet %zu %.2f deg:", worst[i].e, worst[i].deg);
    for (int k = 0; k < 4; ++k)
      std::printf(" %d(%d %.4f %.4f %.4f)", v[k].v, kind(v[k].v), m.points[v[k].v][0], m.points[v[k].v][1],
                  m.points[v[k].v][2]);
    std::printf("\n");
    // Its edges (length, dihedral angle, on the surface mesh or not) and faces on the interface,
    // and per node the worst angle of its star: which of its nodes the sweeps could still move.
    const P3 p[4] = {m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]};
    const std::array<double, 6> ang = tet_dihedral_angles_deg(p[0], p[1], p[2], p[3]);
    std::printf("    edges (length deg):");
    for (int k = 0; k < 6; ++k) {
      const std::int32_t a = v[edge_nodes[k][0]].v, b = v[edge_nodes[k][1]].v;
      std::printf(" %d-%d %.4f %.2f%s", a, b, (m.points[a] - m.points[b]).norm(), ang[k],
                  surface_edges.count({std::min(a, b), std::max(a, b)}) ? "s" : "");
    }
    std::printf("\n    interface faces:");
    for (std::size_t f = 0; f < m.interface.size(); ++f) {
      const VertexId* fv = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
      int in = 0;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 4; ++k) in += fv[i].v == v[k].v ? 1 : 0;
      if (in == 3) std::printf(" (%d %d %d)", fv[0].v, fv[1].v, fv[2].v);
    }
    std::printf("\n");
    for (int k = 0; k < 4; ++k) {
      std::size_t n_star = 0;
      std::vector<double> star;
      for (std::size_t t = 0; t < m.solid.size(); ++t) {
        const VertexId* u = m.solid.nodes(ElemId{static_cast<std::int32_t>(t)});
        if (u[0].v != v[k].v && u[1].v != v[k].v && u[2].v != v[k].v && u[3].v != v[k].v) continue;
        ++n_star;
        const std::array<double, 6> a = tet_dihedral_angles_deg(m.points[u[0].v], m.points[u[1].v], m.points[u[2].v], m.points[u[3].v]);
        star.push_back(*std::min_element(a.begin(), a.end()));
      }
      std::sort(star.begin(), star.end());
      std::printf("    node %d: %zu tets, worst", v[k].v, n_star);
      for (std::size_t i = 0; i < star.size() && i < 5; ++i) std::printf(" %.2f", star[i]);
      std::printf("\n");
    }
  }
}

constexpr const char* usage =
    "usage: diagnose3d SURFACE LEVEL [THICKNESS_CELLS] [options]\n"
    "  The first tree's boundary octants and raw tetrahedra, their inverted ones sorted by cause.\n"
    "  THICKNESS_CELLS       the thickness level from the first tree (Options3d::thickness_cells)\n"
    "first tree and projections:\n"
    "  --dump N              print the first N folded octants   --only K   only cause K of them\n"
    "  --near X Y Z R        with --dump: only octants within R of (X, Y, Z)\n"
    "  --snap                snap to feature lines here too      --unfold   unfold backward projections\n"
    "  --all                 outward test on all faces           --norays   no projection rays\n"
    "  --graze-region        the graze allowance at the interior region's boundary only\n"
    "  --graze-length L      with --graze-region: a segment along an interior octant for more\n"
    "                        than L x its size enters it\n"
    "  --outward C           BoundaryOctantOptions::min_outward  --facing C  min_facing\n"
    "  --feature-extra L     the feature level above the global one (default 1)\n"
    "  --feature-at-edges    the feature level at the feature edges only\n"
    "  --sampled             SurfaceOptions::thickness_sampled (the thickness level from a grid of rays)\n"
    "  --opposing            drop interior octants at nodes with opposing free faces\n"
    "  --thin-share          print the share of the surface thinner than 0.5-2 octants, and stop\n"
    "  --root-shift X Y Z    SurfaceOptions::root_shift (the root cube moved by these shares of its side)\n"
    "  --repair-at-cells     Options3d::repair_at_cells (refine at the cells behind the untangling's faults)\n"
    "  --untangle-reach R    Options3d::untangle_reach (the untangling's moves off the surface bounded)\n"
    "  --backward-along C    with --graze-region: BoundaryOctantOptions::backward_along\n"
    "  --in-plane C          BoundaryOctantOptions::in_plane_cosine (0 = off, the default;\n"
    "                        the try with the surface at one level has 0.01)\n"
    "whole pipeline:\n"
    "  --pipeline            run mesh3d and print its verdict, tets, min dihedral, volume error\n"
    "  --quality             with --pipeline: sort the tets under --below DEG (default 10) by origin;\n"
    "                        --dump N prints the N worst: nodes, edges (length, angle), interface\n"
    "                        faces and each node's worst angles\n"
    "  --single              one try, no fallbacks           --nosnap  no feature snapping\n"
    "  --accept-folds --peel-rounds N --buffer B --flat-buffer B --max-level L --worse-repairs N --max-repairs N --island-refinements N\n"
    "  --island-cells C --island-max-fraction F --thin-cells C --topology-refinements N --topology-gap G\n"
    "  --extra-levels N --thickness-extra N --optimize-sweeps N --target-dihedral DEG --smooth N\n"
    "                        the Options3d fields of those names (dim3/pipeline3d.hpp)\n";

/// The options and how many values each takes.
int option_values(const std::string& a) {
  static const std::vector<std::pair<std::string, int>> known = {
      {"--accept-folds", 0}, {"--all", 0}, {"--feature-at-edges", 0}, {"--norays", 0}, {"--nosnap", 0},
      {"--opposing", 0}, {"--pipeline", 0}, {"--quality", 0}, {"--sampled", 0}, {"--single", 0}, {"--snap", 0},
      {"--thin-share", 0}, {"--unfold", 0}, {"--near", 4}, {"--below", 1}, {"--buffer", 1}, {"--flat-buffer", 1}, {"--max-level", 1}, {"--worse-repairs", 1}, {"--dump", 1},
      {"--extra-levels", 1}, {"--facing", 1}, {"--feature-extra", 1}, {"--island-cells", 1},
      {"--island-max-fraction", 1}, {"--island-refinements", 1}, {"--max-repairs", 1}, {"--only", 1},
      {"--optimize-sweeps", 1}, {"--outward", 1}, {"--peel-rounds", 1}, {"--smooth", 1},
      {"--target-dihedral", 1}, {"--thickness-extra", 1}, {"--thin-cells", 1}, {"--topology-refinements", 1}, {"--topology-gap", 1},
      {"--graze-region", 0}, {"--graze-length", 1}, {"--root-shift", 3}, {"--repair-at-cells", 0},
      {"--untangle-reach", 1}, {"--in-plane", 1}, {"--backward-along", 1}};
  for (const auto& [name, n] : known)
    if (a == name) return n;
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::cout << usage;
      return 0;
    }
  if (argc < 3) {
    std::cerr << usage;
    return 2;
  }
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0) {
      if (i == 3) continue;  // THICKNESS_CELLS
      std::cerr << "diagnose3d: unexpected argument '" << a << "'\n" << usage;
      return 2;
    }
    const int n = option_values(a);
    if (n < 0 || i + n > argc - 1) {
      std::cerr << "diagnose3d: " << (n < 0 ? "unknown option '" + a + "'" : a + " needs " + std::to_string(n) + " value(s)")
                << "\n" << usage;
      return 2;
    }
    i += n;
  }
  const std::string path = argv[1];
  const int level = std::atoi(argv[2]);
  SurfaceOptions so;
  if (argc > 3 && std::string(argv[3]).rfind("--", 0) != 0) so.thickness_cells = std::atof(argv[3]);
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--feature-extra") so.feature_extra_levels = std::atof(argv[i + 1]);
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--feature-at-edges") so.feature_level_at_edges = true;
    if (std::string(argv[i]) == "--sampled") so.thickness_sampled = true;
    if (std::string(argv[i]) == "--root-shift" && i + 3 < argc)
      so.root_shift = P3(std::atof(argv[i + 1]), std::atof(argv[i + 2]), std::atof(argv[i + 3]));
  }
  int dump = 0, only = -1;
  bool near_on = false;
  P3 near_p = P3::Zero();
  double near_r = 0;
  BoundaryOctantOptions bo;
  bo.snap_features = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--all") bo.outward_all_faces = true;
    if (std::string(argv[i]) == "--norays") bo.rays = false;
    if (std::string(argv[i]) == "--unfold") bo.unfold_backward = true;
    if (std::string(argv[i]) == "--in-plane") bo.in_plane_cosine = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--graze-region") bo.graze_region = true;
    if (std::string(argv[i]) == "--snap") bo.snap_features = true;
    if (std::string(argv[i]) == "--near" && i + 4 < argc) {
      near_on = true;
      near_p = P3(std::atof(argv[i + 1]), std::atof(argv[i + 2]), std::atof(argv[i + 3]));
      near_r = std::atof(argv[i + 4]);
    }
    if (i + 1 >= argc) continue;
    if (std::string(argv[i]) == "--outward") bo.min_outward = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--facing") bo.min_facing = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--graze-length") bo.graze_length = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--backward-along") bo.backward_along = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--dump") dump = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--only") only = std::atoi(argv[i + 1]);
  }
  SurfaceBoundary s = SurfaceBoundary::from_file(path, so);
  Options3d opt;
  opt.level = level;
  opt.thickness_cells = so.thickness_cells;
  opt.min_outward = bo.min_outward;
  opt.min_facing = bo.min_facing;
  opt.outward_all_faces = bo.outward_all_faces;
  opt.projection_rays = bo.rays;
  opt.unfold_backward = bo.unfold_backward;
  opt.in_plane_cosine = bo.in_plane_cosine;
  opt.graze_region = bo.graze_region;
  opt.graze_length = bo.graze_length;
  opt.backward_along = bo.backward_along;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--accept-folds") opt.accept_valid_folds = true;
    if (std::string(argv[i]) == "--repair-at-cells") opt.repair_at_cells = true;
  }
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--peel-rounds") opt.peel_rounds = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--untangle-reach") opt.untangle_reach = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--buffer") opt.buffer = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--flat-buffer") opt.flat_buffer = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--max-level") opt.max_level = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--worse-repairs") opt.worse_repairs = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--max-repairs") opt.max_repairs = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--island-refinements") opt.island_refinements = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--island-cells") opt.island_cells = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--thin-cells") opt.thin_cells = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--island-max-fraction") opt.island_max_fraction = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--topology-refinements") opt.topology_refinements = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--topology-gap") opt.topology_gap = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--extra-levels") opt.extra_levels = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--thickness-extra") opt.thickness_extra_levels = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--optimize-sweeps") opt.optimize_sweeps = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--target-dihedral") opt.target_dihedral_deg = std::atof(argv[i + 1]);
    if (std::string(argv[i]) == "--smooth") opt.smoothing_iterations = std::atoi(argv[i + 1]);
  }
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--opposing") opt.drop_opposing = true;
  for (int i = 1; i < argc; ++i) {
    // --single: one try, no fallbacks (buffer, feature snapping, facing projections, level raise)
    if (std::string(argv[i]) == "--single")
      opt.retry_facing = false, opt.retry_without_buffer = false, opt.raise_levels = 0, opt.thin_retry_cells = 0;
    if (std::string(argv[i]) == "--nosnap") opt.snap_features = false;
  }
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--thin-share") {
      // Share of the surface thinner than k octants of the global level (the thin-first rule).
      const double h = s.root_box().extent()[0] / std::ldexp(1.0, level);
      std::printf("THIN %s L%d octant %.4g: share thinner than 0.5/1/1.5/2 octants %.4f %.4f %.4f %.4f\n", path.c_str(),
                  level, h, s.thin_share(0.5 * h), s.thin_share(h), s.thin_share(1.5 * h), s.thin_share(2 * h));
      return 0;
    }
  bool quality = false;
  double below = 10.0;  // --below DEG: the tetrahedra the quality diagnosis sorts and dumps
  for (int i = 1; i < argc; ++i) quality = quality || std::string(argv[i]) == "--quality";
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--below") below = std::atof(argv[i + 1]);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--pipeline") {
      const auto t0 = std::chrono::steady_clock::now();
      std::string verdict = "valid";
      std::size_t n_tets = 0;
      double min_dihedral = 0, vol_err = 0;
      int repairs = 0;
      try {
        const Result3d r = mesh3d(s, opt, [](const std::string& m) { std::fprintf(stderr, "  %s\n", m.c_str()); });
        const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
        if (!v.valid) verdict = "INVALID " + v.summary();
        n_tets = r.fe.mesh.solid.size();
        min_dihedral = summarize_quality(r.fe.mesh).min_angle_deg;
        vol_err = measure_fidelity(r.fe.mesh, s, 1).volume_rel_error;
        repairs = r.n_repairs;
        std::string stages;  // the mesh's own stage times (the last try's, after any retry's)
        for (const StageTime3& t : r.times) stages += " " + t.name + " " + std::to_string(t.seconds).substr(0, 5);
        std::printf("STAGES%s\n", stages.c_str());
        if (quality) print_quality_diagnosis(r, s, dump, below);
      } catch (const std::exception& e) {
        verdict = std::string("refused: ") + e.what();
        if (verdict.size() > 300) verdict.resize(300);
      }
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("PIPELINE %s L%d: %s, %zu tets, min dihedral %.2f deg, volume error %.2f%%, %d repairs, %.1f s\n",
                  path.c_str(), level, verdict.c_str(), n_tets, min_dihedral, 100 * vol_err, repairs, sec);
      return 0;
    }
  s.set_global_level(opt.level);
  s.set_max_level(opt.level + opt.extra_levels);
  s.set_thickness_level(opt.thickness_cells, opt.level + opt.thickness_extra_levels);
  RefineOptions ro;
  ro.max_level = std::max(opt.level + opt.extra_levels + 2, opt.level + opt.thickness_extra_levels);
  const ControlFn<3> control = [&](const Box<3>& b) { return s.control_level(b); };
  Orthtree<3> tree = balance_2to1(subdivide_by_control(s.root_box(), control, ro), BalanceKind::Full);
  const std::vector<Side> sides = classify(tree, s);
  Flags in = interior_flags(sides);
  const std::size_t nb = apply_buffer_rules(tree, in, s, opt);
  const Flags before_pinches = in;
  std::size_t np = remove_pinches(tree, in);
  std::size_t n_opposing = 0;
  for (int i = 0; i < argc; ++i)
    if (std::string(argv[i]) == "--opposing")
      for (int round = 0; round < 4; ++round) {
        const std::size_t k = remove_opposing(tree, in, [&s](const P3& q) { return s.closest_point(q).distance; });
        if (k == 0) break;
        n_opposing += k;
        np += remove_pinches(tree, in);
      }
  if (n_opposing > 0) std::printf("opposing free faces: %zu octants dropped\n", n_opposing);
  const Flags before_islands = in;
  const std::size_t ni = keep_largest_components(tree, in, s.n_components());
  std::size_t n_in = 0;
  for (auto f : in) n_in += f;
  std::printf("%s level %d thickness_cells %.2f: %zu leaves, %zu interior (buffer %zu, pinch %zu, islands %zu)\n",
              path.c_str(), level, so.thickness_cells, tree.n_leaves(), n_in, nb, np, ni);
  if (near_on && std::getenv("FEBEMESH_DUMP_CELLS"))
    for (std::size_t i = 0; i < tree.n_leaves(); ++i) {
      const Box<3> b = geometry(tree, tree.leaf(i));
      if ((b.center() - near_p).norm() > near_r) continue;
      std::printf("  leaf %zu level %d lo (%.4f %.4f %.4f) side %d in %d (pinch %d island %d)\n", i, int(tree.leaf(i).level), b.lo[0],
                  b.lo[1], b.lo[2], int(sides[i]), int(in[i]), int(before_pinches[i] && !in[i] && !before_islands[i]),
                  int(before_islands[i] && !in[i]));
    }
  if (const char* probe = std::getenv("FEBEMESH_PROBE")) {
    P3 q;
    std::sscanf(probe, "%lf %lf %lf", &q[0], &q[1], &q[2]);
    std::printf("PROBE (%.5f %.5f %.5f) inside %d\n", q[0], q[1], q[2], int(s.is_inside(q)));
    for (const ClosestPoint<3>& c : s.closest_points(q, 4))
      std::printf("  candidate (%.5f %.5f %.5f) tri %d distance %.6f enters kept %d crosses %d (stopping 1e-7 short: %d)\n",
                  c.point[0], c.point[1], c.point[2], c.where.patch, c.distance,
                  int(segment_enters_kept(tree, in, q, P3(c.point), 0.05)), int(s.crosses_before(q, P3(c.point))),
                  int(s.segment_crosses(q, q + (1.0 - 1e-7) * (P3(c.point) - q))));
  }
  if (std::getenv("FEBEMESH_DUMP_DROPPED"))
    for (std::size_t i = 0; i < tree.n_leaves(); ++i) {
      const bool pinch = before_pinches[i] && !in[i] && !before_islands[i], island = before_islands[i] && !in[i];
      if (!pinch && !island) continue;
      const P3 c = geometry(tree, tree.leaf(i)).center();
      std::printf("DROPPED %s level %d at %.5f %.5f %.5f\n", pinch ? "pinch" : "island", int(tree.leaf(i).level), c[0], c[1], c[2]);
    }
  const OctantComplexResult ocr = build_octant_complex(tree, in, s, bo);
  const OctantComplex& oc = ocr.complex;
  std::printf("free faces %zu, surface nodes %zu, next-normal %zu, ray %zu, blind %zu, unfolded %zu, edge-snapped %zu, pushed off lines %zu\n",
              ocr.stats.n_free_faces, ocr.stats.n_surface_nodes, ocr.stats.n_next_normal, ocr.stats.n_ray,
              ocr.stats.n_blind, ocr.stats.n_unfolded, ocr.stats.n_edge_snapped, ocr.stats.n_pushed_off_lines);
  const SurfacePointFn sp = [&](const P3& p) {
    const ClosestPoint<3> cp = s.closest_point(p);
    return std::make_pair(P3(cp.point), cp.where);
  };
  const TetMesh fe = tetrahedralize(tree, oc, sp);
  const std::int32_t n_interior = static_cast<std::int32_t>(oc.interior.size());
  std::set<std::int32_t> bad_octants;
  std::size_t n_bad = 0, n_bad_interior = 0;
  for (std::size_t e = 0; e < fe.mesh.solid.size(); ++e) {
    const VertexId* v = fe.mesh.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const P3 &a = fe.mesh.points[v[0].v], &b = fe.mesh.points[v[1].v], &c = fe.mesh.points[v[2].v],
             &d = fe.mesh.points[v[3].v];
    if ((b - a).dot((c - a).cross(d - a)) > 0) continue;
    ++n_bad;
    if (fe.cell[e] < n_interior) ++n_bad_interior;
    else bad_octants.insert(fe.cell[e] - n_interior);
  }
  const auto classify_octant = [&](std::size_t k, bool print) {
    const BoundaryOctant& b = oc.boundary[k];
    const P3 nf = facet_normal<3>(b.face);
    const double h = length(b.cell) * tree.unit();
    int why = 3;
    for (std::int32_t q : b.ring) {
      const std::int32_t p = oc.projection[q];
      const P3 dq = oc.points[p] - oc.points[q];
      const double len = dq.norm();
      const double cos_d = len > 0 ? dq.dot(nf) / len : 1.0;
      const P3 ns = s.surface().normal(oc.where[p].patch).normalized();
      const double cos_n = ns.dot(nf);
      int w = 3;
      if (cos_d < 0) w = 0;
      else if (cos_n < 0) w = 1;
      else if (len > 1.5 * h) w = 2;
      why = std::min(why, w);
      if (print)
        std::printf("    node %d at (%.7f %.7f %.7f) -> (%.7f %.7f %.7f) tri %d: |d|/h %.2f cos(d,nf) %.2f cos(ns,nf) %.2f\n",
                    q, oc.points[q][0], oc.points[q][1], oc.points[q][2], oc.points[p][0], oc.points[p][1],
                    oc.points[p][2], oc.where[p].patch, len / h, cos_d, cos_n);
    }
    return why;
  };
  const char* names[] = {"backward", "away", "long", "other"};
  std::map<int, int> count_bad, count_all;
  for (std::size_t k = 0; k < oc.boundary.size(); ++k) ++count_all[classify_octant(k, false)];
  int shown = 0;
  for (std::int32_t k : bad_octants) {
    const int w = classify_octant(k, false);
    ++count_bad[w];
    bool close = true;
    if (near_on) {
      close = false;
      for (std::int32_t q : oc.boundary[k].ring) close = close || (oc.points[q] - near_p).norm() < near_r;
    }
    if (shown < dump && (only < 0 || only == w) && close) {
      const BoundaryOctant& b = oc.boundary[k];
      const double h0 = length(b.cell) * tree.unit();
      std::printf("  octant %d (%s): leaf level %d face %d h %.4f\n", k, names[w], b.cell.level, b.face,
                  length(b.cell) * tree.unit());
      classify_octant(k, true);
      for (std::size_t e = 0; e < fe.mesh.solid.size(); ++e) {
        if (fe.cell[e] != n_interior + k) continue;
        const VertexId* v = fe.mesh.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
        const P3 &a = fe.mesh.points[v[0].v], &b2 = fe.mesh.points[v[1].v], &c = fe.mesh.points[v[2].v],
                 &d = fe.mesh.points[v[3].v];
        const double vol = (b2 - a).dot((c - a).cross(d - a)) / 6.0;
        if (vol <= 0) std::printf("    tet %d %d %d %d vol/h^3 %.3g\n", v[0].v, v[1].v, v[2].v, v[3].v, vol / (h0 * h0 * h0));
      }
      ++shown;
    }
  }
  if (std::getenv("FEBEMESH_FOLD_STATS")) {
    // Per folded octant (and all): region on rotor (x axis: plate x < -0.097, wall r 0.40-0.46,
    // blades r > 0.46), whether its corners' projections land on opposite sheets (two surface
    // normals with cos < 0), and the face normal's tangency to the surface (max |cos(ns, nf)|).
    std::map<std::string, std::array<int, 2>> tally;
    for (std::size_t k = 0; k < oc.boundary.size(); ++k) {
      const BoundaryOctant& b = oc.boundary[k];
      const bool bad = bad_octants.count(static_cast<std::int32_t>(k)) > 0;
      const P3 nf = facet_normal<3>(b.face);
      const P3 c = geometry(tree, b.cell).center();
      const double r = std::hypot(c[1], c[2]);
      const char* region = c[0] < -0.097 ? "plate" : r < 0.40 ? "inner" : r < 0.46 ? "wall" : "blade";
      double split = 1, tang = 0;
      std::vector<P3> ns;
      for (std::int32_t q : b.ring) ns.push_back(s.surface().normal(oc.where[oc.projection[q]].patch).normalized());
      for (std::size_t i = 0; i < ns.size(); ++i) {
        tang = std::max(tang, ns[i].dot(nf));
        for (std::size_t j = i + 1; j < ns.size(); ++j) split = std::min(split, ns[i].dot(ns[j]));
      }
      const std::string key = std::string(region) + (split < 0 ? " split" : " one-sheet") +
                              (tang < 0.5 ? " tangent(<0.5)" : tang < 0.9 ? " oblique" : " facing");
      ++tally[key][bad ? 1 : 0];
      if (std::string(region) == "wall") {
        // Local thickness at the centre: nearest point plus the nearest local minimum on a sheet
        // facing the other way; cos of the face normal with the radial direction.
        const auto cps = s.closest_points(c, 4);
        double th = -1;
        if (!cps.empty()) {
          const P3 n0 = s.surface().normal(cps[0].where.patch).normalized();
          for (std::size_t i = 1; i < cps.size() && th < 0; ++i)
            if (s.surface().normal(cps[i].where.patch).normalized().dot(n0) < 0) th = cps[0].distance + cps[i].distance;
        }
        const P3 radial = P3(0, c[1], c[2]).normalized();
        const double h = length(b.cell) * tree.unit();
        const int tb = th < 0 ? 9 : std::min(8, static_cast<int>(th / h));
        const std::string k2 = std::string("wall thick/h ") + std::to_string(tb) + (split < 0 ? " split" : " one") +
                               (std::abs(nf.dot(radial)) < 0.5 ? " riser" : " tread");
        ++tally[k2][bad ? 1 : 0];
        if (bad && std::getenv("FEBEMESH_FOLD_WHERE"))
          std::printf("  FOLDAT %s %s x %.4f r %.4f ang %.1f h %.4f th %.4f\n", k2.c_str(), names[classify_octant(k, false)], c[0], r,
                      std::atan2(c[2], c[1]) * 57.29577951308232, h, th);
      }
    }
    for (const auto& [key, n] : tally) std::printf("  FOLDSTAT %-32s folded %6d  unfolded %7d\n", key.c_str(), n[1], n[0]);
  }
  {
    // Face nodes with free faces on both sides along an axis (a slab one octant thick): no
    // single projection leaves through both.
    std::map<std::int32_t, unsigned> dirs;
    for (const BoundaryOctant& b : oc.boundary)
      for (std::int32_t q : b.ring) dirs[q] |= 1u << b.face;
    const auto opposing = [&](std::int32_t q) {
      const unsigned d = dirs[q];
      return (d & 3u) == 3u || (d & 12u) == 12u || (d & 48u) == 48u;
    };
    std::size_t n_opp = 0, n_bad_opp = 0;
    for (const auto& [q, d] : dirs) {
      if (!opposing(q)) continue;
      if (n_opp < static_cast<std::size_t>(dump) && std::getenv("FEBEMESH_DUMP_OPPOSING")) {
        std::printf("  opposing node %d at (%.4f %.4f %.4f) faces %02x:", q, oc.points[q][0], oc.points[q][1], oc.points[q][2], d);
        for (const BoundaryOctant& b : oc.boundary)
          for (std::int32_t r : b.ring)
            if (r == q) std::printf(" [face %d level %d at (%.4f %.4f %.4f)]", b.face, b.cell.level, geometry(tree, b.cell).lo[0],
                                    geometry(tree, b.cell).lo[1], geometry(tree, b.cell).lo[2]);
        std::printf("\n");
      }
      ++n_opp;
    }
    for (std::int32_t k : bad_octants) {
      bool any = false;
      for (std::int32_t q : oc.boundary[k].ring) any = any || opposing(q);
      n_bad_opp += any ? 1 : 0;
    }
    std::printf("face nodes %zu, with opposing free faces %zu; folded octants with such a node %zu\n", dirs.size(),
                n_opp, n_bad_opp);
  }
  std::printf("raw inverted tets %zu (interior cells %zu) in %zu boundary octants of %zu\n", n_bad, n_bad_interior,
              bad_octants.size(), oc.boundary.size());
  for (int w = 0; w < 4; ++w)
    std::printf("  %-8s folded octants %5d   all octants %6d\n", names[w], count_bad[w], count_all[w]);
  return 0;
}
