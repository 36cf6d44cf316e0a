#include "dim3/planar_frame.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

namespace febemesh::dim3 {

namespace {

/// n or -n, whichever has its largest component positive: one direction for both sides of a plate.
P3 canonical(const P3& n) {
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  return n[k] < 0 ? P3(-n) : n;
}

/// The frame's rows permuted and signed (a rotation still) to be nearest the given axes: the
/// largest trace; the first such in a fixed order on ties.
Eigen::Matrix3d nearest_given(const Eigen::Matrix3d& r) {
  static constexpr std::array<std::array<int, 3>, 6> perms{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  Eigen::Matrix3d best = r;
  double best_trace = -10.0;
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d m;
      for (int k = 0; k < 3; ++k) m.row(k) = ((signs >> k) & 1 ? -1.0 : 1.0) * r.row(p[k]);
      if (!(m.determinant() > 0)) continue;
      if (m.trace() > best_trace + 1e-12) best_trace = m.trace(), best = m;
    }
  return best;
}

}  // namespace

PlanarFrame planar_frame(const Surface& s, double tolerance_deg, double min_gain) {
  const double tol = tolerance_deg * std::numbers::pi / 180.0;
  const double cos_tol = std::cos(tol), sin_tol = std::sin(tol);
  std::vector<P3> normals;
  std::vector<double> areas;
  normals.reserve(s.triangles().size());
  areas.reserve(s.triangles().size());
  double total = 0.0;
  for (const Triangle& t : s.triangles()) {
    const P3 a = s.vertex(t[0]), b = s.vertex(t[1]), c = s.vertex(t[2]);
    const P3 cross = (b - a).cross(c - a);
    const double len = cross.norm();
    if (!(len > 0)) continue;
    normals.push_back(cross / len);
    areas.push_back(0.5 * len);
    total += 0.5 * len;
  }
  PlanarFrame f;
  if (!(total > 0)) return f;
  const auto share = [&](const Eigen::Matrix3d& r) {
    double on = 0.0;
    for (std::size_t i = 0; i < normals.size(); ++i)
      if ((r * normals[i]).cwiseAbs().maxCoeff() >= cos_tol) on += areas[i];
    return on / total;
  };
  f.share_given = f.share_frame = share(Eigen::Matrix3d::Identity());

  // Groups of about the same normal: cells of side sin(tolerance) of the canonical normal (a
  // plane's triangles share one normal, so one cell holds the plane).
  struct Group {
    double area = 0.0;
    P3 sum = P3::Zero();
  };
  std::map<std::array<long, 3>, Group> cells;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const P3 c = canonical(normals[i]);
    const std::array<long, 3> key{static_cast<long>(std::floor(c.x() / sin_tol)),
                                  static_cast<long>(std::floor(c.y() / sin_tol)),
                                  static_cast<long>(std::floor(c.z() / sin_tol))};
    Group& g = cells[key];
    g.area += areas[i];
    g.sum += areas[i] * c;
  }
  std::vector<std::pair<double, P3>> groups;
  for (const auto& [key, g] : cells)
    if (g.sum.norm() > 0) groups.emplace_back(g.area, g.sum.normalized());
  std::stable_sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  if (groups.size() > 12) groups.resize(12);

  double best = f.share_given;
  Eigen::Matrix3d best_frame = Eigen::Matrix3d::Identity();
  // The frame with axis a and a second axis along b made square to a.
  const auto consider = [&](const P3& a, const P3& b) {
    const P3 e2 = (b - a.dot(b) * a).normalized();
    Eigen::Matrix3d r;
    r.row(0) = a.transpose();
    r.row(1) = e2.transpose();
    r.row(2) = a.cross(e2).transpose();
    r = nearest_given(r);
    const double sc = share(r);
    if (sc > best + 1e-12) best = sc, best_frame = r;
  };
  for (std::size_t i = 0; i < groups.size(); ++i)
    for (std::size_t j = i + 1; j < groups.size(); ++j)
      if (std::abs(groups[i].second.dot(groups[j].second)) <= sin_tol) consider(groups[i].second, groups[j].second);
  // One family of planes alone (a spool's flanges: the rest is turned about their axis): the
  // second axis from the given axis farthest from square to it.
  for (const auto& [area, a] : groups) {
    int k = 0;
    a.cwiseAbs().minCoeff(&k);
    consider(a, P3::Unit(k));
  }
  if (best >= f.share_given + min_gain) {
    f.to_frame = best_frame;
    f.turned = true;
    f.share_frame = best;
  }
  return f;
}

Surface turned_surface(const Surface& s, const Eigen::Matrix3d& to_frame) {
  TriangleSoup soup;
  soup.vertices.reserve(s.vertices().size());
  for (const P3& v : s.vertices()) soup.vertices.push_back(to_frame * v);
  soup.triangles = s.triangles();
  return Surface(std::move(soup));
}

}  // namespace febemesh::dim3
