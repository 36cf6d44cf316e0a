// Experiment: are febemesh's 2D meshes good finite element meshes? (issue 7, `convergence`)
//
// We solve the Poisson problem  -Laplace u = f  in the flange (examples/flange.json: curved
// fillets, a bore with a sharp keyway, four bolt holes) with the manufactured solution
//
//     u(x, y) = sin(k x) cos(k y) + x y / 10,   k = pi / 3,   so  f = 2 k^2 sin(k x) cos(k y),
//
// Dirichlet data u on every interface node (the BE mesh's nodes), on meshes of levels 4..9.
// Elements: P1 triangles, isoparametric bilinear Q1 quadrilaterals, and mixed meshes of both.
// The errors are measured on the mesh's own (polygonal) domain against the exact u, with
// quadrature exact enough not to pollute them (7-point degree-5 rule on triangles, 3x3 Gauss
// on quads). Theory for a quasi-uniform family: ||u - u_h||_L2 ~ h^2 and |u - u_h|_H1 ~ h.
//
// A convergence study needs the interior refined with the curve: the global level (--level of
// mesh2d) applies to every cell, so the meshes are quasi-uniform (finer only where the
// thickness rule refines thin parts). h is measured as sqrt(area / elements); rates are slopes between consecutive levels.
//
// Output: results/convergence/convergence.md (tables), convergence.csv, convergence.svg
// (log-log plot of both errors against h for the three element kinds).

#include <Eigen/Sparse>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/box.hpp"
#include "core/mesh.hpp"
#include "core/quality.hpp"
#include "core/svg_canvas.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

constexpr double k = std::numbers::pi / 3.0;
double u_exact(const P2& p) { return std::sin(k * p[0]) * std::cos(k * p[1]) + p[0] * p[1] / 10.0; }
P2 grad_exact(const P2& p) {
  return P2(k * std::cos(k * p[0]) * std::cos(k * p[1]) + p[1] / 10.0,
            -k * std::sin(k * p[0]) * std::sin(k * p[1]) + p[0] / 10.0);
}
double f_rhs(const P2& p) { return 2.0 * k * k * std::sin(k * p[0]) * std::cos(k * p[1]); }

/// A quadrature point on the reference element and its weight.
struct QPoint {
  double xi, eta, w;
};

/// Dunavant's 7-point rule, exact for degree 5, on the triangle (0,0), (1,0), (0,1).
std::vector<QPoint> triangle_rule() {
  std::vector<QPoint> q{{1.0 / 3, 1.0 / 3, 0.225 / 2}};
  const double a1 = 0.059715871789770, b1 = 0.470142064105115, w1 = 0.132394152788506 / 2;
  const double a2 = 0.797426985353087, b2 = 0.101286507323456, w2 = 0.125939180544827 / 2;
  for (auto [a, b, w] : {std::array{a1, b1, w1}, std::array{a2, b2, w2}}) {
    q.push_back({b, b, w});
    q.push_back({a, b, w});
    q.push_back({b, a, w});
  }
  return q;
}

/// 3 x 3 Gauss rule on [-1, 1]^2 (exact for degree 5 in each variable).
std::vector<QPoint> quad_rule() {
  const double g = std::sqrt(0.6);
  const std::array<double, 3> x{-g, 0.0, g}, w{5.0 / 9, 8.0 / 9, 5.0 / 9};
  std::vector<QPoint> q;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) q.push_back({x[i], x[j], w[i] * w[j]});
  return q;
}

/// Shape functions and their reference derivatives: P1 on the triangle, Q1 on the square
/// (Gmsh node order: counter-clockwise from (-1, -1)).
struct Shape {
  int n = 0;
  std::array<double, 4> N{};
  std::array<P2, 4> dN{};
};
Shape shape(ElemType t, double xi, double eta) {
  Shape s;
  if (t == ElemType::Tri3) {
    s.n = 3;
    s.N = {1 - xi - eta, xi, eta, 0};
    s.dN = {P2(-1, -1), P2(1, 0), P2(0, 1), P2(0, 0)};
  } else {
    s.n = 4;
    const std::array<double, 4> sx{-1, 1, 1, -1}, sy{-1, -1, 1, 1};
    for (int i = 0; i < 4; ++i) {
      s.N[i] = (1 + sx[i] * xi) * (1 + sy[i] * eta) / 4;
      s.dN[i] = P2(sx[i] * (1 + sy[i] * eta) / 4, sy[i] * (1 + sx[i] * xi) / 4);
    }
  }
  return s;
}

