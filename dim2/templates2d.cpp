#include "dim2/templates2d.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh::dim2 {
namespace {

using P2 = Point<2>;

double cross(const P2& a, const P2& b, const P2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/// Smallest angle of triangle abc in radians (0 if degenerate).
double min_angle(const P2& a, const P2& b, const P2& c) {
  const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
  if (la <= 0 || lb <= 0 || lc <= 0) return 0.0;
  auto ang = [](double opp, double s1, double s2) {
    return std::acos(std::clamp((s1 * s1 + s2 * s2 - opp * opp) / (2 * s1 * s2), -1.0, 1.0));
  };
  return std::min({ang(la, lb, lc), ang(lb, lc, la), ang(lc, la, lb)});
}

VertexId vid(std::int32_t i) { return VertexId{i}; }

struct Builder {
  FeBeMesh out;
  void tri(std::int32_t a, std::int32_t b, std::int32_t c, std::uint8_t level, bool bnd) {
    out.mesh.solid.add(ElemType::Tri3, {vid(a), vid(b), vid(c)});
    out.mesh.level.push_back(level);
    out.mesh.from_boundary_cell.push_back(bnd ? 1 : 0);
  }
  void quad(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d, std::uint8_t level, bool bnd) {
    out.mesh.solid.add(ElemType::Quad4, {vid(a), vid(b), vid(c), vid(d)});
    out.mesh.level.push_back(level);
    out.mesh.from_boundary_cell.push_back(bnd ? 1 : 0);
  }
  std::int32_t point(const P2& p, const BoundaryLocation& w = {}) {
    out.mesh.add_point(p);
    const auto id = static_cast<std::int32_t>(out.mesh.points.size() - 1);
    if (w.patch >= 0) out.where.add(id, w);
    return id;
  }
  const P2& at(std::int32_t i) const { return out.mesh.points[i]; }
};

/// What the templates make of one interior quadrant.
struct QuadrantCount {
  std::size_t elements = 0, element_nodes = 0, points = 0;
  QuadrantCount& operator+=(const QuadrantCount& o) {
    elements += o.elements, element_nodes += o.element_nodes, points += o.points;
    return *this;
  }
};
QuadrantCount interior_count(const InteriorQuadrant& q, ElementKind kind) {
  if (q.has_hanging()) return {q.ring.size(), 3 * q.ring.size(), 1};
  if (kind == ElementKind::Tri) return {2, 6, 0};
  return {1, 4, 0};
}

/// A Builder over arrays sized in advance: writes the elements and points of a run of interior
/// quadrants at the places they have in the serial order, so that runs can be written at once.
struct Slots {
  Mesh<2>& m;
  std::size_t e, k, p;  // the next element, element-node slot and point
  void element(ElemType t, std::initializer_list<std::int32_t> v, std::uint8_t level) {
    m.solid.type[e] = t;
    for (const std::int32_t x : v) m.solid.node[k++] = vid(x);
    m.solid.offset[e + 1] = static_cast<std::int32_t>(k);
    m.level[e] = level;
    m.from_boundary_cell[e] = 0;
    ++e;
  }
  void tri(std::int32_t a, std::int32_t b, std::int32_t c, std::uint8_t level, bool) {
    element(ElemType::Tri3, {a, b, c}, level);
  }
  void quad(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d, std::uint8_t level, bool) {
    element(ElemType::Quad4, {a, b, c, d}, level);
  }
  std::int32_t point(const P2& x) {
    m.points[p] = x;
    return static_cast<std::int32_t>(p++);
  }
  const P2& at(std::int32_t i) const { return m.points[i]; }
};

/// Whether quad abcd (CCW) splits across a-c: the diagonal with the better smallest angle;
/// ties go to a-c so the result is deterministic.
bool splits_ac(const P2& pa, const P2& pb, const P2& pc, const P2& pd) {
  double q_ac = std::min(min_angle(pa, pb, pc), min_angle(pa, pc, pd));
  if (cross(pa, pb, pc) <= 0 || cross(pa, pc, pd) <= 0) q_ac = -1;
  double q_bd = std::min(min_angle(pa, pb, pd), min_angle(pb, pc, pd));
  if (cross(pa, pb, pd) <= 0 || cross(pb, pc, pd) <= 0) q_bd = -1;
  return q_ac >= q_bd;
}

/// splits_ac remembered by the bits of the quad's four sides and two diagonals (b - a, c - b,
/// d - c, a - d, c - a, d - b): min_angle and cross read the points only through these
/// differences (x - y is exactly -(y - x)), so equal bits give the same choice. The interior
/// quadrants of a level are equal squares up to the rounding of their coordinates: a few keys
/// serve most of the mesh, whose 12 sqrt and 12 acos per quad were 4% of the bench's
/// instructions (flange level 9). Direct-mapped; a miss computes and replaces.
class SplitMemo {
 public:
  SplitMemo() : table_(n_slots) {}
  bool splits_ac(const P2& pa, const P2& pb, const P2& pc, const P2& pd) {
    const double diff[12] = {pb[0] - pa[0], pb[1] - pa[1], pc[0] - pb[0], pc[1] - pb[1], pd[0] - pc[0], pd[1] - pc[1],
                             pa[0] - pd[0], pa[1] - pd[1], pc[0] - pa[0], pc[1] - pa[1], pd[0] - pb[0], pd[1] - pb[1]};
    Key key;
    std::memcpy(key.data(), diff, sizeof diff);
    std::uint64_t h = 0;
    for (const std::uint64_t w : key) h = (h ^ w ^ (w >> 31)) * 0x9E3779B97F4A7C15ull;
    Entry& slot = table_[h >> (64 - slot_bits)];
    if (!slot.used || slot.key != key) slot = {key, dim2::splits_ac(pa, pb, pc, pd), true};
    return slot.ac;
  }

 private:
  using Key = std::array<std::uint64_t, 12>;
  struct Entry {
    Key key{};
    bool ac = false, used = false;
  };
  static constexpr int slot_bits = 8;
  static constexpr std::size_t n_slots = std::size_t(1) << slot_bits;
  std::vector<Entry> table_;
};

/// Two triangles of quad abcd (CCW) across the diagonal splits_ac chooses.
template <class Sink>
void split_quad(Sink& b, SplitMemo& memo, std::int32_t a, std::int32_t c1, std::int32_t c, std::int32_t d,
                std::uint8_t level, bool bnd) {
  if (memo.splits_ac(b.at(a), b.at(c1), b.at(c), b.at(d))) {
    b.tri(a, c1, c, level, bnd);
    b.tri(a, c, d, level, bnd);
  } else {
    b.tri(a, c1, d, level, bnd);
    b.tri(c1, c, d, level, bnd);
  }
}

/// A convex-enough polygon (CCW) as the fan, from one of its vertices, whose triangles are all
/// positive with the best smallest angle (ties: the first vertex).
void best_fan(Builder& b, const std::vector<std::int32_t>& poly, std::uint8_t level, bool bnd) {
  const std::size_t n = poly.size();
  std::size_t best = 0;
  double best_q = -2.0;
  for (std::size_t a = 0; a < n; ++a) {
    double q = 4.0;
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const P2 &p0 = b.at(poly[a]), &p1 = b.at(poly[(a + k) % n]), &p2 = b.at(poly[(a + k + 1) % n]);
      q = std::min(q, cross(p0, p1, p2) > 0 ? min_angle(p0, p1, p2) : -1.0);
    }
    if (q > best_q) best_q = q, best = a;
  }
  for (std::size_t k = 1; k + 1 < n; ++k)
    b.tri(poly[best], poly[(best + k) % n], poly[(best + k + 1) % n], level, bnd);
}

/// The templates of qc.interior[begin, end) into b.
void interior_templates(Slots& b, const QuadrantComplex& qc, ElementKind kind, std::size_t begin, std::size_t end) {
  SplitMemo memo;
  for (std::size_t i = begin; i < end; ++i) {
    const InteriorQuadrant& q = qc.interior[i];
    const auto& r = q.ring;
    const std::int32_t ll = r[q.corner_slot[0]], lr = r[q.corner_slot[1]], ur = r[q.corner_slot[2]],
                       ul = r[q.corner_slot[3]];
    if (!q.has_hanging()) {
      if (kind == ElementKind::Tri)
        split_quad(b, memo, ll, lr, ur, ul, q.level, false);
      else
        b.quad(ll, lr, ur, ul, q.level, false);
      continue;
    }
    const P2 centre = 0.25 * (b.at(ll) + b.at(lr) + b.at(ur) + b.at(ul));
    const std::int32_t c = b.point(centre);
    for (std::size_t k = 0; k < r.size(); ++k) b.tri(c, r[k], r[(k + 1) % r.size()], q.level, false);
  }
}

/// The interior quadrants' templates on n_threads threads, appended to out's elements and points
/// (which hold the complex's nodes only): each run of quadrants counts what it makes, and writes
/// it where the serial loop would have put it, so any thread count gives the same mesh.
void interior_templates(FeBeMesh& out, const QuadrantComplex& qc, ElementKind kind, int n_threads) {
  const std::size_t n = qc.interior.size();
  const std::size_t run = chunk_size(n, n_threads, 4096);
  Mesh<2>& m = out.mesh;
  const std::vector<QuadrantCount> start =
      chunk_starts(n, run, n_threads, QuadrantCount{m.solid.size(), m.solid.node.size(), m.points.size()},
                   [&](std::size_t begin, std::size_t end) {
                     QuadrantCount c;
                     for (std::size_t i = begin; i < end; ++i) c += interior_count(qc.interior[i], kind);
                     return c;
                   });
  const QuadrantCount& total = start.back();
  m.solid.type.resize(total.elements);
  m.solid.offset.resize(total.elements + 1);
  m.solid.node.resize(total.element_nodes);
  m.level.resize(total.elements);
  m.from_boundary_cell.resize(total.elements);
  m.points.resize(total.points);  // (the templates' own points are not on the curve)
  for_each_chunk(n, run, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    Slots slots{m, start[c].elements, start[c].element_nodes, start[c].points};
    interior_templates(slots, qc, kind, begin, end);
  });
}

