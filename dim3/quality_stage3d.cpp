#include "dim3/quality_stage3d.hpp"

#include <algorithm>
#include <iterator>
#include <limits>
#include <memory>
#include <numbers>

#include "core/smooth.hpp"
#include "dim3/edge_removal.hpp"
#include "dim3/tet_optimize.hpp"
#include "dim3/triangle_predicates.hpp"
#include "dim3/untangle3d.hpp"

namespace febemesh::dim3 {
namespace {

/// Frees all of the complex but its snap marks (OctantComplex::snapped): its lattice, points,
/// surface locations, projections and boundary octants, which the tetrahedra copied. Held
/// beside the smoothing's lists they were at its peak (bench_mesh3d sphere966 level 6, one
/// thread: 151-152 MB with them, 134-135 MB without).
void keep_snap_marks_only(OctantComplex& c) {
  c.lattice = {};
  std::vector<P3>().swap(c.points);
  std::vector<BoundaryLocation>().swap(c.where);
  std::vector<std::int32_t>().swap(c.projection);
  std::vector<std::size_t>().swap(c.interior);
  std::vector<BoundaryOctant>().swap(c.boundary);
  std::vector<P3>().swap(c.unsnapped);
}

/// Lets the nodes snapped onto a feature line (and still on it) slide along it in the quality
/// sweeps, and frees the snapped nodes now on a face (where.kind Smooth) as plain surface
/// nodes: `to.fixed` releases both, `to.on_line` marks the line nodes and `to.slide` brings a
/// candidate back onto the line, searching the segments near the node's own (as far along the
/// line as three times the step, both ways). Fixed on their snap points they lock the
/// tetrahedra around them: 5 of anchor L4's 8 tetrahedra under 10 deg had a feature-line node
/// (diagnose3d --pipeline --quality).
/// Returns how many nodes slide along a line (the freed face nodes are not counted).
std::size_t slide_on_lines(const SurfaceBoundary& s, const OctantComplex& oc, const TetMesh& fe,
                           TetOptimizeOptions& to) {
  const Features& feat = s.features();
  if (feat.n_feature_edges() == 0) return 0;
  std::size_t n = 0;
  to.on_line.assign(fe.mesh.points.size(), 0);
  for (std::size_t v = 0; v < oc.snapped.size() && v < fe.where.size(); ++v) {
    const BoundaryLocation& w = fe.where[v];
    if (oc.snapped[v] != 1) continue;
    if (w.kind == BoundaryLocation::Kind::Smooth && w.patch >= 0) {
      // Snapped onto a line but now on a face (the snap landed next to a crease, not on it):
      // it moves as any surface node. Fixed, it held fandisk L5's 0.0012 surface edge
      // (other edges 0.015-0.03) and anchor L5 tet's worst tetrahedra (14.38 -> 19.07 deg).
      to.fixed[v] = 0;
      continue;
    }
    if (w.kind != BoundaryLocation::Kind::FeatureEdge || w.feature < 0) continue;
    to.fixed[v] = 0;
    to.on_line[v] = 1;
    ++n;
  }
  // The segment of each feature edge along its line.
  auto segment = std::make_shared<std::vector<std::int32_t>>(feat.n_feature_edges(), -1);
  for (const FeatureLine& l : feat.lines())
    for (std::size_t i = 0; i < l.edges.size(); ++i) (*segment)[feat.feature_edge_index(l.edges[i])] = static_cast<std::int32_t>(i);
  to.slide = [&s, &feat, segment](const P3& x0, const BoundaryLocation& w0, const P3& x) {
    const FeatureLine& l = feat.lines()[feat.line_of(w0.feature)];
    const std::int32_t n_seg = static_cast<std::int32_t>(l.points.size()) - 1;
    const std::int32_t i0 = (*segment)[w0.feature];
    const double reach = 3.0 * (x - x0).norm();
    double best_d = std::numeric_limits<double>::infinity();
    std::int32_t best = -1;
    P3 best_q = x0;
    const auto visit = [&](std::int32_t i) {
      const P3 &a = l.points[i], &b = l.points[i + 1];
      const P3 q = a + closest_on_segment(x, a, b) * (b - a);
      const double d = (q - x).norm();
      if (d < best_d) best_d = d, best = i, best_q = q;
      return (b - a).norm();
    };
    visit(i0);
    for (const int dir : {1, -1}) {
      double arc = 0.0;
      std::int32_t i = i0;
      for (std::int32_t step = 1; step < n_seg && arc <= reach; ++step) {
        i += dir;
        if (i < 0 || i >= n_seg) {
          if (!l.closed) break;
          i = (i + n_seg) % n_seg;
        }
        if (i == i0) break;
        arc += visit(i);
      }
    }
    LineSlide out;
    out.point = best_q;
    out.where = s.closest_point(best_q).where;
    out.where.kind = BoundaryLocation::Kind::FeatureEdge;
    out.where.feature = feat.feature_edge_index(l.edges[best]);
    out.tangent = (l.points[best + 1] - l.points[best]).normalized();
    return out;
  };
  return n;
}

}  // namespace

void improve_quality(const SurfaceBoundary& s, OctantComplex& complex, TetMesh& fe, const Options3d& opt,
                     const SurfacePointFn& surface_point, const std::function<P3(const BoundaryLocation&)>& surface_normal,
                     Result3d& r, const Progress3& say) {
  // From here on a tetrahedral mesh needs only the complex's snap marks (which nodes the
  // sweeps keep fixed or slide along a line); the hex-dominant merge needs all of it.
  if (!opt.hex_dominant) keep_snap_marks_only(complex);
  say("smoothing: " + std::to_string(opt.smoothing_iterations) + " guarded Laplacian iterations");
  SmoothOptions<3> so;
  so.n_iterations = opt.smoothing_iterations;
  so.n_threads = opt.n_threads;
  so.fixed.assign(fe.mesh.points.size(), 0);
  for (std::size_t v = 0; v < fe.where.size(); ++v) so.fixed[v] = fe.where[v].patch >= 0 ? 1 : 0;
  so.boundary_fixed = true;  // the solid's boundary is the surface faces, all of whose nodes are on it
  const SmoothStats ss = smooth(fe.mesh, so);
  r.n_smoothing_accepted = ss.moves_accepted;
  r.n_smoothing_rejected = ss.moves_rejected;
  if (opt.optimize_sweeps > 0) {
    // Sliver removal: raise each node's worst dihedral angle (surface nodes slide on the
    // surface; feature nodes stay on their features).
    TetOptimizeOptions to;
    to.max_sweeps = opt.optimize_sweeps;
    to.target_dihedral_deg = opt.target_dihedral_deg;
    to.fixed = fixed_nodes(complex, fe, true);
    to.project = surface_point;
    to.surface_normal = surface_normal;
    to.n_threads = opt.n_threads;
    // The ranks go from each pass to the next (the points do not move in between).
    std::vector<double> ranks;
    to.ranks = &ranks;
    // Likewise each pass's node -> tetrahedra lists to the edge removal after it.
    NodeTets node_tets;
    to.incidence = &node_tets;
    const TetOptimizeStats ts = optimize_tets(fe.mesh, fe.where, to);
    r.n_optimize_moves = ts.moves;
    if (opt.slide_feature_nodes && slide_on_lines(s, complex, fe, to) > 0) {
      // More passes with the feature-line nodes sliding along their lines. After the first
      // pass, not in it: sliding from the start changes every later move and ended worse
      // on spool L4 (9.55 deg) and fandisk L4 (11.62). No pass can lower the minimum (every
      // move raises its node's worst tetrahedron); each starts afresh from every node below
      // the target. Measured (CLI, L4, min dihedral deg, anchor/spool/fandisk): one pass
      // 8.73/10.24/12.21; + one sliding 11.46/13.08/13.17 (+ one with the lines fixed
      // instead: 9.49/12.66/13.18); + two sliding 11.55/14.33/13.18; + two sliding and one
      // with the crease moves below 20 deg (tangent_below_deg) 12.84/14.33/13.18 (that one
      // as the only extra pass: 12.72/11.79/13.18). Those passes aim at 20 deg, not the
      // first pass's 30: 12.73/14.30/13.18 instead of 12.84/14.33/13.18, in 14.5/4.6/16.0 s
      // CPU instead of 24.5/9.7/17.5 (one pass: 13.0/4.1/14.4).
      to.target_dihedral_deg = std::min(opt.target_dihedral_deg, 20.0);
      for (int pass = 0; pass < 3; ++pass) {
        if (pass == 2) to.tangent_below_deg = 20.0;
        r.n_optimize_moves += optimize_tets(fe.mesh, fe.where, to).moves;
      }
    }
    if (opt.remove_edges_below_deg > 0) {
      // Node moves stall where the connectivity fixes a wedge (anchor L5: four tetrahedra
      // around a surface edge whose triangles meet at 62 deg, five under 10 deg). Measured
      // (CLI, min dihedral deg, base -> edges under 15 deg -> under 30): anchor L5 9.45 ->
      // 12.20 -> 14.38; L4: sphere966 28.17 -> 28.17 -> 29.93, spool 14.30 (unchanged),
      // anchor 12.73 -> 16.70 -> 19.56 (25 deg: 19.96, anchor L5 12.81), fandisk 13.18 ->
      // 14.33 -> 14.34, rotor 16.73 -> 16.73 -> 17.60, elephant 13.80 -> 16.78 (one round) ->
      // 21.42. Volume and Hausdorff errors the same to 3 digits; CPU about the same (30 deg
      // with a sort per removal instead of a heap: anchor L5 14.3 s instead of 6.5).
      EdgeRemovalOptions eo;
      eo.below_deg = opt.remove_edges_below_deg;
      // A hex-dominant mesh loses every hex and pyramid of a cell whose tetrahedra change:
      // there only the tetrahedra under the merge's own bar (sphere966 L4 at 30 deg: hex
      // volume share 0.999 -> 0.459).
      if (opt.hex_dominant) eo.below_deg = std::min(eo.below_deg, opt.hex.min_dihedral_deg);
      eo.surface_normal = surface_normal;
      eo.n_threads = opt.n_threads;
      eo.contract_below_deg = opt.contract_edges_below_deg;
      eo.ranks = &ranks;
      eo.incidence = &node_tets;
      // Contractions keep the corners. Nodes snapped onto a feature line may go (into a node
      // of theirs): those the sweeps keep fixed include some whose closest point is on a
      // face beside the line (fandisk L5: the smooth-surface end of a 0.0012 edge whose
      // seven tetrahedra stayed under 15 deg).
      std::vector<std::uint8_t> corners = fixed_nodes(complex, fe, false);
      const auto removal_rounds = [&] {
        for (int round = 0; round < 3; ++round) {
          eo.keep = corners;
          const EdgeRemovalStats es = remove_bad_edges(fe.mesh, fe.where, &fe.cell, eo);
          r.n_edges_removed += es.removed;
          r.n_edges_contracted += es.contracted;
          r.n_concave_swaps += es.concave_swapped;
          for (auto* per_node : {&corners, &to.fixed, &to.on_line, &eo.only_at}) remap_nodes(es.node_map, *per_node);
          remap_nodes(es.node_map, fe.where);
          if (!es.node_map.empty()) {  // the template's node ids -> today's (make_hex_dominant)
            if (fe.node_map.empty()) fe.node_map = es.node_map;
            else
              for (std::int32_t& id : fe.node_map)
                if (id >= 0) id = es.node_map[static_cast<std::size_t>(id)];
          }
          // With --elements hex those cells stay tetrahedra (make_hex_dominant).
          std::vector<std::int32_t> changed;
          std::set_union(fe.cells_changed.begin(), fe.cells_changed.end(), es.cells_changed.begin(),
                         es.cells_changed.end(), std::back_inserter(changed));
          fe.cells_changed = std::move(changed);
          if (es.removed == 0 && es.contracted == 0) break;
          r.n_optimize_moves += optimize_tets(fe.mesh, fe.where, to).moves;
        }
      };
      removal_rounds();
      if (opt.hex_dominant && opt.hex.min_dihedral_deg < opt.remove_edges_below_deg) {
        // Tetrahedra still under the merge's bar: the tetrahedral mesh's rounds (up to
        // remove_edges_below_deg) once more, on the tetrahedra at their nodes only, so that the
        // other cells keep their hexes and pyramids. Measured (elephant L5 hex, CLI, one thread):
        // 14.06 deg left under the 15 deg bar (14.32 with a 20 deg bar everywhere), where the
        // tetrahedral mesh's 30 deg rounds reach 19.72 deg.
        // The passes' ranks (tet_search_rank at the current points) pick the candidates, with
        // edge removal's margin; their angles decide.
        const bool ranked = ranks.size() == fe.mesh.solid.size();
        const double below_rank = tet_search_rank_of_angle(opt.hex.min_dihedral_deg * std::numbers::pi / 180.0) + 1e-9;
        std::vector<std::uint8_t> near(fe.mesh.points.size(), 0);
        bool any = false;
        for (std::size_t e = 0; e < fe.mesh.solid.size(); ++e) {
          if (ranked && !(ranks[e] < below_rank)) continue;
          const VertexId* v = fe.mesh.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
          const auto& p = fe.mesh.points;
          if (!(tet_min_dihedral_deg(p[v[0].v], p[v[1].v], p[v[2].v], p[v[3].v]) < opt.hex.min_dihedral_deg)) continue;
          for (int k = 0; k < 4; ++k) near[static_cast<std::size_t>(v[k].v)] = 1;
          any = true;
        }
        if (any) {
          eo.below_deg = opt.remove_edges_below_deg;
          eo.only_at = std::move(near);
          removal_rounds();
        }
      }
    }
  }
}

}  // namespace febemesh::dim3
