#include "dim3/tet_optimize.hpp"

#include <algorithm>
#include <atomic>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <span>

#include "core/error.hpp"
#include "core/incidence_csr.hpp"
#include "core/ordered_sweep.hpp"
#include "core/parallel_ranges.hpp"
#include "core/sort_short.hpp"
#include "dim3/escobar_objective.hpp"
#include "dim3/moving_tet.hpp"

namespace febemesh::dim3 {
namespace {

using P3 = Point<3>;
using Tet = std::array<std::int32_t, 4>;

constexpr double pi = 3.14159265358979323846;

/// Signed mean ratio 6 sqrt(2) V / l_rms^3 (1 for the regular tetrahedron).
double mean_ratio_volume(const P3& a, const P3& b, const P3& c, const P3& d) {
  const P3 ab = b - a, ac = c - a, ad = d - a;
  const double v6 = ab.dot(ac.cross(ad));
  const double l2 = (ab.squaredNorm() + ac.squaredNorm() + ad.squaredNorm() + (c - b).squaredNorm() +
                     (d - b).squaredNorm() + (d - c).squaredNorm()) /
                    6.0;
  if (l2 <= 0) return -1.0;
  return std::sqrt(2.0) * v6 / (l2 * std::sqrt(l2));
}

/// Cosine of the smallest dihedral angle (largest cosine over the six edges).
double max_dihedral_cos(const P3& a, const P3& b, const P3& c, const P3& d) {
  // Outward (for positive orientation) face normals opposite a, b, c, d.
  const std::array<P3, 4> n = {(c - b).cross(d - b), (d - a).cross(c - a), (b - a).cross(d - a),
                               (c - a).cross(b - a)};
  std::array<double, 4> len{};
  for (int i = 0; i < 4; ++i) len[i] = n[i].norm();
  double best = -1.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      if (len[i] <= 0 || len[j] <= 0) return 1.0;
      best = std::max(best, -n[i].dot(n[j]) / (len[i] * len[j]));
    }
  return std::clamp(best, -1.0, 1.0);
}

/// The angle (radians) of a search rank r > 0 (tet_search_rank's 1 - c|c| of its cosine c).
double rank_angle(double r) {
  const double cc = 1.0 - r;
  return std::acos(std::clamp(cc >= 0 ? std::sqrt(cc) : -std::sqrt(-cc), -1.0, 1.0));
}
/// The search rank of a positive tetrahedron whose smallest dihedral angle is `angle` radians.
double angle_rank(double angle) {
  const double c = std::cos(std::clamp(angle, 0.0, pi));
  return 1.0 - c * std::abs(c);
}

/// The central-difference gradient of m's rank at x, step h, N points at a time.
template <int N> [[gnu::always_inline]] inline P3 lanes_gradient(const MovingTet& m, const P3& x, double h) {
  // Points 2d and 2d + 1: x + h e_d and x - h e_d (then copies of the last to fill the lanes).
  constexpr int n_points = (6 + N - 1) / N * N;
  double at[3][n_points], r[n_points];
  for (int k = 0; k < n_points; ++k) {
    const int d = std::min(k, 5) / 2;
    for (int c = 0; c < 3; ++c) at[c][k] = x[c];
    at[d][k] = std::min(k, 5) % 2 == 0 ? x[d] + h : x[d] - h;
  }
  MovingTetLanes<N> lanes;
  lanes.set_all(m);
  for (int k = 0; k < n_points; k += N) {
    lanes.rank(&at[0][k], &at[1][k], &at[2][k], &r[k]);
    for (int l = 0; l < N; ++l)
      if (std::isnan(r[k + l])) r[k + l] = m.rank(P3(at[0][k + l], at[1][k + l], at[2][k + l]));
  }
  P3 g;
  for (int d = 0; d < 3; ++d) g[d] = (r[2 * d] - r[2 * d + 1]) / (2 * h);
  return g;
}

/// The worst rank over `local` at x, N at a time (blocks: `local` in lanes), into trial; some
/// value <= bound as soon as one is. The block of `first` (the one likeliest to fail) is tried
/// first, and `first` becomes the one that failed. Without an early stop, trial[i] holds every
/// rank at x.
template <int N>
[[gnu::always_inline]] inline double lanes_worst_above(const std::vector<MovingTet>& local, const MovingTetLanes<N>* blocks,
                                                       double* trial, const P3& x, double bound, std::int32_t& first) {
  const std::int32_t n = static_cast<std::int32_t>(local.size());
  const std::int32_t n_blocks = (n + N - 1) / N;
  double at[3][N];
  for (int c = 0; c < 3; ++c)
    for (int l = 0; l < N; ++l) at[c][l] = x[c];
  const std::int32_t b0 = first / N;
  double w = std::numeric_limits<double>::infinity();
  for (std::int32_t j = 0; j < n_blocks; ++j) {
    const std::int32_t b = j == 0 ? b0 : j <= b0 ? j - 1 : j;
    double r[N];
    blocks[b].rank(at[0], at[1], at[2], r);
    std::int32_t failed = -1;
    for (std::int32_t l = 0; l < N && N * b + l < n; ++l) {
      const std::int32_t i = N * b + l;
      trial[i] = std::isnan(r[l]) ? local[i].rank(x) : r[l];
      w = std::min(w, trial[i]);
      if (failed < 0 && trial[i] <= bound) failed = i;
    }
    if (failed >= 0) {
      first = failed;
      return w;
    }
  }
  return w;
}

// Four lanes in AVX registers where the CPU has them (AVX without FMA: SSE2's roundings).
// MovingTetLanes<4>'s vector helpers are all inlined into the AVX functions; GCC and Clang still
// warn (GCC at the end of the file) that their four-double arguments would change the ABI.
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FEBEMESH_TARGET_AVX [[gnu::target("avx")]]
bool has_avx() { return __builtin_cpu_supports("avx"); }
#else
#define FEBEMESH_TARGET_AVX
bool has_avx() { return false; }
#endif
FEBEMESH_TARGET_AVX P3 lanes_gradient_avx(const MovingTet& m, const P3& x, double h) { return lanes_gradient<4>(m, x, h); }
/// The sum of escobar_objective over the first n lanes of `blocks`, added in lane order (as
/// one tetrahedron at a time: the same number).
template <int N>
[[gnu::always_inline]] inline double escobar_sum_lanes(const EscobarLanes<N>* blocks, std::int32_t n, const P3& x,
                                                       double scale, double delta) {
  double k = 0.0;
  for (std::int32_t b = 0; N * b < n; ++b) {
    double e[N];
    blocks[b].objective(x, scale, delta, e);
    for (std::int32_t l = 0; l < N && N * b + l < n; ++l) k += e[l];
  }
  return k;
}
FEBEMESH_TARGET_AVX double escobar_sum_avx(const EscobarLanes<4>* blocks, std::int32_t n, const P3& x, double scale,
                                           double delta) {
  return escobar_sum_lanes<4>(blocks, n, x, scale, delta);
}
FEBEMESH_TARGET_AVX double lanes_worst_above_avx(const std::vector<MovingTet>& local, const MovingTetLanes<4>* blocks,
                                                 double* trial, const P3& x, double bound, std::int32_t& first) {
  return lanes_worst_above<4>(local, blocks, trial, x, bound, first);
}
#undef FEBEMESH_TARGET_AVX

/// The tetrahedra of a mesh of Tet4 elements only, read in place from its node array (four a
/// tetrahedron, in element order): a copy was 16 B a tetrahedron, 22 with the vector's growth,
/// of the optimiser's 53 B at the heap peak (sphere966 L5, heaptrack).
struct TetView {
  const VertexId* node = nullptr;
  std::size_t n = 0;
  Tet operator[](std::size_t t) const {
    const VertexId* v = node + 4 * t;
    return {v[0].v, v[1].v, v[2].v, v[3].v};
  }
  std::size_t size() const { return n; }
};

constexpr int max_tangent_planes = 3;
constexpr int max_tangent_candidates = max_tangent_planes * 3 * 2;

struct Optimizer {
  Mesh<3>& mesh;
  std::vector<BoundaryLocation>& where;
  const TetOptimizeOptions& opt;
  TetView tets;
  std::vector<std::int32_t> start, incident;  // CSR node -> tets
  /// Node -> neighbour nodes, listed only for the nodes a sweep visits (list_neighbours):
  /// nb_count[v] of them at nb_list[v], null while v has none. All of them up front were most
  /// of a call after edge removal (sphere966 L6: 0.08-0.12 s for 10^4 nodes to visit). Each
  /// call's lists go in a block of their own, of their exact size: one array grown by resize
  /// held up to twice its entries, and old and new at once while it grew (sphere966 L6: 13.9
  /// MB for 4.7 MB of lists, at the pipeline's heap peak, heaptrack).
  std::vector<std::int32_t*> nb_list;
  std::vector<std::int32_t> nb_count;
  std::vector<std::unique_ptr<std::int32_t[]>> nb_blocks;
  /// list_neighbours' marks of the nodes met, one set a range (at most opt.n_threads), kept
  /// from call to call: a bit a node, set while one node's neighbours are gathered and cleared
  /// after (by the list of those set). (A fresh array of -1 for each range of each pass, 0.69 MB
  /// at sphere966's 995,232 tetrahedra however few nodes it listed: 64 lists a run took 52 ms
  /// on one thread and 44 on two.)
  struct Marks {
    std::vector<std::uint64_t> bits;
    std::vector<std::int32_t> set;
  };
  std::vector<Marks> nb_marks;
  std::span<const std::int32_t> neighbours(std::int32_t v) const {
    return {nb_list[v], static_cast<std::size_t>(nb_count[v])};
  }
  std::vector<std::array<std::int32_t, 3>> faces;  // interface triangles
  std::vector<std::int32_t> f_start, f_incident;   // CSR node -> interface triangles
  /// The surface normal at each surface node: normals[normal_slot[v]], slot -1 (normal 0) for
  /// the others (one a node was 6.1 MB at sphere966 L6 for 4% of the nodes on the surface).
  std::vector<std::int32_t> normal_slot;
  std::vector<P3> normals;
  P3 node_normal(std::int32_t v) const {
    const std::int32_t k = normal_slot.empty() ? -1 : normal_slot[v];
    return k < 0 ? P3(P3::Zero()) : normals[static_cast<std::size_t>(k)];
  }
  /// The search rank of every tetrahedron at the current points: tet_search_rank at the
  /// start, then MovingTet::rank from the node that last moved (the same formula, to rounding).
  std::vector<double> tet_q;
  /// Per tetrahedron, 1 once a move re-ranked it (only when opt.ranks is handed back).
  std::vector<std::uint8_t> moved_tet;
  double target_rank = 0.0;  ///< angle_rank of the target dihedral angle
  double tangent_rank = 0.0;  ///< angle_rank of opt.tangent_below_deg
  bool avx = has_avx();  ///< rank four lanes at a time in AVX registers
  /// With untangle_only: the positive tetrahedra start at unranked_rank, not ranked
  /// (tet_untangle_rank), until a move or relax (for a folded triangle's node) ranks them.
  bool unranked = false;
  static constexpr double unranked_rank = 1.0;  // above every rank (1 - cos^2(70.53 deg) = 8/9)
  /// One thread's working space for relax.
  struct alignas(64) Scratch {
    std::vector<MovingTet> local;  ///< relax's incident tetrahedra seen from its node
    /// The same in blocks of lanes (the last one padded with copies): fours with AVX, else pairs.
    std::vector<MovingTetLanes<4>> quads;
    std::vector<MovingTetLanes<2>> pairs;
    /// escobar_descent's node's tetrahedra for the Escobar objective, in fours or pairs.
    std::vector<EscobarLanes<4>> escobar_quads;
    std::vector<EscobarLanes<2>> escobar_pairs;
    std::vector<double> trial, best_ranks;  ///< their ranks at a candidate, at the best one
    std::vector<std::int32_t> woken;  ///< the nodes this thread woke for the next sweep
    std::size_t moves = 0;
  };

