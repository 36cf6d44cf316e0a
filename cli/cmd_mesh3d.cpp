// `febemesh mesh3d SURFACE -o DIR`: the octree pipeline (dim3/pipeline3d.hpp) on a closed
// triangle surface, validated, written atomically as mesh.msh, mesh.vtu and report.json.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/command.hpp"
#include "cli/limit_hint.hpp"
#include "cli/progress.hpp"
#include "cli/size_option.hpp"
#include "core/atomic_output.hpp"
#include "core/error.hpp"
#include "core/process_stats.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "core/write_msh.hpp"
#include "core/write_vtu.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/figures3d.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface_boundary.hpp"

namespace febemesh::cli {
namespace {

/// The finest global level --level and --size may ask for (octants of the root's side / 2^9).
constexpr int finest_level = 9;

/// --figures auto: a figure of more polygons than this is not drawn. sphere966 level 5 (199,647
/// tets) cuts 7,813-7,818 polygons a plane (1.2 MB of SVG), level 6 (1,506,818 tets) 30,093-30,112
/// (4.4 MB; rsvg-convert renders one in 1.2 s), so this draws up to about level 6's twice.
constexpr std::size_t auto_figures_max_shapes = 60000;

/// x as printf's %g (6 significant digits).
std::string fmt_g(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

/// Where a mesh misses volume: how much of the surface lies on parts thinner than two octants
/// of `cell` (their side at the surface), how thin they get, and the --size that would put two
/// octants across the thinnest (or that it is finer than the finest level allows). Empty when no
/// part is that thin.
std::string thin_parts(dim3::SurfaceBoundary& surface, double cell, std::size_t n_interface) {
  if (!(cell > 0)) return {};
  const double share = surface.thin_share(2.0 * cell);
  if (!(share > 0)) return {};
  double thinnest = std::numeric_limits<double>::infinity();
  for (const double t : surface.thicknesses())
    if (t > 0) thinnest = std::min(thinnest, t);
  const double finest = default_root_side(surface.bounding_box()) / std::ldexp(1.0, finest_level);  // default cube
  const double size = thinnest / 2;
  std::ostringstream os;
  os.precision(3);
  os << "; " << 100.0 * share << "% of the surface's area lies on parts thinner than two octants (2 x " << cell
     << "), down to " << thinnest << " thick: two octants across that are --size " << size;
  if (size < finest) os << ", finer than level " << finest_level << " allows (" << finest << ")";
  // --size puts the whole surface at that size: the interface faces grow as the area over the
  // octants' faces. (Measured: rotor.off at --size 0.01, 43x its level-4 interface faces by this
  // rule, had not finished after 15 minutes on one thread.)
  const double growth = (cell / size) * (cell / size);
  if (n_interface > 0 && growth >= 2) {
    const double unit = std::pow(10.0, std::floor(std::log10(growth)) - 2);  // three digits
    os << "; the whole surface at that size is about " << std::fixed << std::setprecision(growth < 10 ? 1 : 0)
       << std::round(growth / unit) * unit << "x this mesh's " << n_interface << " interface faces";
  }
  return os.str();
}

const char* help_text =
    "usage: febemesh mesh3d SURFACE -o DIR [options]\n\n"
    "Tetrahedral (or hex-dominant) FE mesh of the solid bounded by a closed triangle surface\n"
    "(OFF, STL, OBJ, PLY) and the triangle (or quad) BE mesh of its boundary, sharing nodes:\n"
    "octree refined by a level field, 2:1 balance, interior octants, boundary octants by\n"
    "projection onto the surface, feature snapping, tetrahedra from templates, guarded\n"
    "smoothing; with --elements hex the tetrahedra of each octant are merged into a hexahedron\n"
    "or pyramids where that conforms.\n\n"
    "options:\n"
    "  -o DIR              output folder (mesh.msh, mesh.vtu, report.json, figures/),\n"
    "                      written atomically; an earlier run's folder is replaced, a\n"
    "                      folder holding other files refused\n"
    "  --level N           global octree level at the surface (1..9, default 4)\n"
    "  --size H            instead of --level: the octants' side at the surface, in the\n"
    "                      surface's units (the level whose octants are no larger, in a\n"
    "                      root cube enlarged by less than 2x so that they are H; the\n"
    "                      element count then follows H instead of 8x steps)\n"
    "  --extra-levels N    extra levels for curvature and features (0..4, default 2);\n"
    "                      when every try with them is refused, the run goes on with\n"
    "                      the surface at the one level (report.json surface_uniform)\n"
    "  --elements KIND     tet (default), or hex: hex-dominant (hexahedra where the octants\n"
    "                      conform, pyramids and tetrahedra elsewhere; quad BE faces where\n"
    "                      a hexahedron's or pyramid's surface face stays a quad)\n"
    "  --buffer X          the buffer rule of the last try (after the tries without it):\n"
    "                      drop interior octants nearer the surface than X times their\n"
    "                      size (0..0.5, default 0.2; 0: no such try)\n"
    "  --smooth N          smoothing iterations (0..50, default 4)\n"
    "  --target-dihedral DEG  what the tetrahedra's optimisation aims at: nodes whose\n"
    "                      tetrahedra all reach this dihedral angle stay put, and edges\n"
    "                      of tetrahedra under it are removed where that helps (0..35,\n"
    "                      default 30; lower is faster: sphere966 level 6 on one thread\n"
    "                      in 4.4 s at 30 (min 29.7 deg), 3.3 s at 25, 3.0 s at 20)\n"
    "  --no-features       do not snap to feature edges and corners (also skipped on a\n"
    "                      faceted surface, where most feature lines end in smooth surface)\n"
    "  --given-axes        mesh in the input's axes (by default a part whose flat faces lie\n"
    "                      at an angle to them is meshed in the frame of those faces and\n"
    "                      turned back: report.json \"frame\")\n"
    "  --lattice-draws N   where the mesh is degraded (refused, one level finer, thin parts\n"
    "                      left out, a dihedral angle under --draw-below, more of the volume\n"
    "                      lost than --draw-lost), mesh again up to N times with the\n"
    "                      octree's lattice shifted against the part, within the work\n"
    "                      bound left (0..2, default 2; report.json lattice_draw)\n"
    "  --draw-below DEG    the dihedral angle under which a mesh counts as degraded for\n"
    "                      the lattice draws (0..30, default 10)\n"
    "  --draw-lost PCT     the share of the volume a mesh may lose (thin parts not meshed)\n"
    "                      before it counts as degraded for the lattice draws (0..100,\n"
    "                      default 10)\n"
    "  --flat-retry-below DEG  where the mesh's smallest dihedral angle is under this,\n"
    "                      mesh once more without the interior octants whose faces lie\n"
    "                      flat just under the surface, and keep the better (0..30,\n"
    "                      default 15; 0: never; report.json flat_retry)\n"
    "  --draw-effort X     where the first run lost only volume, its draws may build on\n"
    "                      at most X times the octants it built, in all (0..1000,\n"
    "                      default 2; 0: what the work bound leaves)\n"
    "  --max-cells N       refuse octrees of more than N octants (default 20000000)\n"
    "  --threads N         threads for refinement, classification, smoothing and the\n"
    "                      tet optimiser (default: all cores); the mesh is the same\n"
    "                      byte for byte for every N\n"
    "  --effort X          work bound: the repairs and retries may build on at most X\n"
    "                      times the first octree's octants, 2*10^6 at least, in all\n"
    "                      (1..1000, default 60); past it the last valid mesh stands,\n"
    "                      or the run is refused\n"
    "  --binary            write mesh.msh as MSH 4.1 binary (faster to write and read, not\n"
    "                      smaller: every tag takes 8 bytes) and mesh.vtu with its arrays\n"
    "                      as raw appended binary (faster, about half the size)\n"
    "  --figures MODE      all | none | auto (default): figures/section-x.svg, -y, -z (the\n"
    "                      solid cut by three planes through the middle, each element\n"
    "                      coloured by its smallest dihedral angle, the surface's cut in\n"
    "                      black) and figures/interface.svg (the BE mesh seen from a\n"
    "                      corner); auto leaves out a figure of more than 60000 polygons\n"
    "                      (figures/README.txt says which)\n"
    "  --no-figures        same as --figures none\n"
    "  --allow-invalid     write the mesh even if validation fails (exit status 1 still)\n"
    "  --quiet             no progress on stderr\n\n"
    "Bad input (open, non-manifold or self-intersecting surface: two of its triangles that\n"
    "share no vertex cross or touch; unreadable file) exits with status 1 and writes\n"
    "nothing; so does a surface whose boundary octants cannot be built\n"
    "up to the maximum level or within the work bound. A coarse level refused cheaply (under\n"
    "2*10^6 octants) is tried once more one level finer, with a warning: after the lattice\n"
    "draws, when none of them stands undegraded.\n";

nlohmann::json quality_json(const QualitySummary& q) {
  nlohmann::json j;
  j["n_elements"] = q.n_elements;
  j["min_dihedral_deg"] = q.min_angle_deg;
  j["max_dihedral_deg"] = q.max_angle_deg;
  j["min_scaled_jacobian"] = q.min_scaled_jacobian;
  j["mean_scaled_jacobian"] = q.mean_scaled_jacobian;
  j["max_aspect_ratio"] = q.max_aspect_ratio;
  j["max_radius_ratio"] = q.max_radius_ratio;
  j["scaled_jacobian_histogram"] = {{"bin_edges", {-1.0, -0.8, -0.6, -0.4, -0.2, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0}},
                                    {"counts", q.scaled_jacobian_histogram}};
  j["sliver_threshold_deg"] = q.sliver_threshold_deg;
  j["n_slivers"] = q.n_slivers;
  return j;
}

/// The mesh with each interface quad split into two triangles: measure_fidelity samples
/// triangles only (hex-dominant BE meshes have quads).
Mesh<3> triangulated_interface(const Mesh<3>& m) {
  Mesh<3> out = m;
  out.interface.clear();
  for (std::size_t f = 0; f < m.interface.size(); ++f) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
    out.interface.add(ElemType::Tri3, {v[0], v[1], v[2]});
    if (m.interface.type[f] == ElemType::Quad4) out.interface.add(ElemType::Tri3, {v[0], v[2], v[3]});
  }
  return out;
}

int run(const std::vector<std::string>& argv) {
  const Args args(argv, {"--quiet", "--no-features", "--features-fallback-first", "--buffer-first", "--uniform-last", "--uniform-before-unsnapped",
                   "--no-thickness-probe", "--given-axes", "--allow-invalid",
                   "--binary", "--no-figures"},
                  {"-o", "--level", "--size", "--extra-levels", "--elements", "--buffer", "--smooth", "--threads", "--effort",
                   "--max-cells",
                   "--lattice-draws", "--draw-below", "--draw-lost", "--draw-effort", "--target-dihedral",
                   "--flat-buffer", "--in-plane", "--flat-retry-below", "--figures"});
  args.expect_positional({"SURFACE"});
  const std::string input = args.positional()[0];
  const auto out = args.value("-o");
  if (!out) throw UsageError("missing -o DIR");
  check_output_folder(*out);  // before the run: never replaces a folder febemesh did not write
  dim3::Options3d opt;
  opt.level = args.int_or("--level", 4, 1, finest_level);
  opt.size = size_option(args);
  opt.extra_levels = args.int_or("--extra-levels", 2, 0, 4);
  opt.buffer = args.real_or("--buffer", 0.2, 0.0, 0.5);
  opt.smoothing_iterations = args.int_or("--smooth", 4, 0, 50);
  dim3::set_target_dihedral(opt, args.real_or("--target-dihedral", opt.target_dihedral_deg, 0.0, 35.0));
  opt.snap_features = !args.has("--no-features");
  // Hidden, for comparisons with the order before session 29: each try once more without
  // feature snapping at once (Options3d::features_fallback_last off).
  opt.features_fallback_last = !args.has("--features-fallback-first");
  // Hidden, for comparisons with the order before session 31: the buffer rule's try first
  // (Options3d::buffer_last off).
  opt.buffer_last = !args.has("--buffer-first");
  // Hidden, for comparisons with the order of session 51: on a faceted surface the try with the
  // surface at one level after every other, not right after the first (Options3d::uniform_early_faceted off).
  opt.uniform_early_faceted = !args.has("--uniform-last");
  opt.uniform_early_snapped = args.has("--uniform-before-unsnapped");  // hidden, an experiment
  // Hidden, for comparisons with the tries before session 32: no thickness try's first tree
  // after a first tree with problems (Options3d::thickness_probe off).
  opt.thickness_probe = !args.has("--no-thickness-probe");
  opt.align_planar_faces = !args.has("--given-axes");
  // Hidden, for experiments: Options3d::flat_buffer (interior octants whose free face lies flat
  // within this x their size of the surface are dropped; 0, off, by default).
  opt.flat_buffer = args.real_or("--flat-buffer", opt.flat_buffer, 0.0, 0.5);
  // Hidden, for experiments: Options3d::in_plane_cosine in every try (0, off, by default; the
  // try with the surface at one level uses uniform_in_plane_cosine).
  opt.in_plane_cosine = args.real_or("--in-plane", opt.in_plane_cosine, 0.0, 0.5);
  opt.effort = args.real_or("--effort", opt.effort, 1.0, 1000.0);
  opt.max_cells = static_cast<std::size_t>(args.real_or("--max-cells", static_cast<double>(opt.max_cells), 1e2, 1e10));
  opt.lattice_draws = args.int_or("--lattice-draws", opt.lattice_draws, 0, 2);
  opt.draw_min_dihedral_deg = args.real_or("--draw-below", opt.draw_min_dihedral_deg, 0.0, 30.0);
  opt.draw_max_volume_error = args.real_or("--draw-lost", 100 * opt.draw_max_volume_error, 0.0, 100.0) / 100;
  opt.volume_draw_effort = args.real_or("--draw-effort", opt.volume_draw_effort, 0.0, 1000.0);
  opt.flat_retry_below_deg = args.real_or("--flat-retry-below", opt.flat_retry_below_deg, 0.0, 30.0);
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  opt.n_threads = args.int_or("--threads", hw, 1, 256);
  const std::string elements = args.choice_or("--elements", "tet", {"tet", "hex"});
  opt.hex_dominant = elements == "hex";
  const MshEncoding encoding = args.has("--binary") ? MshEncoding::Binary : MshEncoding::Ascii;
  const std::string figures =
      args.has("--no-figures") ? "none" : args.choice_or("--figures", "auto", {"all", "none", "auto"});
  const bool quiet = args.has("--quiet");
  const Progress progress("mesh3d", quiet);

  const auto t0 = std::chrono::steady_clock::now();
  progress("reading " + input);
  dim3::SurfaceBoundary surface = dim3::SurfaceBoundary::from_file(input);
  // --level's range for the level --size gives in the given axes (a frame's may differ).
  if (opt.size > 0) sized_level<3>(surface.bounding_box(), opt.size, finest_level, input);
  const double t_read = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  dim3::Result3d r;
  const auto t_mesh0 = std::chrono::steady_clock::now();
  try {
    r = dim3::mesh3d(surface, opt, progress);
  } catch (const LimitError& e) {
    throw limit_refusal(input, e);
  } catch (const GeometryError& e) {
    throw GeometryError(input + ": " + e.what());
  }
  const double t_mesh = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_mesh0).count();
  const Mesh<3>& mesh = r.fe.mesh;

