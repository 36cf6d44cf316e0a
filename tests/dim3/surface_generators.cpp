// Random closed surfaces for the 3D property suite; surface_generators.hpp says why each kind
// is valid and how it shrinks.

#include "surface_generators.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

namespace febemesh::test {

using dim3::P3;
using dim3::Triangle;
using dim3::TriangleSoup;

namespace {

constexpr double pi = 3.14159265358979323846;

/// A value that shrinks towards 0 from either side: magnitude in [0, hi], then a sign.
int signed_small(int hi) {
  const int m = *rc::gen::inRange(0, hi + 1);
  return m == 0 ? 0 : (*rc::gen::inRange(0, 2) == 0 ? m : -m);
}

// ---- sphere ----

TriangleSoup icosphere(int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleSoup s;
  for (const P3& p : {P3(-1, t, 0), P3(1, t, 0), P3(-1, -t, 0), P3(1, -t, 0), P3(0, -1, t), P3(0, 1, t),
                      P3(0, -1, -t), P3(0, 1, -t), P3(t, 0, -1), P3(t, 0, 1), P3(-t, 0, -1), P3(-t, 0, 1)})
    s.vertices.push_back(p.normalized());
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint;  // ordered: vertex numbering is deterministic
    auto mid = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      s.vertices.push_back((s.vertices[a] + s.vertices[b]).normalized());
      const int v = static_cast<int>(s.vertices.size()) - 1;
      midpoint.emplace(key, v);
      return v;
    };
    std::vector<Triangle> next;
    for (const Triangle& tr : s.triangles) {
      const int ab = mid(tr[0], tr[1]), bc = mid(tr[1], tr[2]), ca = mid(tr[2], tr[0]);
      next.push_back({tr[0], ab, ca});
      next.push_back({tr[1], bc, ab});
      next.push_back({tr[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    s.triangles = std::move(next);
  }
  return s;
}

/// The radial perturbation's coefficients, scaled so that sum |c_k| <= max_perturbation.
std::array<double, 9> perturbation(const std::array<int, 9>& h) {
  std::array<double, 9> c{};
  double sum = 0.0;
  for (int k = 0; k < 9; ++k) {
    c[k] = 0.04 * h[k];
    sum += std::abs(c[k]);
  }
  if (sum > max_perturbation)
    for (double& v : c) v *= max_perturbation / sum;
  return c;
}

/// 1 + p(u) for a unit vector u; every basis function is bounded by 1 on the unit sphere.
double radius(const P3& u, const std::array<double, 9>& c) {
  const double x = u.x(), y = u.y(), z = u.z();
  const double f[9] = {x, y, z, 2 * x * y, 2 * y * z, 2 * z * x, x * x - y * y, (3 * z * z - 1) / 2,
                       x * x * x - 3 * x * y * y};
  double r = 1.0;
  for (int k = 0; k < 9; ++k) r += c[k] * f[k];
  return r;
}

TriangleSoup sphere_soup(const SurfaceSpec& spec) {
  TriangleSoup s = icosphere(spec.subdivisions);
  const std::array<double, 9> c = perturbation(spec.harmonics);
  for (P3& p : s.vertices) p *= radius(p, c);
  return s;
}

// ---- torus ----

double minor_radius(const SurfaceSpec& spec) { return 0.5 - 0.05 * spec.minor_step; }

TriangleSoup torus_soup(const SurfaceSpec& spec) {
  const int n = spec.major_segments, m = spec.minor_segments;
  const double r = minor_radius(spec);
  TriangleSoup s;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * pi * i / n;
    for (int j = 0; j < m; ++j) {
      const double b = 2 * pi * j / m;
      const double rho = 1.0 + r * std::cos(b);
      s.vertices.emplace_back(rho * std::cos(a), rho * std::sin(a), r * std::sin(b));
    }
  }
  auto id = [&](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      // (i, j) -> (i+1, j) -> (i+1, j+1) -> (i, j+1) runs counter-clockwise seen from outside.
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return s;
}

// ---- voxels ----

struct Grid {
  int g;
  std::vector<char> filled;  ///< per cell
  bool at(int x, int y, int z) const {
    if (x < 0 || y < 0 || z < 0 || x >= g || y >= g || z >= g) return false;
    return filled[index(x, y, z)] != 0;
  }
  int index(int x, int y, int z) const { return x + g * (y + g * z); }
  bool inside(int x, int y, int z) const { return x >= 0 && y >= 0 && z >= 0 && x < g && y < g && z < g; }
};

/// Face-connected components of the cells in block (x0..x0+1)^3 with state `want`, counting
/// cells outside the grid as empty; true if they form one component (or none).
bool block_connected(const Grid& gr, int x0, int y0, int z0, bool want) {
  std::array<bool, 8> in{};
  int count = 0, first = -1;
  for (int k = 0; k < 8; ++k) {
    in[k] = gr.at(x0 + (k & 1), y0 + ((k >> 1) & 1), z0 + ((k >> 2) & 1)) == want;
    if (in[k]) {
      ++count;
      if (first < 0) first = k;
    }
  }
  if (count == 0) return true;
  std::array<bool, 8> seen{};
  std::vector<int> stack{first};
  seen[first] = true;
  int reached = 1;
  while (!stack.empty()) {
    const int k = stack.back();
    stack.pop_back();
    for (int bit : {1, 2, 4}) {
      const int j = k ^ bit;  // face neighbour inside the block
      if (in[j] && !seen[j]) {
        seen[j] = true;
        ++reached;
        stack.push_back(j);
      }
    }
  }
  return reached == count;
}

/// Fills the empty cells not reachable from outside the grid through empty cells.
void fill_cavities(Grid& gr) {
  const int g = gr.g, p = g + 2;  // padded grid: a ring of outside cells
  std::vector<char> outside(p * p * p, 0);
  std::vector<std::array<int, 3>> stack{{-1, -1, -1}};
  outside[0] = 1;
  while (!stack.empty()) {
    const auto [x, y, z] = stack.back();
    stack.pop_back();
    for (int d = 0; d < 6; ++d) {
      const int nx = x + (d == 0) - (d == 1), ny = y + (d == 2) - (d == 3), nz = z + (d == 4) - (d == 5);
      if (nx < -1 || ny < -1 || nz < -1 || nx > g || ny > g || nz > g) continue;
      const int k = (nx + 1) + p * ((ny + 1) + p * (nz + 1));
      if (outside[k] || gr.at(nx, ny, nz)) continue;
      outside[k] = 1;
      stack.push_back({nx, ny, nz});
    }
  }
  for (int z = 0; z < g; ++z)
    for (int y = 0; y < g; ++y)
      for (int x = 0; x < g; ++x)
        if (!outside[(x + 1) + p * ((y + 1) + p * (z + 1))]) gr.filled[gr.index(x, y, z)] = 1;
}

/// The first lattice vertex (block origin) whose 2x2x2 block is not a manifold neighbourhood,
/// and the smallest empty in-grid cell of it; -1 if every block is fine. A diagonal pair around
/// an edge shows up as a disconnected block at both ends of the edge.
int first_fix(const Grid& gr) {
  for (int z = -1; z < gr.g; ++z)
    for (int y = -1; y < gr.g; ++y)
      for (int x = -1; x < gr.g; ++x) {
        if (block_connected(gr, x, y, z, true) && block_connected(gr, x, y, z, false)) continue;
        for (int k = 0; k < 8; ++k) {
          const int cx = x + (k & 1), cy = y + ((k >> 1) & 1), cz = z + ((k >> 2) & 1);
          if (gr.inside(cx, cy, cz) && !gr.at(cx, cy, cz)) return gr.index(cx, cy, cz);
        }
      }
  return -1;
}

void keep_first_component(Grid& gr) {
  const auto it = std::find(gr.filled.begin(), gr.filled.end(), 1);
  if (it == gr.filled.end()) return;
  std::vector<char> keep(gr.filled.size(), 0);
  std::vector<int> stack{static_cast<int>(it - gr.filled.begin())};
  keep[stack[0]] = 1;
  const int g = gr.g;
  while (!stack.empty()) {
    const int c = stack.back();
    stack.pop_back();
    const int x = c % g, y = (c / g) % g, z = c / (g * g);
    for (int d = 0; d < 6; ++d) {
      const int nx = x + (d == 0) - (d == 1), ny = y + (d == 2) - (d == 3), nz = z + (d == 4) - (d == 5);
      if (!gr.at(nx, ny, nz)) continue;
      const int k = gr.index(nx, ny, nz);
      if (keep[k]) continue;
      keep[k] = 1;
      stack.push_back(k);
    }
  }
  gr.filled = keep;
}

TriangleSoup voxel_soup(const SurfaceSpec& spec) {
  const int g = spec.grid, l = g + 1;  // lattice vertices per side
  Grid gr{g, std::vector<char>(g * g * g, 0)};
  for (int c : spec.cells) gr.filled[c] = 1;
  std::vector<int> lattice_id(l * l * l, -1);
  TriangleSoup s;
  const double h = 2.0 / g;  // the grid spans [-1, 1]^3
  auto vertex = [&](int x, int y, int z) {
    int& id = lattice_id[x + l * (y + l * z)];
    if (id < 0) {
      id = static_cast<int>(s.vertices.size());
      s.vertices.emplace_back(-1.0 + h * x, -1.0 + h * y, -1.0 + h * z);
    }
    return id;
  };
  for (int z = 0; z < g; ++z)
    for (int y = 0; y < g; ++y)
      for (int x = 0; x < g; ++x) {
        if (!gr.at(x, y, z)) continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side = 0; side < 2; ++side) {
            std::array<int, 3> n{x, y, z};
            n[axis] += side == 0 ? -1 : 1;
            if (gr.at(n[0], n[1], n[2])) continue;
            // The face's corners: the cell's corner on `side` along `axis`, the other two axes
            // u, v running 0..1, ordered counter-clockwise seen from outside.
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::array<int, 4> q{};
            const int corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int k = 0; k < 4; ++k) {
              std::array<int, 3> p{x, y, z};
              p[axis] += side;
              p[u] += corners[k][0];
              p[v] += corners[k][1];
              q[k] = vertex(p[0], p[1], p[2]);
            }
            // (u, v, axis) is right-handed, so (0,0),(1,0),(1,1),(0,1) faces +axis.
            if (side == 0) std::swap(q[1], q[3]);
            s.triangles.push_back({q[0], q[1], q[2]});
            s.triangles.push_back({q[0], q[2], q[3]});
          }
      }
  return s;
}

P3 apply_pose(const Pose& pose, const P3& p) {
  const Eigen::Matrix3d rot = (Eigen::AngleAxisd(pose.degrees[0] * pi / 180, P3::UnitZ()) *
                               Eigen::AngleAxisd(pose.degrees[1] * pi / 180, P3::UnitY()) *
                               Eigen::AngleAxisd(pose.degrees[2] * pi / 180, P3::UnitX()))
                                  .toRotationMatrix();
  const double scale = std::exp2(pose.scale_quarters / 4.0);
  return scale * (rot * p) + 0.1 * P3(pose.shift[0], pose.shift[1], pose.shift[2]);
}

}  // namespace

const char* name(ShapeKind k) {
  switch (k) {
    case ShapeKind::Sphere: return "sphere";
    case ShapeKind::Torus: return "torus";
    case ShapeKind::Voxels: return "voxels";
  }
  return "?";
}

std::vector<int> manifold_voxels(int grid, std::vector<int> cells) {
  Grid gr{grid, std::vector<char>(grid * grid * grid, 0)};
  for (int c : cells) gr.filled[c] = 1;
  if (std::find(gr.filled.begin(), gr.filled.end(), 1) == gr.filled.end()) gr.filled[0] = 1;
  // Each round adds one cell, so this ends (a full grid is a box). Components of the result
  // touch nowhere and none lies in another's cavity, so keeping one keeps a manifold.
  for (;;) {
    fill_cavities(gr);
    const int c = first_fix(gr);
    if (c < 0) break;
    gr.filled[c] = 1;
  }
  keep_first_component(gr);
  std::vector<int> out;
  for (int c = 0; c < grid * grid * grid; ++c)
    if (gr.filled[c]) out.push_back(c);
  return out;
}

TriangleSoup to_soup(const SurfaceSpec& spec) {
  TriangleSoup s = spec.kind == ShapeKind::Sphere  ? sphere_soup(spec)
                   : spec.kind == ShapeKind::Torus ? torus_soup(spec)
                                                   : voxel_soup(spec);
  for (P3& p : s.vertices) p = apply_pose(spec.pose, p);
  return s;
}

dim3::Surface to_surface(const SurfaceSpec& spec) { return dim3::Surface(to_soup(spec)); }

int expected_euler(const SurfaceSpec& spec) {
  if (spec.kind == ShapeKind::Sphere) return 2;
  if (spec.kind == ShapeKind::Torus) return 0;
  return to_surface(spec).euler_characteristic();
}

double exact_volume(const SurfaceSpec& spec) {
  if (spec.kind != ShapeKind::Voxels) return 0.0;
  const double h = 2.0 / spec.grid * std::exp2(spec.pose.scale_quarters / 4.0);
  return static_cast<double>(spec.cells.size()) * h * h * h;
}

std::string describe(const SurfaceSpec& spec) {
  std::ostringstream os;
  os << name(spec.kind);
  if (spec.kind == ShapeKind::Sphere) {
    os << " subdivisions " << spec.subdivisions << " harmonics";
    for (int h : spec.harmonics) os << ' ' << h;
  } else if (spec.kind == ShapeKind::Torus) {
    os << " r " << minor_radius(spec) << " segments " << spec.major_segments << "x" << spec.minor_segments;
  } else {
    os << " grid " << spec.grid << " cells";
    for (int c : spec.cells) os << ' ' << c;
  }
  os << " rotation " << spec.pose.degrees[0] << ' ' << spec.pose.degrees[1] << ' ' << spec.pose.degrees[2]
     << " scale 2^(" << spec.pose.scale_quarters << "/4) shift 0.1*(" << spec.pose.shift[0] << ' '
     << spec.pose.shift[1] << ' ' << spec.pose.shift[2] << ") level " << spec.level;
  return os.str();
}

std::string to_off(const SurfaceSpec& spec) {
  const TriangleSoup s = to_soup(spec);
  std::ostringstream os;
  os.precision(17);
  os << "OFF\n# level " << spec.level << "\n# " << describe(spec) << "\n"
     << s.vertices.size() << ' ' << s.triangles.size() << " 0\n";
  for (const P3& p : s.vertices) os << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const Triangle& t : s.triangles) os << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  return os.str();
}