  /// Search quality of interface triangle f with node v at x (normal nx there): +inf when it
  /// is aligned with the surface, else like an inverted tetrahedron (-1 + cosine, in [-2, -1]).
  double face_quality(std::int32_t f, std::int32_t v, const P3& x, const P3& nx) const {
    std::array<P3, 3> p;
    P3 ref = P3::Zero();
    for (int k = 0; k < 3; ++k) {
      const std::int32_t u = faces[f][k];
      p[k] = u == v ? x : mesh.points[u];
      ref += u == v ? nx : node_normal(u);
    }
    const double c = surface_alignment(p[0], p[1], p[2], ref);
    return c > 1e-9 ? std::numeric_limits<double>::infinity() : -2.0 + 0.5 * (1.0 + c);
  }
  double faces_worst(std::int32_t v, const P3& x, const P3& nx) const {
    double w = std::numeric_limits<double>::infinity();
    if (f_start.empty()) return w;
    for (std::int32_t k = f_start[v]; k < f_start[v + 1]; ++k) w = std::min(w, face_quality(f_incident[k], v, x, nx));
    return w;
  }

  double quality_at(std::int32_t t, std::int32_t v, const P3& x) const {
    std::array<P3, 4> p;
    for (int k = 0; k < 4; ++k) p[k] = tets[t][k] == v ? x : mesh.points[tets[t][k]];
    return tet_search_rank(p[0], p[1], p[2], p[3]);
  }
  P3 gradient(const MovingTet& m, const P3& x, double h) const {
    return avx ? lanes_gradient_avx(m, x, h) : lanes_gradient<2>(m, x, h);
  }
  /// local in blocks of lanes, the last one padded with copies of the last tetrahedron.
  template <int N> static void fill_blocks(const std::vector<MovingTet>& local, std::vector<MovingTetLanes<N>>& blocks) {
    blocks.resize((local.size() + N - 1) / N);
    for (std::size_t k = 0; k < blocks.size(); ++k)
      for (std::size_t l = 0; l < N; ++l) blocks[k].set_lane(static_cast<int>(l), local[std::min(N * k + l, local.size() - 1)]);
  }
  /// v's tetrahedra in lanes of the Escobar objective (their other nodes stay put while v
  /// descends), the last block padded with copies of the last tetrahedron.
  template <int N> void fill_escobar(std::int32_t v, std::vector<EscobarLanes<N>>& blocks) const {
    const std::int32_t n = start[v + 1] - start[v];
    blocks.resize(static_cast<std::size_t>((n + N - 1) / N));
    for (std::int32_t i = 0; i < N * static_cast<std::int32_t>(blocks.size()); ++i) {
      const Tet& t = tets[incident[start[v] + std::min(i, n - 1)]];
      std::array<P3, 4> p;
      int slot = 0;
      for (int k = 0; k < 4; ++k) {
        p[k] = mesh.points[t[k]];
        if (t[k] == v) slot = k;
      }
      blocks[static_cast<std::size_t>(i / N)].set_lane(i % N, p, slot);
    }
  }
  /// The sum of escobar_objective over v's tetrahedra with v at x, in incidence order (sc:
  /// fill_escobar's blocks of v).
  double escobar_sum(std::int32_t v, const P3& x, double scale, double delta, const Scratch& sc) const {
    const std::int32_t n = start[v + 1] - start[v];
    return avx ? escobar_sum_avx(sc.escobar_quads.data(), n, x, scale, delta)
               : escobar_sum_lanes<2>(sc.escobar_pairs.data(), n, x, scale, delta);
  }
  int n_inverted_at(std::int32_t v, const P3& x) const {
    int n = 0;
    for (std::int32_t i = start[v]; i < start[v + 1]; ++i) n += quality_at(incident[i], v, x) < 0 ? 1 : 0;
    return n;
  }
  int n_folded_at(std::int32_t v, const P3& x, const P3& nx) const {
    int n = 0;
    if (f_start.empty()) return 0;
    for (std::int32_t k = f_start[v]; k < f_start[v + 1]; ++k) n += face_quality(f_incident[k], v, x, nx) < 0 ? 1 : 0;
    return n;
  }