void boundary_templates(Builder& b, const QuadrantComplex& qc, ElementKind kind) {
  SplitMemo memo;
  for (const BoundaryQuadrant& q : qc.boundary) {
    const auto& n = q.node;
    if (q.corner >= 0) {
      best_fan(b, q.polygon(), q.level, true);
      b.out.mesh.interface.add(ElemType::Line2, {vid(n[2]), vid(q.corner)});
      b.out.mesh.interface.add(ElemType::Line2, {vid(q.corner), vid(n[3])});
      continue;
    }
    if (q.is_triangle()) {
      b.tri(n[0], n[1], n[2], q.level, true);
    } else if (kind == ElementKind::Tri) {
      split_quad(b, memo, n[0], n[1], n[2], n[3], q.level, true);
    } else {
      b.quad(n[0], n[1], n[2], n[3], q.level, true);
    }
    if (n[2] != n[3]) b.out.mesh.interface.add(ElemType::Line2, {vid(n[2]), vid(n[3])});
  }
}

}  // namespace

const char* name(ElementKind k) {
  switch (k) {
    case ElementKind::Tri: return "tri";
    case ElementKind::Quad: return "quad";
    case ElementKind::Mixed: return "mixed";
  }
  return "?";
}

ElementKind element_kind_from(const std::string& s) {
  if (s == "tri") return ElementKind::Tri;
  if (s == "quad") return ElementKind::Quad;
  if (s == "mixed") return ElementKind::Mixed;
  throw std::invalid_argument("element kind must be tri, quad or mixed, got '" + s + "'");
}