  // The folder is made before the validation, so that with two threads or more mesh.msh and
  // mesh.vtu are written beside it and the measures (the writers only read the mesh; a mesh that
  // fails validation throws below, and the folder is removed). sphere966 level 4 (callgrind,
  // one thread): the writers were 168 M of the CLI's 2.34 G instructions, the checks 435 M.
  // The fidelity measures (closest-point queries, const) go beside them too: 104 M there.
  AtomicOutputDir dir{std::filesystem::path(*out)};
  const auto launch = opt.n_threads > 1 ? std::launch::async : std::launch::deferred;
  std::future<void> writing = std::async(launch, [&] {
    write_msh(mesh, dir.file("mesh.msh"), encoding);
    write_vtu(mesh, dir.file("mesh.vtu"), encoding == MshEncoding::Binary ? VtuEncoding::Binary : VtuEncoding::Ascii);
  });
  progress("validating " + std::to_string(mesh.solid.size()) + (opt.hex_dominant ? " solid elements" : " tetrahedra"));
  const auto tv = std::chrono::steady_clock::now();
  std::future<dim3::Fidelity3d> measuring = std::async(launch, [&] {
    return dim3::measure_fidelity(opt.hex_dominant ? triangulated_interface(mesh) : mesh, surface);
  });
  const ValidateOptions<3> vo = dim3::surface_validation(surface, opt.n_threads);
  // The pipeline's report of this mesh with these checks, when it made one (meshes from the
  // Escobar pass, with folds, from the thickness retry) and the mesh is still that one (its
  // content hash): the same report without validating twice (elephant L4: 1.4 s a thread).
  const std::uint64_t hash = content_hash(mesh);
  const bool reported = r.validation && r.validation_hash == hash;
  const ValidationReport vr = reported ? *r.validation : validate(mesh, vo);
  // Likewise the quality summary mesh3d took to rank the lattice draws.
  const QualitySummary q = r.quality && r.quality_hash == hash ? *r.quality : summarize_quality(mesh, 10.0, opt.n_threads);
  const dim3::Fidelity3d fid = measuring.get();
  const double t_check = std::chrono::duration<double>(std::chrono::steady_clock::now() - tv).count();