  /// Untangling by descent of the Escobar objective from x0 (projected onto the surface for
  /// surface nodes). Max-min steps stall where no single direction raises the worst
  /// tetrahedron; the smooth sum still has a descent direction there. The result is taken when
  /// it inverts no more tetrahedra (and folds no more interface triangles) and lowers the sum.
  bool escobar_descent(std::int32_t v, const P3& x0, double len, P3& x_out, BoundaryLocation& w_out, Scratch& sc) const {
    const double scale = len;
    double sigma_min = std::numeric_limits<double>::infinity();
    for (std::int32_t i = start[v]; i < start[v + 1]; ++i) {
      std::array<P3, 4> p;
      for (int k = 0; k < 4; ++k) p[k] = mesh.points[tets[incident[i]][k]];
      const double v6 = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / (scale * scale * scale);
      sigma_min = std::min(sigma_min, v6 * std::sqrt(2.0));  // det S = 6 V sqrt2 / scale^3
    }
    const double eps = 1e-3;
    const double delta = sigma_min < eps ? std::sqrt(eps * (eps - sigma_min)) : 0.0;
    const bool surf = is_surface(v);
    const bool guard = surf && !f_start.empty();
    const int inv0 = n_inverted_at(v, x0);
    const int fold0 = guard ? n_folded_at(v, x0, node_normal(v)) : 0;
    P3 x = x0;
    BoundaryLocation w = surf ? where[v] : BoundaryLocation{};
    if (avx)
      fill_escobar(v, sc.escobar_quads);
    else
      fill_escobar(v, sc.escobar_pairs);
    double k = escobar_sum(v, x, scale, delta, sc);
    const double k0 = k;
    const double hd = 1e-5 * len;
    for (int it = 0; it < 8; ++it) {
      P3 g;
      for (int d = 0; d < 3; ++d) {
        P3 xp = x, xm = x;
        xp[d] += hd;
        xm[d] -= hd;
        g[d] = (escobar_sum(v, xp, scale, delta, sc) - escobar_sum(v, xm, scale, delta, sc)) / (2 * hd);
      }
      if (surf) {
        const P3 n = node_normal(v);
        if (n.norm() > 0) g -= g.dot(n.normalized()) * n.normalized();
      }
      if (!(g.norm() > 0)) break;
      const P3 dir = -g.normalized();
      bool stepped = false;
      for (double step = 0.5 * len; step >= 1e-3 * len; step *= 0.5) {
        P3 y = x + step * dir;
        BoundaryLocation wy;
        if (surf) std::tie(y, wy) = opt.project(y);
        const double ky = escobar_sum(v, y, scale, delta, sc);
        if (ky < k) {
          x = y, w = wy, k = ky, stepped = true;
          break;
        }
      }
      if (!stepped) break;
    }
    if (!(k < k0 * (1.0 - 1e-9))) return false;
    if (n_inverted_at(v, x) > inv0) return false;
    if (guard && n_folded_at(v, x, opt.surface_normal(w)) > fold0) return false;
    x_out = x;
    w_out = w;
    return true;
  }
  /// Lists the neighbours (the nodes sharing a tetrahedron, ascending) of the nodes of `visit`
  /// that have none yet, in a new block (nb_blocks).
  void list_neighbours(const std::vector<std::int32_t>& visit) {
    const std::size_t n = mesh.points.size();
    if (nb_list.empty()) nb_list.assign(n, nullptr), nb_count.assign(n, 0);
    std::vector<std::int32_t> todo;
    for (const std::int32_t v : visit)
      if (!nb_list[v]) todo.push_back(v);
    if (todo.empty()) return;
    // The distinct neighbours by marks (marks[u] == v), then sorted: the lists of sorting all
    // ~70 uses a node's tetrahedra make and keeping one of each (97 M instructions, sphere966
    // L5, of which the sort most).
    // Two passes, counting then filling: the array has its exact size (push_back's growth left
    // up to twice, at the optimiser's heap peak).
    // Ranges of todo on opt.n_threads threads, each with its own marks (the same lists).
    const auto for_distinct = [&](Marks& marks, std::int32_t v, auto&& f) {
      for (std::int32_t k = start[v]; k < start[v + 1]; ++k)
        for (const std::int32_t u : tets[incident[k]]) {
          std::uint64_t& word = marks.bits[static_cast<std::size_t>(u) >> 6];
          const std::uint64_t bit = std::uint64_t{1} << (u & 63);
          if (u == v || (word & bit)) continue;
          word |= bit;
          marks.set.push_back(u);
          f(u);
        }
      for (const std::int32_t u : marks.set) marks.bits[static_cast<std::size_t>(u) >> 6] = 0;
      marks.set.clear();
    };
    const auto ranges = [&](auto&& body) {
      if (nb_marks.empty()) nb_marks.resize(static_cast<std::size_t>(std::clamp(opt.n_threads, 1, 256)));
      std::atomic<std::size_t> slot{0};
      for_each_range(todo.size(), opt.n_threads, [&](std::size_t begin, std::size_t end) {
        Marks& marks = nb_marks[slot++];
        if (marks.bits.empty()) marks.bits.assign((n + 63) / 64, 0);
        body(marks, begin, end);
      });
    };
    ranges([&](Marks& marks, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        std::int32_t count = 0;
        for_distinct(marks, todo[i], [&](std::int32_t) { ++count; });
        nb_count[todo[i]] = count;
      }
    });
    std::size_t total = 0;
    for (const std::int32_t v : todo) total += static_cast<std::size_t>(nb_count[v]);
    nb_blocks.emplace_back(new std::int32_t[std::max<std::size_t>(total, 1)]);
    std::int32_t* at = nb_blocks.back().get();
    for (const std::int32_t v : todo) nb_list[v] = at, at += nb_count[v];
    ranges([&](Marks& marks, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::int32_t v = todo[i];
        std::int32_t* out = nb_list[v];
        for_distinct(marks, v, [&](std::int32_t u) { *out++ = u; });
        sort_short(nb_list[v], out);
      }
    });
  }
  bool is_surface(std::int32_t v) const {
    return static_cast<std::size_t>(v) < where.size() && where[v].patch >= 0;
  }
  bool is_line(std::int32_t v) const {
    return opt.slide && !opt.on_line.empty() && opt.on_line[v] && is_surface(v);
  }
  /// Where node v (at x0) goes for candidate c: c itself inside, its closest surface point on
  /// the surface, the nearby point of its line on a feature line.
  void place(std::int32_t v, const P3& x0, const P3& c, P3& x, BoundaryLocation& w) const {
    if (is_line(v)) {
      const LineSlide ls = opt.slide(x0, where[v], c);
      x = ls.point, w = ls.where;
    } else if (is_surface(v)) {
      std::tie(x, w) = opt.project(c);
    } else {
      x = c;
    }
  }
  /// Whether x is in the box node v's moves stay in (TetOptimizeOptions::bounds).
  bool within(std::int32_t v, const P3& x) const {
    if (opt.bounds.empty()) return true;
    const Box<3>& b = opt.bounds[static_cast<std::size_t>(v)];
    return b.lo.x() > b.hi.x() || b.contains(x);
  }
  bool movable(std::int32_t v) const {
    if (!opt.fixed.empty() && opt.fixed[v]) return false;
    if (is_surface(v) && !opt.project) return false;
    return start[v + 1] > start[v];
  }

  /// Surface-node candidates that stay in the tangent planes of the surface around v (its own
  /// and its interface neighbours' normals): the search directions and the way to the centroid
  /// of its interface neighbours, each projected into those planes. The other candidates leave
  /// the surface and are brought back by the closest point, which outside a convex feature edge
  /// is the edge itself: nodes crowded onto a feature line by their projections could never
  /// leave it, and the interface triangles they make there are caps (measured: spool L4's 2.6
  /// deg and anchor L4's 8.3 deg tetrahedra all stand on such caps, 177-179 deg).
  int tangent_candidates(std::int32_t v, const P3& x0, double len, const P3* dirs, int n_dirs, P3* out) const {
    std::array<P3, max_tangent_planes> planes;
    int n_planes = 0;
    // Planes 30 deg or more apart: only across a crease (a feature line's two sides).
    const auto add_plane = [&](const P3& n) {
      const double l = n.norm();
      if (!(l > 0) || n_planes == max_tangent_planes) return;
      const P3 u = n / l;
      for (int i = 0; i < n_planes; ++i)
        if (planes[i].dot(u) > std::cos(pi / 6)) return;
      planes[n_planes++] = u;
    };
    add_plane(node_normal(v));
    P3 ring = P3::Zero();
    int n_ring = 0;
    for (std::int32_t k = f_start[v]; k < f_start[v + 1]; ++k)
      for (const std::int32_t u : faces[f_incident[k]])
        if (u != v) add_plane(node_normal(u)), ring += mesh.points[u], ++n_ring;
    if (n_planes < 2) return 0;  // smooth surface around v: the projected candidates do
    std::array<P3, 3> moves;
    int n_moves = 0;
    for (int i = 0; i < n_dirs; ++i) moves[n_moves++] = dirs[i];
    if (n_ring > 0 && (ring / n_ring - x0).norm() > 0) moves[n_moves++] = (ring / n_ring - x0).normalized();
    int n = 0;
    for (int p = 0; p < n_planes; ++p)
      for (int i = 0; i < n_moves; ++i) {
        P3 t = moves[i] - moves[i].dot(planes[p]) * planes[p];
        if (!(t.norm() > 0.1)) continue;
        t.normalize();
        for (double s : {0.2, 0.05}) out[n++] = x0 + s * len * t;
      }
    return n;
  }

  /// One local search at node v; returns true if it moved. Reads v's neighbours and the
  /// ranks of v's tetrahedra, writes v (point, location, normal) and those ranks.
  bool relax(std::int32_t v, Scratch& sc) {
    std::vector<MovingTet>& local = sc.local;
    std::vector<double>& trial = sc.trial;
    std::vector<double>& best_ranks = sc.best_ranks;
    const P3 x0 = mesh.points[v];
    std::int32_t worst_local = 0;
    const bool surf = is_surface(v);
    const bool guard = surf && !f_start.empty();
    double tets_worst = std::numeric_limits<double>::infinity();
    const auto find_worst = [&] {
      for (std::int32_t k = start[v]; k < start[v + 1]; ++k)
        if (tet_q[incident[k]] < tets_worst) tets_worst = tet_q[incident[k]], worst_local = k - start[v];
    };
    find_worst();
    const double f0 = std::min(tets_worst, guard ? faces_worst(v, x0, node_normal(v)) : 1e300);
    if (opt.untangle_only ? f0 > 0 : f0 >= target_rank) return false;
    if (unranked && tets_worst > 0) {
      // Only a folded interface triangle here: the worst tetrahedron (the first search
      // direction) is the worst of positive ones, so those not ranked yet are ranked now. Not
      // moved since the start (a move ranks them), they get the numbers the start gives them.
      for (std::int32_t k = start[v]; k < start[v + 1]; ++k) {
        double& q = tet_q[incident[k]];
        if (q != unranked_rank) continue;
        const Tet& t = tets[incident[k]];
        q = tet_search_rank(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]);
      }
      tets_worst = std::numeric_limits<double>::infinity();
      find_worst();
    }
    double len = 0.0;
    const std::span<const std::int32_t> ring = neighbours(v);
    for (const std::int32_t u : ring) len += (mesh.points[u] - x0).norm();
    len /= static_cast<double>(std::max<std::size_t>(1, ring.size()));
    if (len <= 0) return false;
    const double h = 1e-4 * len;

    local.resize(static_cast<std::size_t>(start[v + 1] - start[v]));
    trial.resize(local.size());
    best_ranks.resize(local.size());
    for (std::int32_t k = start[v]; k < start[v + 1]; ++k) local[k - start[v]].set(tets[incident[k]], v, mesh.points);
    if (avx)
      fill_blocks(local, sc.quads);
    else
      fill_blocks(local, sc.pairs);
    std::array<P3, 2> dirs;
    int n_dirs = 0;
    const P3 g = gradient(local[worst_local], x0, h);
    if (g.norm() > 0) dirs[n_dirs++] = g.normalized();
    P3 sum = P3::Zero();
    // The nearly worst: within 0.02 rad of the worst angle.
    const double near = f0 <= 0 ? f0 : angle_rank(rank_angle(f0) + 0.02);
    for (std::int32_t k = start[v]; k < start[v + 1]; ++k) {
      const std::int32_t t = incident[k];
      const double q = tet_q[t];
      if (q <= near || (f0 <= 0 && q <= 0)) {
        // The worst tetrahedron's gradient is g (the same numbers).
        const P3 gt = k - start[v] == worst_local ? g : gradient(local[k - start[v]], x0, h);
        if (gt.norm() > 0) sum += gt.normalized();
      }
    }
    if (sum.norm() > 0) dirs[n_dirs++] = sum.normalized();

    std::array<P3, 10 + std::max(max_tangent_candidates, 8)> cands;
    int n_cands = 0;
    P3 centroid = P3::Zero();
    for (const std::int32_t u : ring) centroid += mesh.points[u];
    centroid /= static_cast<double>(std::max<std::size_t>(1, ring.size()));
    cands[n_cands++] = centroid;
    cands[n_cands++] = 0.5 * (centroid + x0);
    for (int i = 0; i < n_dirs; ++i)
      for (double s : {0.25, 0.08, 0.025, 0.006}) cands[n_cands++] = x0 + s * len * dirs[i];
    if (is_line(v)) {
      // Along the line both ways: the other candidates reach it only through their projection.
      const P3 t = opt.slide(x0, where[v], x0).tangent;
      if (t.norm() > 0)
        for (double s : {0.25, 0.08, 0.025, 0.006}) cands[n_cands++] = x0 + s * len * t, cands[n_cands++] = x0 - s * len * t;
    } else if (guard && !opt.untangle_only && f0 < tangent_rank) {
      n_cands += tangent_candidates(v, x0, len, dirs.data(), n_dirs, &cands[n_cands]);
    }

    double best = f0;
    P3 best_x = x0;
    BoundaryLocation best_w = surf ? where[v] : BoundaryLocation{};
    for (int i = 0; i < n_cands; ++i) {
      const P3& c = cands[i];
      P3 x;
      BoundaryLocation w;
      place(v, x0, c, x, w);
      if (!within(v, x)) continue;
      double f = avx ? lanes_worst_above_avx(local, sc.quads.data(), trial.data(), x, best + 1e-12, worst_local)
                     : lanes_worst_above<2>(local, sc.pairs.data(), trial.data(), x, best + 1e-12, worst_local);
      if (guard && f > best + 1e-12) f = std::min(f, faces_worst(v, x, opt.surface_normal(w)));
      if (f > best + 1e-12) best = f, best_x = x, best_w = w, best_ranks.swap(trial);
    }
    if (opt.untangle_only && opt.escobar && !(best > 0) && (!surf || opt.escobar_surface) && !is_line(v)) {
      // The max-min candidates did not untangle this node's tetrahedra: descend the smooth
      // objective instead (from the better of x0 and their best point).
      P3 ex;
      BoundaryLocation ew;
      const P3 from = best_x;
      if (escobar_descent(v, from, len, ex, ew, sc) && !(ex == x0) && within(v, ex)) {
        best_x = ex, best_w = ew;
        for (std::size_t k = 0; k < local.size(); ++k) best_ranks[k] = local[k].rank(ex);
      }
    }
    if (best_x == x0) return false;
    mesh.points[v] = best_x;
    // The ranks at the new point were computed for the accepted candidate (all of them: it
    // was not stopped early).
    for (std::int32_t k = start[v]; k < start[v + 1]; ++k) tet_q[incident[k]] = best_ranks[k - start[v]];
    if (!moved_tet.empty())  // (v's tetrahedra: no other node visited meanwhile shares one)
      for (std::int32_t k = start[v]; k < start[v + 1]; ++k) moved_tet[incident[k]] = 1;
    if (surf) where[v] = best_w;
    if (guard) normals[static_cast<std::size_t>(normal_slot[v])] = opt.surface_normal(best_w);
    return true;
  }
};

}  // namespace

