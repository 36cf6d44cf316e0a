#include "dim2/report2d.hpp"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "core/quality.hpp"
#include "dim2/fidelity2d.hpp"

namespace febemesh::dim2 {

Quality2d measure_quality(const Mesh<2>& m, const CurveBoundary& curve, int n_threads) {
  Quality2d q;
  q.summary = summarize_quality<2>(m, 20.0, n_threads);
  q.min_angle_away_deg = min_angle_away_from_sharp_corners(m, curve, 20.0, &q.n_near_sharp_corners, n_threads);
  if (std::any_of(m.solid.type.begin(), m.solid.type.end(), [](ElemType t) { return t == ElemType::Quad4; }))
    q.quad_bar = angles_away_from_sharp_corners(m, curve, 30.0, n_threads);  // the quad bar, [30, 150] deg
  return q;
}

std::string report_json(const Result2d& r, const CurveBoundary& curve, const Options2d& opt, const Fidelity2d& fid,
                        const Quality2d& quality2d, const ValidationReport& valid, const RunInfo& info) {
  using nlohmann::ordered_json;
  const Mesh<2>& m = r.fe.mesh;
  const QualitySummary& q = quality2d.summary;
  std::size_t n_tri = 0, n_quad = 0;
  for (ElemType t : m.solid.type) (t == ElemType::Tri3 ? n_tri : n_quad)++;
  std::size_t n_in = 0;
  for (auto f : r.interior) n_in += f;

  ordered_json j;
  j["febemesh"] = info.version;
  j["input"] = info.input;
  j["dimension"] = 2;
  ordered_json counts;
  counts["nodes"] = m.points.size();
  counts["fe_elements"] = m.solid.size();
  counts["triangles"] = n_tri;
  counts["quadrilaterals"] = n_quad;
  counts["be_elements"] = m.interface.size();
  counts["quadrants_subdivided"] = r.n_subdivided;
  counts["quadrants_balanced"] = r.n_balanced;
  counts["quadrants_final"] = r.tree.n_leaves();
  counts["interior_quadrants"] = n_in;
  counts["boundary_quadrants"] = r.n_boundary_quadrants;
  counts["loops"] = curve.n_loops();
  counts["components"] = curve.n_components();
  counts["holes"] = curve.n_holes();
  j["counts"] = counts;

  ordered_json bq;
  bq["free_edges"] = r.stats.n_free_edges;
  bq["chains"] = r.stats.n_chains;
  bq["next_normal"] = r.stats.n_next_normal;
  bq["walked"] = r.stats.n_walked;
  bq["clamped_to_keep_order"] = r.stats.n_clamped;
  bq["triangles_p1_eq_p2"] = r.stats.n_triangles;
  bq["corners_pulled"] = r.stats.n_corners_pulled;
  bq["corners_inserted"] = r.stats.n_corners_inserted;
  bq["projections_merged"] = r.stats.n_merged;
  bq["edge_flips"] = r.n_flips;
  bq["angle_optimisation_moves"] = r.n_angle_moves;
  bq["corners_missed"] = r.stats.n_corners_missed;
  bq["clamped_moved_to_reachable"] = r.stats.n_reachable_in_order;
  bq["buffer_dropped"] = r.n_buffer_dropped;
  bq["pinches_dropped"] = r.n_pinches_dropped;
  bq["repairs"] = r.n_repairs;
  bq["thin_parts_refined"] = r.thin_parts_refined;  // Options2d::thin_retry_boost's retry made it
  bq["smoothing_moves_rejected"] = r.n_smoothing_rejected;
  j["boundary_quadrants"] = bq;

  ordered_json quality;
  quality["min_angle_deg"] = q.min_angle_deg;
  quality["max_angle_deg"] = q.max_angle_deg;
  quality["min_angle_away_from_sharp_corners_deg"] = quality2d.min_angle_away_deg;
  quality["elements_near_sharp_corners"] = quality2d.n_near_sharp_corners;
  if (quality2d.quad_bar)
    quality["quad_angle_range_away_from_sharp_corners_deg"] = {quality2d.quad_bar->min_quad_deg, quality2d.quad_bar->max_quad_deg};
  quality["min_scaled_jacobian"] = q.min_scaled_jacobian;
  quality["mean_scaled_jacobian"] = q.mean_scaled_jacobian;
  quality["max_aspect_ratio"] = q.max_aspect_ratio;
  quality["elements_below_20deg"] = q.n_slivers;
  ordered_json hist = ordered_json::array();
  for (int b = 0; b < 10; ++b) {
    ordered_json bin;
    bin["from"] = -1.0 + 0.2 * b;
    bin["to"] = -1.0 + 0.2 * (b + 1);
    bin["count"] = q.scaled_jacobian_histogram[b];
    hist.push_back(bin);
  }
  quality["scaled_jacobian_histogram"] = hist;
  j["quality"] = quality;

  ordered_json f;
  f["exact_area"] = fid.exact_area;
  f["fe_area"] = fid.fe_area;
  f["be_polygon_area"] = fid.be_polygon_area;
  f["area_rel_error"] = fid.area_rel_error;
  f["hausdorff"] = fid.hausdorff;
  f["hausdorff_rel"] = fid.hausdorff_rel;
  f["max_interface_node_distance"] = fid.max_node_distance;
  j["fidelity"] = f;

  ordered_json v;
  v["valid"] = valid.valid;
  v["euler"] = valid.euler;
  v["expected_euler"] = curve.n_components() - curve.n_holes();
  v["inverted"] = valid.inverted;
  v["nonconforming_facets"] = valid.nonconforming_facets;
  v["hanging_nodes"] = valid.hanging_nodes;
  v["interface_mismatch"] = valid.interface_mismatch;
  j["validation"] = v;

  ordered_json times;
  for (const StageTime& t : r.times) times[t.name] = t.seconds;
  for (const StageTime& t : info.steps) times[t.name] = t.seconds;
  times["total"] = info.total_seconds;
  j["timings_seconds"] = times;
  j["peak_memory_bytes"] = info.peak_memory_bytes;
  j["elements_per_second"] = info.total_seconds > 0 ? m.solid.size() / info.total_seconds : 0.0;

  ordered_json o;
  o["level"] = opt.level;
  o["automatic_levels"] = curve.is_automatic();
  o["elements"] = name(opt.elements);
  o["smoothing_iterations"] = opt.smoothing_iterations;
  o["slide_boundary"] = opt.slide_boundary;
  o["buffer"] = opt.buffer;
  o["improve_rounds"] = opt.improve_rounds;
  o["max_level"] = opt.max_level;
  o["max_repairs"] = opt.max_repairs;
  o["threads"] = opt.n_threads;
  j["options"] = o;
  return j.dump(2) + "\n";
}

}  // namespace febemesh::dim2