  if (!vr.valid && !args.has("--allow-invalid"))
    throw GeometryError(input + ": the mesh is not valid:\n" + vr.summary());
  writing.get();  // rethrows a write error (one thread: writes now)
  dim3::MeshFigures drawn;
  double t_figures = 0.0;
  if (figures != "none") {
    progress("figures: sections and the BE mesh");
    const auto tf = std::chrono::steady_clock::now();
    drawn = dim3::write_mesh_figures(mesh, surface.surface(), dir.file("figures"),
                                     figures == "all" ? 0 : auto_figures_max_shapes);
    t_figures = std::chrono::duration<double>(std::chrono::steady_clock::now() - tf).count();
  }

  nlohmann::json rep;
  rep["input"] = input;
  rep["options"] = {{"level", r.level},
                    {"size", opt.size > 0 ? nlohmann::json(opt.size) : nlohmann::json(nullptr)},
                    {"root_scale", r.root_scale},
                    {"cell_size", r.cell_size},
                    {"extra_levels", opt.extra_levels},
                    {"elements", elements},
                    {"buffer", opt.buffer},
                    {"flat_buffer", opt.flat_buffer},
                    {"smoothing_iterations", opt.smoothing_iterations},
                    {"target_dihedral_deg", opt.target_dihedral_deg},
                    {"snap_features", opt.snap_features},
                    {"features_fallback_last", opt.features_fallback_last},
                    {"buffer_last", opt.buffer_last},
                    {"thickness_probe", opt.thickness_probe},
                    {"threads", opt.n_threads},
                    {"msh_encoding", encoding == MshEncoding::Binary ? "binary" : "ascii"},
                    {"vtu_encoding", encoding == MshEncoding::Binary ? "binary" : "ascii"},
                    {"figures", figures},
                    {"buffer_rule_dropped", r.buffer_dropped},
                    {"buffer_rule_fallback", r.buffer_fallback},
                    {"feature_snapping_dropped", r.features_dropped},
                    {"facing_projection", r.facing_projection},
                    {"thickness_refined", r.thickness_refined},
                    {"thickness_after_refusal", r.thickness_after_refusal},
                    {"thin_parts_coarse", r.thin_parts_coarse},
                    {"surface_uniform", r.surface_uniform},
                    {"thickness_early", r.thickness_early},
                    {"level_raised", r.level_raised},
                    {"align_planar_faces", opt.align_planar_faces},
                    {"frame_turned", r.frame.turned},
                    {"frame_refused", r.frame_refused},
                    {"lattice_draws", opt.lattice_draws},
                    {"draw_below_deg", opt.draw_min_dihedral_deg},
                    {"draw_lost_pct", 100 * opt.draw_max_volume_error},
                    {"draw_effort", opt.volume_draw_effort},
                    {"lattice_draws_run", r.lattice_draws_run},
                    {"flat_retry_below_deg", opt.flat_retry_below_deg},
                    {"flat_retry_made", r.flat_retry_made},
                    {"flat_retry", r.flat_retry},
                    {"lattice_draw", r.lattice_draw}};
  {
    const dim3::P3 shift = dim3::lattice_draw_shift(r.lattice_draw);
    rep["options"]["lattice_shift"] = {shift.x(), shift.y(), shift.z()};
  }
  // The frame meshed in (Options3d::align_planar_faces): its axes as rows, in the input's
  // coordinates, and the share of the area on planes square to them and to the given axes.
  nlohmann::json axes = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) axes.push_back({r.frame.to_frame(k, 0), r.frame.to_frame(k, 1), r.frame.to_frame(k, 2)});
  rep["frame"] = {{"turned", r.frame.turned},
                  {"axes", axes},
                  {"planar_share_given", r.frame.share_given},
                  {"planar_share_frame", r.frame.share_frame}};
  rep["surface"] = {{"triangles", surface.triangles().size()},
                    {"euler_characteristic", surface.euler_characteristic()},
                    {"components", surface.n_components()},
                    {"volume", surface.volume()},
                    {"feature_edges", surface.features().n_feature_edges()},
                    {"corners", surface.features().n_corners()},
                    {"feature_free_end_share", surface.features().free_end_share()}};
  std::size_t n_interior = 0;
  for (auto f : r.interior) n_interior += f ? 1 : 0;
  rep["counts"] = {{"nodes", mesh.points.size()},
                   {"tetrahedra", opt.hex_dominant ? r.hex.n_tet : mesh.solid.size()},
                   {"interface_triangles", opt.hex_dominant ? r.hex.n_interface_triangles : mesh.interface.size()},
                   {"leaves_subdivided", r.n_leaves_subdivided},
                   {"leaves", r.tree.n_leaves()},
                   {"interior_octants", n_interior},
                   {"boundary_octants", r.stats.n_free_faces},
                   {"buffer_dropped", r.n_buffer_dropped},
                   {"pinches_dropped", r.n_pinches_dropped},
                   {"opposing_dropped", r.n_opposing_dropped},
                   {"islands_dropped", r.n_islands_dropped},
                   {"surface_nodes", r.stats.n_surface_nodes},
                   {"shared_projections", r.stats.n_shared_projections},
                   {"next_normal", r.stats.n_next_normal},
                   {"ray_projections", r.stats.n_ray},
                   {"blind_projections", r.stats.n_blind},
                   {"untangle_moves", r.n_untangled},
                   {"untangle_node_moves", r.n_untangle_moves},
                   {"optimize_moves", r.n_optimize_moves},
                   {"edges_removed", r.n_edges_removed},
                   {"edges_contracted", r.n_edges_contracted},
                   {"concave_surface_swaps", r.n_concave_swaps},
                   {"corners_snapped", r.stats.n_corners_snapped},
                   {"corners_missed", r.stats.n_corners_missed},
                   {"edge_nodes_snapped", r.stats.n_edge_snapped},
                   {"snaps_reverted", r.n_snaps_reverted},
                   {"degenerate_cones_dropped", r.fe.n_dropped_degenerate},
                   {"fins_cancelled", r.fe.n_fins_cancelled},
                   {"repairs", r.n_repairs},
                   {"octants_built", r.n_octants_built},
                   {"smoothing_accepted", r.n_smoothing_accepted},
                   {"smoothing_rejected", r.n_smoothing_rejected}};
  nlohmann::json times = nlohmann::json::object();
  times["read"] = t_read;
  double in_stages = 0.0;
  for (const auto& st : r.times) times[st.name] = times.value(st.name, 0.0) + st.seconds, in_stages += st.seconds;
  // The stages are the kept try's; the tries before it (refused, or whose mesh a retry
  // replaced: `how` in the options) took the rest of the pipeline's time.
  times["tries_not_kept"] = std::max(0.0, t_mesh - in_stages);
  times["validate_and_measure"] = t_check;
  times["figures"] = t_figures;
  // Reading to the report, writing mesh.msh and mesh.vtu included.
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  times["total"] = total;
  rep["timings_s"] = times;
  // As mesh2d's report: the process's peak resident memory so far (reading to the report), and
  // the solid elements per second of the total.
  rep["peak_memory_bytes"] = peak_memory_bytes();
  const std::size_t n_elements = opt.hex_dominant ? r.hex.n_elements() : mesh.solid.size();
  rep["elements_per_second"] = total > 0.0 ? static_cast<double>(n_elements) / total : 0.0;
  rep["quality"] = quality_json(q);
  if (opt.hex_dominant)
    rep["hex_dominant"] = {{"hexahedra", r.hex.n_hex},
                           {"pyramids", r.hex.n_pyramid},
                           {"tetrahedra", r.hex.n_tet},
                           {"interface_quads", r.hex.n_interface_quads},
                           {"interface_triangles", r.hex.n_interface_triangles},
                           {"hex_share", r.hex.hex_share()},
                           {"hex_volume_share", r.hex.hex_volume_share()},
                           {"hex_candidates", r.hex.n_hex_candidates},
                           {"hex_rejected", r.hex.n_hex_rejected},
                           {"hex_demoted", r.hex.n_hex_demoted},
                           {"faces_split", r.hex.n_faces_split},
                           {"tets_min_dihedral_deg", r.hex.tets_min_dihedral_deg},
                           {"min_hex_scaled_jacobian", opt.hex.min_hex_scaled_jacobian},
                           {"min_scaled_jacobian", q.min_scaled_jacobian}};
  rep["fidelity"] = {{"surface_volume", fid.surface_volume},
                     {"fe_volume", fid.fe_volume},
                     {"volume_rel_error", fid.volume_rel_error},
                     {"hausdorff", fid.hausdorff},
                     {"hausdorff_rel", fid.hausdorff_rel},
                     {"be_to_surface", fid.be_to_surface},
                     {"surface_to_be", fid.surface_to_be},
                     {"max_interface_node_distance", fid.max_node_distance}};
  rep["validation"] = {{"valid", vr.valid},
                       {"euler", vr.euler},
                       {"expected_euler", vo.expected_euler ? nlohmann::json(*vo.expected_euler) : nlohmann::json()},
                       {"inverted", vr.inverted},
                       {"nonconforming_facets", vr.nonconforming_facets},
                       {"hanging_nodes", vr.hanging_nodes},
                       {"interface_mismatch", vr.interface_mismatch},
                       {"off_boundary_nodes", vr.off_boundary_nodes},
                       {"max_boundary_distance", vr.max_boundary_distance},
                       {"problems", vr.problems}};