double tet_search_rank(const P3& a, const P3& b, const P3& c, const P3& d) {
  const P3 ab = b - a, ac = c - a, ad = d - a;
  const P3 bc = c - b, bd = d - b, cd = d - c;
  // Outward (for positive orientation) face normals opposite a, b, c, d.
  const P3 n0 = bc.cross(bd), n1 = ad.cross(ac), n2 = ab.cross(ad), n3 = ac.cross(ab);
  const double v6 = -ab.dot(n1);
  const double l2 = (ab.squaredNorm() + ac.squaredNorm() + ad.squaredNorm() + bc.squaredNorm() + bd.squaredNorm() +
                     cd.squaredNorm()) /
                    6.0;
  if (l2 <= 0) return -2.0;
  // Mean ratio sqrt2 v6 / l2^1.5 > 1e-9 without the root: 2 v6^2 > 1e-18 l2^3.
  if (!(v6 > 0 && 2.0 * v6 * v6 > 1e-18 * l2 * l2 * l2)) return std::min(std::sqrt(2.0) * v6 / (l2 * std::sqrt(l2)), 0.0) - 1.0;
  const std::array<P3, 4> n = {n0, n1, n2, n3};
  std::array<double, 4> inv{};
  for (int i = 0; i < 4; ++i) {
    const double s = n[i].squaredNorm();
    if (!(s > 0)) return 0.0;  // a zero-area face: cosine 1
    inv[i] = 1.0 / s;
  }
  // The largest c|c| over the six edges, c = -n_i.n_j / (|n_i| |n_j|): no root, no acos.
  double best = -1.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      const double dd = -n[i].dot(n[j]);
      best = std::max(best, dd * std::abs(dd) * inv[i] * inv[j]);
    }
  return 1.0 - std::clamp(best, -1.0, 1.0);
}