FeBeMesh split_to_quads(const FeBeMesh& in, const CurveMidpoint& midpoint) {
  Builder b;
  b.out.mesh.points = in.mesh.points;
  b.out.where = in.where;
  std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> mid;
  std::map<std::pair<std::int32_t, std::int32_t>, bool> on_curve;
  for (std::size_t e = 0; e < in.mesh.interface.size(); ++e) {
    const VertexId* v = in.mesh.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    on_curve[{std::min(v[0].v, v[1].v), std::max(v[0].v, v[1].v)}] = true;
  }
  auto edge_mid = [&](std::int32_t a, std::int32_t c) {
    const std::pair<std::int32_t, std::int32_t> key{std::min(a, c), std::max(a, c)};
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    std::int32_t m;
    if (on_curve.count(key)) {
      auto [p, w] = midpoint(b.out.where[a], b.out.where[c]);
      m = b.point(p, w);
    } else {
      m = b.point(0.5 * (b.at(a) + b.at(c)));
    }
    mid.emplace(key, m);
    return m;
  };
  for (std::size_t e = 0; e < in.mesh.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* v = in.mesh.solid.nodes(id);
    const int n = in.mesh.solid.n_nodes_of(id);
    P2 centre = P2::Zero();
    for (int k = 0; k < n; ++k) centre += b.at(v[k].v);
    const std::int32_t c = b.point(centre / n);
    for (int k = 0; k < n; ++k) {
      const std::int32_t prev = v[(k + n - 1) % n].v, cur = v[k].v, next = v[(k + 1) % n].v;
      b.quad(cur, edge_mid(cur, next), c, edge_mid(prev, cur), in.mesh.level[e], in.mesh.from_boundary_cell[e]);
    }
  }
  for (std::size_t e = 0; e < in.mesh.interface.size(); ++e) {
    const VertexId* v = in.mesh.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    const std::int32_t m = edge_mid(v[0].v, v[1].v);
    b.out.mesh.interface.add(ElemType::Line2, {v[0], vid(m)});
    b.out.mesh.interface.add(ElemType::Line2, {vid(m), v[1]});
  }
  return std::move(b.out);
}