  // A valid mesh can still miss part of the solid: parts thinner than the octants, dropped as
  // islands or by the buffer rule. Say so rather than let the number hide in the report.
  nlohmann::json warnings = nlohmann::json::array();
  if (fid.volume_rel_error > 0.05) {
    std::ostringstream w;
    w.precision(3);
    w << input << ": the mesh's volume differs from the surface's by " << 100.0 * fid.volume_rel_error;
    if (r.thin_parts_coarse)
      w << "% (parts thinner than the octants are not meshed: every try that refined them was refused,"
        << " and this one does not refine them)";
    else
      w << "% (parts of the solid are not meshed: thin parts or dropped islands)";
    w << thin_parts(surface, r.cell_size, mesh.interface.size());
    warnings.push_back(w.str());
    std::cerr << "febemesh mesh3d: warning: " << w.str() << "\n";
  }
  if (r.level_raised > 0) {
    const std::string level = std::to_string(r.level);
    const std::string asked = opt.size > 0 ? "level " + level + " (--size " + fmt_g(opt.size) + ")" : "--level " + level;
    const std::string w = input + ": refused at " + asked + "; meshed at level " + std::to_string(r.level + r.level_raised) +
                          " (the shape's features are too small for level " + level + ")";
    warnings.push_back(w);
    std::cerr << "febemesh mesh3d: warning: " << w << "\n";
  }
  rep["warnings"] = warnings;
  {
    nlohmann::json names = nlohmann::json::array(), skipped = nlohmann::json::array();
    for (const auto& f : drawn.written) names.push_back(f.string());
    for (const auto& why : drawn.skipped) skipped.push_back(why);
    rep["figures"] = {{"drawn", names}, {"skipped", skipped}};
  }

  {
    std::ofstream os(dir.file("report.json"));
    os << rep.dump(2) << "\n";
    if (!os) throw InputError(dir.file("report.json").string() + ": cannot write");
  }
  dir.commit();
  progress("wrote " + dir.final_path().string() + ": " + std::to_string(mesh.solid.size()) +
           (opt.hex_dominant ? " solid elements, " : " tetrahedra, ") + std::to_string(mesh.interface.size()) +
           (opt.hex_dominant ? " interface faces" : " interface triangles") + ", min dihedral " +
           std::to_string(q.min_angle_deg) + " deg" + (vr.valid ? "" : " (INVALID)"));
  if (!vr.valid) {
    std::cerr << "febemesh mesh3d: the mesh is not valid:\n" << vr.summary() << "\n";
    return exit_bad_input;
  }
  return exit_ok;
}

}  // namespace

FEBEMESH_COMMAND(Command{"mesh3d", "tetrahedral FE mesh + triangle BE mesh of a closed surface (octree)", help_text,
                         run});

}  // namespace febemesh::cli