double tet_search_rank_of_angle(double angle) { return angle_rank(angle); }

double tet_untangle_rank(const P3& a, const P3& b, const P3& c, const P3& d) {
  const P3 ab = b - a, ac = c - a, ad = d - a;
  const double v6 = -ab.dot(ad.cross(ac));  // tet_search_rank's v6, the same operations
  const double l2 = (ab.squaredNorm() + ac.squaredNorm() + ad.squaredNorm() + (c - b).squaredNorm() +
                     (d - b).squaredNorm() + (d - c).squaredNorm()) /
                    6.0;
  // Mean ratio rho = sqrt2 v6 / l2^1.5 above 1e-3 (2 v6^2 > 1e-6 l2^3). At an edge e between
  // faces i and j, sin(theta) = 6 V / (|e| h_i h_j) (h: the faces' heights over e), all three
  // lengths at most the longest edge L, and L^2 <= 6 l2: sin(theta) >= v6 / (6 l2)^1.5 =
  // rho / (6^1.5 sqrt2) > 4.8e-5 at every edge, so cos^2 < 1 - 2.3e-9 and tet_search_rank's
  // 1 - c|c| is above 1e-9, far beyond its rounding (and no face has zero area while l2 is far
  // above underflow).
  if (v6 > 0 && l2 > 1e-100 && 2.0 * v6 * v6 > 1e-6 * l2 * l2 * l2) return 1.0;
  return tet_search_rank(a, b, c, d);
}

