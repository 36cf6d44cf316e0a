#include "dim3/faults3d.hpp"

#include <algorithm>
#include <set>
#include <sstream>

#include "core/quality.hpp"
#include "core/validate.hpp"

namespace febemesh::dim3 {
namespace {

P3 centroid(const Mesh<3>& m, std::size_t e) {
  const ElemId id{static_cast<std::int32_t>(e)};
  const auto pts = element_points<3>(m.solid, id, m.points);
  P3 c = P3::Zero();
  for (int k = 0; k < pts.n; ++k) c += pts.p[k];
  return c / pts.n;
}

P3 face_centroid(const Mesh<3>& m, std::size_t f) {
  const VertexId* n = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
  return (m.points[n[0].v] + m.points[n[1].v] + m.points[n[2].v]) / 3.0;
}

}  // namespace

std::vector<Problem3> surface_contacts(const Mesh<3>& m, int n_threads) {
  std::vector<std::uint8_t> on_surface(m.points.size(), 0);
  for (const VertexId v : m.interface.node) on_surface[v.v] = 1;
  Mesh<3> part;
  std::vector<std::int32_t> local(m.points.size(), -1);  // node ids in `part`
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* v = m.solid.nodes(id);
    const int n = m.solid.n_nodes_of(id);
    if (std::none_of(v, v + n, [&](VertexId x) { return on_surface[x.v] != 0; })) continue;
    VertexId w[8];
    for (int k = 0; k < n; ++k) {
      if (local[v[k].v] < 0) local[v[k].v] = part.add_point(m.points[v[k].v]).v;
      w[k] = VertexId{local[v[k].v]};
    }
    part.solid.add(m.solid.type[e], w, n);
  }
  ValidateOptions<3> vo;
  vo.check_interface = false;
  vo.n_threads = n_threads;
  const ValidationReport v = validate(part, vo);
  std::vector<Problem3> out;
  if (v.hanging_nodes == 0 && v.duplicate_nodes == 0 && v.nonconforming_facets == 0) return out;
  for (const auto& site : v.sites)
    if (site.node >= 0) out.push_back({part.points[site.node], site.kind});
  return out;
}

std::string describe(const std::vector<Problem3>& problems) {
  std::ostringstream os;
  os.precision(6);
  const std::size_t shown = std::min<std::size_t>(problems.size(), 3);
  for (std::size_t k = 0; k < shown; ++k)
    os << (k ? "; " : "") << problems[k].what << " near (" << problems[k].where[0] << ", " << problems[k].where[1]
       << ", " << problems[k].where[2] << ")";
  if (problems.size() > shown) os << "; and " << problems.size() - shown << " more";
  return os.str();
}

void add_problems(const Mesh<3>& m, const std::vector<std::size_t>& bad, const std::vector<std::size_t>& folded,
                  const std::string& when, std::vector<Problem3>& out) {
  for (std::size_t e : bad) out.push_back({centroid(m, e), "an element is inverted" + when});
  for (std::size_t f : folded) out.push_back({face_centroid(m, f), "the surface mesh folds" + when});
}

std::vector<P3> fault_places(const Orthtree<3>& t, const OctantComplex& oc, const TetMesh& fe,
                             const std::vector<std::size_t>& bad, const std::vector<P3>& behind) {
  const std::size_t n_int = oc.interior.size();
  std::set<std::int32_t> cells;
  for (std::size_t e : bad) cells.insert(fe.cell[e]);
  std::vector<P3> out;
  for (std::int32_t c : cells) {
    if (static_cast<std::size_t>(c) < n_int) {
      out.push_back(geometry(t, t.leaf(oc.interior[c])).center());
    } else {
      const BoundaryOctant& b = oc.boundary[static_cast<std::size_t>(c) - n_int];
      P3 centre = P3::Zero();
      for (std::int32_t q : b.ring) centre += oc.points[q];
      out.push_back(centre / static_cast<double>(b.ring.size()));
    }
  }
  out.insert(out.end(), behind.begin(), behind.end());
  return out;
}

std::vector<P3> nodes_behind(const Orthtree<3>& t, const OctantComplex& oc, const Mesh<3>& m,
                             const std::vector<std::size_t>& bad, const std::vector<std::size_t>& folded) {
  const std::int32_t n_lat = oc.n_lattice(), n_pts = static_cast<std::int32_t>(oc.points.size());
  std::vector<std::uint8_t> mark(n_pts, 0);
  const auto add = [&](const Elements& elems, std::size_t e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* v = elems.nodes(id);
    for (int k = 0; k < elems.n_nodes_of(id); ++k)
      if (v[k].v < n_pts) mark[v[k].v] = 1;
  };
  for (std::size_t e : bad) add(m.solid, e);
  for (std::size_t f : folded) add(m.interface, f);
  std::vector<P3> out;
  for (std::int32_t q = 0; q < n_lat; ++q)
    if (mark[q] || (oc.projection[q] >= 0 && mark[oc.projection[q]])) out.push_back(position(t, oc.lattice.points[q]));
  return out;
}

}  // namespace febemesh::dim3
