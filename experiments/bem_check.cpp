// Experiment: is febemesh's BE mesh usable by a boundary element method? (issue 7, `bem_check`)
//
// The capacity problem of a conductor in the plane: find the charge density sigma on the
// boundary curve Gamma with a unit potential,
//
//     V sigma (x) = -1/(2 pi) \int_Gamma log|x - y| sigma(y) ds_y = 1   for x on Gamma,
//
// and its total charge Q = \int_Gamma sigma ds. The closed form: the equilibrium measure of
// Gamma has the constant potential -log(c) / (2 pi), c = the logarithmic capacity, so
// Q = -2 pi / log c. For an ellipse with semi-axes a, b, c = (a + b) / 2 (a circle: its radius).
//
// The curve is built in code as a native Domain: 32 cubic Bezier arcs of the unit circle
// (the standard 4/3 tan(theta/4) handles; relative radial error ~1e-9), scaled to the ellipse.
// febemesh meshes it at increasing levels; the BE method uses the interface mesh ALONE:
// piecewise constant sigma on its straight edges, collocation at edge midpoints, the log
// kernel integrated exactly over each edge (self term included). The error of Q against the
// closed form should fall like h^2 (chords of a smooth curve, midpoint collocation).
//
// Output: results/bem_check/bem_check.md and bem_check.csv.

#include <Eigen/Dense>
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

#include "dim2/curve_boundary.hpp"
#include "dim2/curve_model.hpp"
#include "dim2/pipeline2d.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

constexpr double pi = std::numbers::pi;

/// An ellipse with semi-axes a, b centred at the origin: n cubic Bezier arcs of the unit circle,
/// scaled (an affine image of a Bezier is the Bezier of the images).
Loop ellipse_loop(double a, double b, int n) {
  std::vector<Bezier> pieces;
  const double dt = 2 * pi / n, h = 4.0 / 3.0 * std::tan(dt / 4);
  for (int i = 0; i < n; ++i) {
    const double t0 = i * dt, t1 = (i + 1) * dt;
    const P2 p0(std::cos(t0), std::sin(t0)), p3(std::cos(t1), std::sin(t1));
    const P2 d0(-std::sin(t0), std::cos(t0)), d3(-std::sin(t1), std::cos(t1));
    Bezier q{p0, p0 + h * d0, p3 - h * d3, p3};
    for (P2& p : q) p = P2(a * p[0], b * p[1]);
    pieces.push_back(q);
  }
  pieces.back()[3] = pieces.front()[0];  // close exactly
  return loop_from_beziers(std::move(pieces), "ellipse");
}

/// \int over the segment [A, B] of log|x - y| ds_y, exactly.
double log_integral(const P2& x, const P2& A, const P2& B) {
  const double len = (B - A).norm();
  const P2 t = (B - A) / len;
  const double s0 = (A - x).dot(t), s1 = (B - x).dot(t);          // along the line, from the foot
  const double d = std::abs((A - x)[0] * t[1] - (A - x)[1] * t[0]);  // distance to the line
  // F(s) = \int 0.5 log(s^2 + d^2) ds.
  auto F = [d](double s) {
    const double r2 = s * s + d * d;
    const double slog = s == 0.0 ? 0.0 : 0.5 * s * std::log(r2);
    return slog - s + (d > 0 ? d * std::atan2(s, d) : 0.0);
  };
  return F(s1) - F(s0);
}

struct Row {
  int level = 0;
  std::size_t n = 0;
  double h = 0, q = 0, err = 0, seconds = 0;
};

Row solve(double a, double b, int level) {
  Domain d;
  d.loops.push_back(ellipse_loop(a, b, 32));
  d.source = "ellipse (in code)";
  CurveBoundary curve(std::move(d));
  curve.set_global_level(level);
  Options2d opt;
  opt.level = level;
  opt.keep_stages = false;
  const auto t0 = std::chrono::steady_clock::now();
  const Result2d r = mesh2d(curve, opt);
  const Mesh<2>& m = r.fe.mesh;
  const std::size_t n = m.interface.size();
  std::vector<P2> A(n), B(n), mid(n);
  std::vector<double> len(n);
  double hmax = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const VertexId* v = m.interface.nodes(ElemId{std::int32_t(e)});
    A[e] = m.points[v[0].v];
    B[e] = m.points[v[1].v];
    mid[e] = (A[e] + B[e]) / 2;
    len[e] = (B[e] - A[e]).norm();
    hmax = std::max(hmax, len[e]);
  }
  Eigen::MatrixXd V(n, n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) V(i, j) = -log_integral(mid[i], A[j], B[j]) / (2 * pi);
  const Eigen::VectorXd sigma = V.partialPivLu().solve(Eigen::VectorXd::Ones(Eigen::Index(n)));
  Row row;
  row.level = level;
  row.n = n;
  row.h = hmax;
  for (std::size_t e = 0; e < n; ++e) row.q += sigma[Eigen::Index(e)] * len[e];
  const double exact = -2 * pi / std::log((a + b) / 2);
  row.err = std::abs(row.q - exact) / exact;
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out =
      argc > 1 ? std::filesystem::path(argv[1]) : std::filesystem::path(FEBEMESH_SOURCE_DIR) / "results/bem_check";
  std::filesystem::create_directories(out);
  std::ostringstream md, csv;
  md << "# BEM check: capacity of a circle and an ellipse on febemesh's BE mesh\n\n"
     << "Constant elements, midpoint collocation, exact log integrals; Q = -2 pi / log((a+b)/2).\n";
  csv << "a,b,level,be_elements,h_max,charge,rel_error,seconds\n";
  for (auto [a, b] : {std::pair{0.5, 0.5}, std::pair{0.5, 0.25}}) {
    const double exact = -2 * pi / std::log((a + b) / 2);
    md << "\n## a = " << a << ", b = " << b << " (closed form Q = " << exact << ")\n\n"
       << "| level | BE elements | max h | Q | rel. error | rate | s |\n|---:|---:|---:|---:|---:|---:|---:|\n";
    std::cout << "ellipse a = " << a << ", b = " << b << ": exact Q = " << exact << "\n";
    Row prev;
    for (int level = 3; level <= 8; ++level) {
      const Row r = solve(a, b, level);
      char line[256];
      // A rate only where the elements got smaller (the ellipse's tips refine levels 3-4 alike:
      // the same mesh twice gave 0/0).
      if (prev.n == 0 || !(r.h < 0.9 * prev.h))
        std::snprintf(line, sizeof line, "| %d | %zu | %.4g | %.8f | %.3e | - | %.2f |\n", r.level, r.n, r.h, r.q,
                      r.err, r.seconds);
      else
        std::snprintf(line, sizeof line, "| %d | %zu | %.4g | %.8f | %.3e | %.2f | %.2f |\n", r.level, r.n, r.h, r.q,
                      r.err, std::log(prev.err / r.err) / std::log(prev.h / r.h), r.seconds);
      md << line;
      std::cout << line;
      csv << a << "," << b << "," << r.level << "," << r.n << "," << r.h << "," << r.q << "," << r.err << ","
          << r.seconds << "\n";
      prev = r;
    }
  }
  std::ofstream(out / "bem_check.md") << md.str();
  std::ofstream(out / "bem_check.csv") << csv.str();
  std::cout << "wrote " << (out / "bem_check.md").string() << "\n";
  return 0;
}