double tet_search_quality(const P3& a, const P3& b, const P3& c, const P3& d) {
  const double r = mean_ratio_volume(a, b, c, d);
  if (!(r > 1e-9)) return std::min(r, 0.0) - 1.0;
  return std::acos(max_dihedral_cos(a, b, c, d));
}

double surface_alignment(const P3& a, const P3& b, const P3& c, const P3& ref) {
  const P3 n = (b - a).cross(c - a);
  const double len = n.norm() * ref.norm();
  return len > 0 ? n.dot(ref) / len : -1.0;
}

double tet_min_dihedral_deg(const P3& a, const P3& b, const P3& c, const P3& d) {
  return std::acos(max_dihedral_cos(a, b, c, d)) * 180.0 / pi;
}

TetOptimizeStats optimize_tets(Mesh<3>& mesh, std::vector<BoundaryLocation>& where, const TetOptimizeOptions& opt) {
  Optimizer o{mesh, where, opt, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, 0.0, 0.0};
  const std::size_t n = mesh.points.size();
  if (opt.incidence) opt.incidence->clear();  // filled at the end, where the lists were made
  for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
    MESH_ASSERT(mesh.solid.type[e] == ElemType::Tet4, "optimize_tets needs tetrahedra");
    MESH_ASSERT(mesh.solid.offset[e] == static_cast<std::int32_t>(4 * e), "element " << e << " is not at 4 e");
  }
  o.tets = {mesh.solid.node.data(), mesh.solid.size()};  // the connectivity does not change here
  if (opt.surface_normal && opt.project) {
    o.normal_slot.assign(n, -1);
    for (std::size_t v = 0; v < n && v < where.size(); ++v)
      if (where[v].patch >= 0) {
        o.normal_slot[v] = static_cast<std::int32_t>(o.normals.size());
        o.normals.push_back(opt.surface_normal(where[v]));
      }
    o.f_start.assign(n + 1, 0);
    for (std::size_t f = 0; f < mesh.interface.size(); ++f) {
      const VertexId* v = mesh.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
      if (mesh.interface.n_nodes_of(ElemId{static_cast<std::int32_t>(f)}) != 3) continue;
      o.faces.push_back({v[0].v, v[1].v, v[2].v});
      for (int k = 0; k < 3; ++k) ++o.f_start[v[k].v + 1];
    }
    for (std::size_t v = 0; v < n; ++v) o.f_start[v + 1] += o.f_start[v];
    o.f_incident.resize(o.f_start[n]);
    std::vector<std::int32_t> fill(o.f_start.begin(), o.f_start.end() - 1);
    for (std::size_t f = 0; f < o.faces.size(); ++f)
      for (std::int32_t v : o.faces[f]) o.f_incident[fill[v]++] = static_cast<std::int32_t>(f);
  }
  const auto count_folded = [&] {
    std::atomic<std::size_t> folded{0};
    for_each_range(o.faces.size(), opt.n_threads, [&](std::size_t begin, std::size_t end) {
      std::size_t k = 0;
      for (std::size_t f = begin; f < end; ++f)
        if (o.face_quality(static_cast<std::int32_t>(f), -1, P3::Zero(), P3::Zero()) < 0) ++k;
      folded += k;
    });
    return folded.load();
  };

  TetOptimizeStats st;
  // Inverted tetrahedra and the smallest dihedral angle, from the ranks (one acos).
  // (Not the angle with untangle_only and no ranks handed back: the positive ones are not ranked.)
  // Ranges on the threads, four running minima in each (one was a chain of dependent minsd:
  // 2.3 ms a call for 10^6 tetrahedra, two calls a pass, 66 untangling passes in elephant L4);
  // a count and a minimum, the same whatever the order.
  const auto measure = [&](std::size_t& inverted, double& min_deg) {
    std::atomic<std::size_t> n_inverted{0};
    std::mutex lowest;
    double lo = std::numeric_limits<double>::infinity();
    for_each_range(o.tet_q.size(), opt.n_threads, [&](std::size_t begin, std::size_t end) {
      std::size_t k = 0;
      double m[4];
      std::fill(m, m + 4, std::numeric_limits<double>::infinity());
      std::size_t i = begin;
      for (; i + 4 <= end; i += 4)
        for (int l = 0; l < 4; ++l) {
          const double q = o.tet_q[i + l];
          k += q < 0 ? 1 : 0;
          m[l] = std::min(m[l], q);
        }
      for (; i < end; ++i) k += o.tet_q[i] < 0 ? 1 : 0, m[0] = std::min(m[0], o.tet_q[i]);
      n_inverted += k;
      const std::lock_guard<std::mutex> hold(lowest);
      for (const double x : m) lo = std::min(lo, x);
    });
    const std::size_t inv = n_inverted.load();
    inverted = inv;
    min_deg = inv > 0 || (opt.untangle_only && !opt.ranks) ? 0.0
              : o.tet_q.empty()                                  ? 180.0
                                                                 : rank_angle(lo) * 180.0 / pi;
  };
  // Active nodes: those of a tetrahedron below the target; the set shrinks as nodes settle.
  const double target = opt.untangle_only ? 0.0 : opt.target_dihedral_deg * pi / 180.0;
  std::vector<std::uint8_t> active(n, 0);
  // The ranks handed in (the last pass's, at these points), else every tetrahedron ranked:
  // one such scan was 37 ms of sphere966 L6's pipeline, seven a run (three sweeps' passes,
  // three edge removal rounds, the untangling).
  const bool ranked = opt.ranks && opt.ranks->size() == o.tets.size();
  if (ranked)
    o.tet_q.swap(*opt.ranks);
  else
    o.tet_q.resize(o.tets.size());
  // Untangling looks at the tetrahedra at or below rank 0 only (relax returns at once from a
  // node whose tetrahedra are all above it; below it, the worst and the nearly worst are those
  // at or below 0, exact): the others start at rank 1 (tet_untangle_rank), unless the ranks go
  // back to the caller. Every such pass ranked all of them (elephant L4: 66 passes, 1.1 s).
  const bool untangle_ranks = opt.untangle_only && !opt.ranks;
  o.unranked = untangle_ranks;
  o.target_rank = angle_rank(target);
  o.tangent_rank = angle_rank(opt.tangent_below_deg * pi / 180.0);
  std::atomic<bool> some_active{false};
  for_each_range(o.tets.size(), opt.n_threads, [&](std::size_t begin, std::size_t end) {
    bool here = false;
    for (std::size_t i = begin; i < end; ++i) {
      const Tet& t = o.tets[i];
      const P3 &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]], &d = mesh.points[t[3]];
      const double q = ranked ? o.tet_q[i] : untangle_ranks ? tet_untangle_rank(a, b, c, d) : tet_search_rank(a, b, c, d);
      o.tet_q[i] = q;
      if (opt.untangle_only ? q <= 0 : q < o.target_rank) {
        here = true;
        for (std::int32_t v : t) mark(active[v], 1);  // another range may mark the same node
      }
    }
    if (here) some_active.store(true, std::memory_order_relaxed);
  });
  bool any_active = some_active.load();
  measure(st.inverted_before, st.min_dihedral_before_deg);
  st.folded_before = count_folded();
  if (st.folded_before > 0) {
    any_active = true;
    for (std::size_t f = 0; f < o.faces.size(); ++f)
      if (o.face_quality(static_cast<std::int32_t>(f), -1, P3::Zero(), P3::Zero()) < 0)
        for (std::int32_t v : o.faces[f]) active[v] = 1;
  }
  if (!any_active) {  // nothing below the target: one empty sweep, no node graph needed
    st.sweeps = opt.max_sweeps > 0 ? 1 : 0;
    st.inverted_after = st.inverted_before, st.min_dihedral_after_deg = st.min_dihedral_before_deg;
    st.folded_after = st.folded_before;
    if (opt.ranks) opt.ranks->swap(o.tet_q);
    return st;
  }
  if (opt.ranks) o.moved_tet.assign(o.tets.size(), 0);
  // Node -> tetrahedra only now: the untangling pass before smoothing usually finds nothing to
  // do (sphere966 L6: 0.07 s of lists for 1.5 M tetrahedra, none inverted).
  incidence_csr(
      n, o.tets.size(),
      [&](std::size_t t, auto&& f) {
        for (std::int32_t v : o.tets[t]) f(v);
      },
      opt.n_threads, o.start, o.incident);
  // stale[v]: v or a neighbour moved since v's last local search. A search that did not move
  // v, repeated with the same numbers, does not move it either: such nodes are skipped (the
  // moves, and so the mesh, are those of searching them again).
  // Smaller sets cost quality (issue 8, CLI, one thread, min dihedral deg; today sphere966 L4
  // 28.17, L5 27.67): waking the neighbours only after a move of more than 0.7% (3%) of the
  // node's mean edge: L4 28.01 (27.18), L5 27.11 (26.45); a move only if it gains 1e-4 in rank:
  // L5 27.40; 8 sweeps instead of 16: L4 27.47; from sweep 4 on, nodes within 1 (2, 5) deg of
  // the current minimum only: L4 26.84 (28.05, 28.17), L5 25.20 (25.66, 27.49). The last at
  // 5 deg in the 30-deg pass raised spool/anchor/fandisk L4 (15.03/13.33/13.28, CPU in
  // smoothing 3.0/6.3/1.6 s -> 2.1/3.2/1.1) but at 8 deg dropped anchor to 11.58: not kept.
  std::vector<std::uint8_t> stale(n, 1), next(n, 0);
  // Each sweep visits the active movable nodes in order; relax(v) reads and writes only v's
  // neighbourhood (its tetrahedra and interface triangles), so on several threads the sweep
  // visits v as soon as its lower neighbours are done (core/ordered_sweep.hpp) and moves the
  // nodes the serial sweep moves.
  // The neighbours for the sweep's order: those of v's tetrahedra (ascending, distinct), then
  // the nodes of v's interface triangles that are not among them (none where the triangles are
  // faces of the tetrahedra, as in the pipeline). Listed again, they made sweep_dag sort every
  // surface node's list, which comes ascending and distinct without them (sphere966 at 995,232
  // tetrahedra, two threads: the DAGs of a run 75-79 ms with them, 44-46 ms now).
  const auto for_neighbours = [&](std::int32_t v, auto&& visit) {
    const std::span<const std::int32_t> near = o.neighbours(v);
    for (const std::int32_t u : near) visit(u);
    if (o.f_start.empty()) return;
    for (std::int32_t k = o.f_start[v]; k < o.f_start[v + 1]; ++k)
      for (const std::int32_t u : o.faces[o.f_incident[k]])
        if (u != v && !std::binary_search(near.begin(), near.end(), u)) visit(u);
  };
  std::vector<Optimizer::Scratch> scratch(static_cast<std::size_t>(std::max(1, opt.n_threads)));
  // A sweep's nodes: the active movable ones, ascending. The next sweep's are those a move
  // woke (next[u] set), listed by the threads as they set them: few (1-6 k in an untangling
  // sweep) are sorted, many are found by a scan of next, as every sweep did (30 sweeps a pass,
  // 66 passes at elephant L4).
  std::vector<std::int32_t> nodes;
  for (std::size_t v = 0; v < n; ++v)
    if (active[v] && o.movable(static_cast<std::int32_t>(v))) nodes.push_back(static_cast<std::int32_t>(v));
  std::vector<std::uint8_t>().swap(active);
  for (int sweep = 0; sweep < opt.max_sweeps; ++sweep) {
    for (Optimizer::Scratch& sc : scratch) sc.moves = 0, sc.woken.clear();
    o.list_neighbours(nodes);
    const OrderedSweep order(nodes, n, opt.n_threads, for_neighbours);
    order.run([&](std::int32_t v, int t) {
      if (!stale[v]) return;
      stale[v] = 0;
      Optimizer::Scratch& sc = scratch[static_cast<std::size_t>(t)];
      if (!o.relax(v, sc)) return;
      ++sc.moves;
      // (Two threads may both list a node: the list is made unique.)
      const auto wake = [&](std::int32_t u) {
        if (std::atomic_ref<std::uint8_t>(next[u]).load(std::memory_order_relaxed)) return;
        mark(next[u], 1);
        sc.woken.push_back(u);
      };
      for (const std::int32_t u : o.neighbours(v)) wake(u), mark(stale[u], 1);
      wake(v), stale[v] = 1;
    });
    std::size_t moved = 0, woken = 0;
    for (const Optimizer::Scratch& sc : scratch) moved += sc.moves, woken += sc.woken.size();
    st.sweeps = sweep + 1;
    st.moves += moved;
    if (moved == 0) break;
    nodes.clear();
    if (woken <= n / 16) {
      for (const Optimizer::Scratch& sc : scratch) nodes.insert(nodes.end(), sc.woken.begin(), sc.woken.end());
      std::sort(nodes.begin(), nodes.end());
      nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      for (const std::int32_t v : nodes) next[v] = 0;
      nodes.erase(std::remove_if(nodes.begin(), nodes.end(), [&](std::int32_t v) { return !o.movable(v); }), nodes.end());
    } else {
      for (std::size_t v = 0; v < n; ++v)
        if (next[v] && o.movable(static_cast<std::int32_t>(v))) nodes.push_back(static_cast<std::int32_t>(v));
      std::fill(next.begin(), next.end(), 0);
    }
  }
  measure(st.inverted_after, st.min_dihedral_after_deg);
  st.folded_after = count_folded();
  if (opt.ranks) {
    for_each_range(o.tets.size(), opt.n_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        if (o.moved_tet[i]) {
          const Tet& t = o.tets[i];
          o.tet_q[i] = tet_search_rank(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]);
        }
    });
    opt.ranks->swap(o.tet_q);
  }
  if (opt.incidence) {
    opt.incidence->start = std::move(o.start);
    opt.incidence->tets = std::move(o.incident);
  }
  return st;
}

}  // namespace febemesh::dim3