/// Calls visit(x, physical gradients of the shape functions, N, weight * |J|) at every quadrature
/// point of element e.
template <typename Visit> void for_each_qpoint(const Mesh<2>& m, ElemId e, Visit&& visit) {
  static const std::vector<QPoint> tri = triangle_rule(), quad = quad_rule();
  const ElemType t = m.solid.type[e.v];
  const VertexId* v = m.solid.nodes(e);
  for (const QPoint& q : t == ElemType::Tri3 ? tri : quad) {
    const Shape s = shape(t, q.xi, q.eta);
    Eigen::Matrix2d J = Eigen::Matrix2d::Zero();  // J(i, j) = d x_i / d xi_j
    P2 x = P2::Zero();
    for (int a = 0; a < s.n; ++a) {
      const P2& p = m.points[v[a].v];
      x += s.N[a] * p;
      J.col(0) += s.dN[a][0] * p;
      J.col(1) += s.dN[a][1] * p;
    }
    const double det = J.determinant();
    const Eigen::Matrix2d Jinv_t = J.inverse().transpose();
    std::array<P2, 4> grad;
    for (int a = 0; a < s.n; ++a) grad[a] = Jinv_t * s.dN[a];
    visit(x, grad, s, q.w * std::abs(det));
  }
}

struct Errors {
  std::size_t elements = 0, dofs = 0;
  double h = 0, l2 = 0, h1 = 0, seconds = 0;
};