rc::Gen<Pose> gen_pose() {
  return rc::gen::exec([] {
    Pose p;
    for (int& d : p.degrees) d = *rc::gen::inRange(0, 360);
    p.scale_quarters = signed_small(4);
    for (int& t : p.shift) t = signed_small(5);
    return p;
  });
}

rc::Gen<SurfaceSpec> gen_sphere_spec(int min_subdivisions) {
  return rc::gen::exec([min_subdivisions] {
    SurfaceSpec s;
    s.kind = ShapeKind::Sphere;
    s.subdivisions = min_subdivisions >= 2 ? min_subdivisions : *rc::gen::inRange(1, 3);
    for (int& h : s.harmonics) h = signed_small(3);
    s.pose = *gen_pose();
    return s;
  });
}

rc::Gen<SurfaceSpec> gen_torus_spec() {
  return rc::gen::exec([] {
    SurfaceSpec s;
    s.kind = ShapeKind::Torus;
    s.minor_step = *rc::gen::inRange(0, 5);
    s.major_segments = 12 + 4 * *rc::gen::inRange(0, 5);
    s.minor_segments = 8 + 2 * *rc::gen::inRange(0, 5);
    s.pose = *gen_pose();
    return s;
  });
}

rc::Gen<SurfaceSpec> gen_voxel_spec() {
  return rc::gen::exec([] {
    SurfaceSpec s;
    s.kind = ShapeKind::Voxels;
    s.grid = *rc::gen::inRange(2, 5);
    std::vector<int> cells;
    for (int c = 0; c < s.grid * s.grid * s.grid; ++c)
      if (*rc::gen::inRange(0, 2) == 1) cells.push_back(c);
    s.cells = manifold_voxels(s.grid, cells);
    s.pose = *gen_pose();
    return s;
  });
}

rc::Gen<SurfaceSpec> gen_surface_spec() {
  return rc::gen::exec([] {
    switch (*rc::gen::inRange(0, 3)) {
      case 0: return *gen_sphere_spec();
      case 1: return *gen_torus_spec();
      default: return *gen_voxel_spec();
    }
  });
}

void showValue(const SurfaceSpec& spec, std::ostream& os) { os << describe(spec) << "\n" << to_off(spec); }

}  // namespace febemesh::test