/// Sizes of the mesh the templates make of qc (capacity reserved up front: growing the arrays
/// by doubling held up to three times their size at the run's memory peak).
struct TemplateCounts {
  std::size_t elements = 0, element_nodes = 0, points = 0, lines = 0;
};

TemplateCounts count_templates(const QuadrantComplex& qc, ElementKind kind) {
  TemplateCounts n;
  n.points = qc.points.size();
  auto tris = [&](std::size_t k) { n.elements += k, n.element_nodes += 3 * k; };
  for (const InteriorQuadrant& q : qc.interior) {
    const QuadrantCount c = interior_count(q, kind);
    n.elements += c.elements, n.element_nodes += c.element_nodes, n.points += c.points;
  }
  for (const BoundaryQuadrant& q : qc.boundary) {
    if (q.corner >= 0) {
      tris(q.polygon().size() - 2);
      n.lines += 2;
      continue;
    }
    if (q.is_triangle()) tris(1);
    else if (kind == ElementKind::Tri) tris(2);
    else ++n.elements, n.element_nodes += 4;
    n.lines += q.node[2] != q.node[3];
  }
  return n;
}

void reserve(FeBeMesh& out, const TemplateCounts& n, int n_threads) {
  Mesh<2>& m = out.mesh;
  reserve_huge(m.points, n.points, n_threads);
  reserve_huge(m.solid.type, n.elements, n_threads);
  reserve_huge(m.solid.offset, n.elements + 1, n_threads);
  reserve_huge(m.solid.node, n.element_nodes, n_threads);
  reserve_huge(m.level, n.elements, n_threads);
  reserve_huge(m.from_boundary_cell, n.elements, n_threads);
  m.interface.type.reserve(n.lines);
  m.interface.offset.reserve(n.lines + 1);
  m.interface.node.reserve(2 * n.lines);
}

FeBeMesh fe_be_mesh(const QuadrantComplex& qc, ElementKind kind, const CurveMidpoint& midpoint, int n_threads) {
  Builder b;
  const ElementKind base = kind == ElementKind::Tri ? ElementKind::Tri : ElementKind::Mixed;
  reserve(b.out, count_templates(qc, base), n_threads);
  b.out.mesh.points.assign(qc.points.begin(), qc.points.end());
  std::size_t n_located = 0;
  for (const NodeKind k : qc.kind) n_located += k == NodeKind::Boundary ? 1 : 0;
  b.out.where.reserve(n_located);
  for (std::size_t i = 0; i < qc.points.size(); ++i)
    if (qc.kind[i] == NodeKind::Boundary && qc.where(static_cast<std::int32_t>(i)).patch >= 0)
      b.out.where.add(static_cast<std::int32_t>(i), qc.where(static_cast<std::int32_t>(i)));
  interior_templates(b.out, qc, base, n_threads);
  boundary_templates(b, qc, base);
  if (kind == ElementKind::Quad) return split_to_quads(b.out, midpoint);
  return std::move(b.out);
}

}  // namespace febemesh::dim2