/// Assembles, eliminates the Dirichlet (interface) nodes and solves with sparse Cholesky.
Errors solve_poisson(const Mesh<2>& m) {
  const std::size_t n = m.points.size();
  std::vector<std::uint8_t> fixed(n, 0);
  for (const VertexId v : m.interface.node) fixed[v.v] = 1;
  std::vector<int> dof(n, -1);
  int n_free = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!fixed[i]) dof[i] = n_free++;
  std::vector<double> g(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    if (fixed[i]) g[i] = u_exact(m.points[i]);

  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n_free);
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{std::int32_t(e)};
    const VertexId* v = m.solid.nodes(id);
    const int nn = m.solid.n_nodes_of(id);
    Eigen::Matrix4d K = Eigen::Matrix4d::Zero();
    Eigen::Vector4d F = Eigen::Vector4d::Zero();
    for_each_qpoint(m, id, [&](const P2& x, const std::array<P2, 4>& grad, const Shape& s, double w) {
      const double fx = f_rhs(x);
      for (int a = 0; a < nn; ++a) {
        F[a] += w * fx * s.N[a];
        for (int b = 0; b < nn; ++b) K(a, b) += w * grad[a].dot(grad[b]);
      }
    });
    for (int a = 0; a < nn; ++a) {
      const int ia = dof[v[a].v];
      if (ia < 0) continue;
      rhs[ia] += F[a];
      for (int b = 0; b < nn; ++b) {
        const int ib = dof[v[b].v];
        if (ib >= 0)
          trip.emplace_back(ia, ib, K(a, b));
        else
          rhs[ia] -= K(a, b) * g[v[b].v];
      }
    }
  }
  Eigen::SparseMatrix<double> A(n_free, n_free);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) throw std::runtime_error("the stiffness matrix is not positive definite");
  const Eigen::VectorXd x = solver.solve(rhs);
  std::vector<double> uh = g;
  for (std::size_t i = 0; i < n; ++i)
    if (dof[i] >= 0) uh[i] = x[dof[i]];

  Errors err;
  double l2 = 0, h1 = 0, area = 0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{std::int32_t(e)};
    const VertexId* v = m.solid.nodes(id);
    for_each_qpoint(m, id, [&](const P2& x, const std::array<P2, 4>& grad, const Shape& s, double w) {
      double val = 0;
      P2 gr = P2::Zero();
      for (int a = 0; a < s.n; ++a) {
        val += s.N[a] * uh[v[a].v];
        gr += grad[a] * uh[v[a].v];
      }
      l2 += w * std::pow(val - u_exact(x), 2);
      h1 += w * (gr - grad_exact(x)).squaredNorm();
      area += w;
    });
  }
  err.elements = m.solid.size();
  err.dofs = std::size_t(n_free);
  err.l2 = std::sqrt(l2);
  err.h1 = std::sqrt(h1);
  err.h = std::sqrt(area / double(m.solid.size()));
  return err;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string input = argc > 1 ? std::string(argv[1]) : std::string(FEBEMESH_SOURCE_DIR) + "/examples/flange.json";
  const std::filesystem::path out =
      argc > 2 ? std::filesystem::path(argv[2]) : std::filesystem::path(FEBEMESH_SOURCE_DIR) / "results/convergence";
  std::filesystem::create_directories(out);
  std::cout << "Poisson convergence on " << input << "\n";

  struct Run {
    ElementKind kind;
    int first, last;
  };
  // Quad meshes split every element into 3 or 4 quads, so they start one level lower.
  const std::vector<Run> runs{{ElementKind::Tri, 4, 9}, {ElementKind::Mixed, 4, 9}, {ElementKind::Quad, 3, 8}};
  std::ostringstream md, csv;
  md << "# Poisson convergence on " << std::filesystem::path(input).filename().string() << "\n\n"
     << "u = sin(kx) cos(ky) + xy/10, k = pi/3; Dirichlet data on the interface nodes; uniform global "
        "level. Rates are slopes between consecutive levels, given only where h shrinks by 25% or more (at low "
        "levels the thin parts are refined whatever the level).\n";
  csv << "kind,level,elements,dofs,h,l2_error,h1_error,seconds\n";
  std::vector<std::pair<std::string, std::vector<Errors>>> all;
  for (const Run& run : runs) {
    md << "\n## " << name(run.kind) << "\n\n| level | elements | dofs | h | L2 error | rate | H1 error | rate | s |\n"
       << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::vector<Errors> errs;
    for (int level = run.first; level <= run.last; ++level) {
      CurveBoundary curve(read_domain(input));
      curve.set_global_level(level);
      Options2d opt;
      opt.level = level;
      opt.elements = run.kind;
      opt.keep_stages = false;
      const auto t0 = std::chrono::steady_clock::now();
      const Result2d r = mesh2d(curve, opt);
      Errors e = solve_poisson(r.fe.mesh);
      e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      char line[256];
      // A rate needs h to shrink: at low levels the thickness rule and the repairs refine the
      // thin parts of the flange whatever the level, so consecutive levels can have nearly the
      // same h (or a larger one), and a slope over them means nothing.
      if (errs.empty() || errs.back().h / e.h < 1.25) {
        std::snprintf(line, sizeof line, "| %d | %zu | %zu | %.4g | %.3e | - | %.3e | - | %.2f |\n", level, e.elements,
                      e.dofs, e.h, e.l2, e.h1, e.seconds);
      } else {
        const Errors& p = errs.back();
        const double lh = std::log(p.h / e.h);
        std::snprintf(line, sizeof line, "| %d | %zu | %zu | %.4g | %.3e | %.2f | %.3e | %.2f | %.2f |\n", level,
                      e.elements, e.dofs, e.h, e.l2, std::log(p.l2 / e.l2) / lh, e.h1, std::log(p.h1 / e.h1) / lh,
                      e.seconds);
      }
      md << line;
      std::cout << name(run.kind) << " " << line;
      csv << name(run.kind) << "," << level << "," << e.elements << "," << e.dofs << "," << e.h << "," << e.l2 << ","
          << e.h1 << "," << e.seconds << "\n";
      errs.push_back(e);
    }
    all.emplace_back(name(run.kind), errs);
  }
  std::ofstream(out / "convergence.md") << md.str();
  std::ofstream(out / "convergence.csv") << csv.str();

  // Log-log plot: x = -log10 h (finer to the right), y = log10 error; solid L2, dashed-looking
  // (thinner) H1, with reference slopes 2 and 1.
  SvgCanvas svg(720.0, 40.0);
  double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9;
  for (const auto& [kind, errs] : all)
    for (const Errors& e : errs) {
      xmin = std::min(xmin, -std::log10(e.h));
      xmax = std::max(xmax, -std::log10(e.h));
      ymin = std::min({ymin, std::log10(e.l2), std::log10(e.h1)});
      ymax = std::max({ymax, std::log10(e.l2), std::log10(e.h1)});
    }
  const double sx = 2.0 / (xmax - xmin), sy = 1.4 / (ymax - ymin);
  auto at = [&](double lx, double ly) { return P2((lx - xmin) * sx, (ly - ymin) * sy); };
  int c = 0;
  for (const auto& [kind, errs] : all) {
    std::vector<P2> l2, h1;
    for (const Errors& e : errs) {
      l2.push_back(at(-std::log10(e.h), std::log10(e.l2)));
      h1.push_back(at(-std::log10(e.h), std::log10(e.h1)));
    }
    svg.polyline(l2, SvgStyle{"none", svg_palette(c), 2.0, 1.0});
    svg.polyline(h1, SvgStyle{"none", svg_palette(c), 1.0, 1.0});
    for (const P2& p : l2) svg.dot(p, 3.0, SvgStyle{svg_palette(c), "none", 0.0, 1.0});
    for (const P2& p : h1) svg.dot(p, 2.0, SvgStyle{svg_palette(c), "none", 0.0, 1.0});
    svg.text(P2(2.1, 1.4 - 0.1 * c), kind + " (thick: L2, thin: H1)", 13.0, svg_palette(c));
    ++c;
  }
  const double x0 = xmin, x1 = xmax;
  svg.polyline({at(x0, ymin + 0.2), at(x1, ymin + 0.2 - 2 * (x1 - x0))}, SvgStyle{"none", "#888888", 0.8, 1.0});
  svg.polyline({at(x0, ymax), at(x1, ymax - (x1 - x0))}, SvgStyle{"none", "#888888", 0.8, 1.0});
  svg.text(P2(2.1, 0.2), "grey: slopes 2 and 1", 12.0, "#555555");
  svg.text(P2(0.0, -0.12), "x: -log10 h (finer to the right), y: log10 error", 12.0);
  svg.write(out / "convergence.svg");
  std::cout << "wrote " << (out / "convergence.md").string() << ", convergence.csv, convergence.svg\n";
  return 0;
}
