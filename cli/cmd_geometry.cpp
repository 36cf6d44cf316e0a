// `febemesh geometry INPUT [--svg OUT.svg]`: what the reader and the curve kernel understood of a
// 2D input, as JSON on stdout, and optionally a drawing in the style of the paper's Figures 1-2
// (B-spline loops with their control polygons and corners).

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/args.hpp"
#include "cli/command.hpp"
#include "core/error.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/read_domain.hpp"

namespace febemesh::cli {

namespace {

using dim2::Bezier;
using dim2::CurveBoundary;
using dim2::P2;

const char* geometry_help =
    "usage: febemesh geometry INPUT [--svg OUT.svg]\n"
    "\n"
    "Reads a 2D geometry file and prints what was understood, as JSON on stdout:\n"
    "  source       the input file\n"
    "  area         total solid area (mesh units, positive)\n"
    "  bbox         [xmin, ymin, xmax, ymax] of the curves\n"
    "  components   loops that bound the solid from outside\n"
    "  holes        loops that bound a hole\n"
    "  corners      corner points (tangent jumps) over all loops\n"
    "  loops        per loop: name, signed_area (> 0 outer, < 0 hole), length, pieces (cubic\n"
    "               Bezier pieces), corners, hole\n"
    "  interior     number of interior control points; default_level (null when none)\n"
    "\n"
    "INPUT is .json (native B-spline control points, see docs/native-format.md), .svg (paths,\n"
    "basic shapes, transforms and fill-rule; mesh coordinates are (x, -y) of the user units) or\n"
    ".poly (Triangle's format: every vertex a corner).\n"
    "\n"
    "options:\n"
    "  --svg OUT.svg   also draw the loops (blue outer, red holes), the Bezier control polygons\n"
    "                  (grey), piece junctions (dots), corners (orange squares) and interior\n"
    "                  control points (green crosses with their radius)\n"
    "  -h, --help      this text\n"
    "\n"
    "exit status: 0 success, 1 bad input (message names the file, the place and the reason;\n"
    "nothing is written), 2 bad usage\n";

std::string num(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

/// SVG coordinates of a mesh point: y flips back.
std::string at(const P2& p) { return num(p.x()) + "," + num(-p.y()); }

std::string loop_path(const dim2::Loop& l) {
  // Appends only: g++ 12 warns falsely (-Wrestrict) on "literal" + std::string here.
  std::string d = "M";
  d += at(l.pieces.front()[0]);
  for (const Bezier& b : l.pieces) {
    d += " C";
    d += at(b[1]);
    d += ' ';
    d += at(b[2]);
    d += ' ';
    d += at(b[3]);
  }
  d += " Z";
  return d;
}

std::string draw_svg(const CurveBoundary& cb) {
  const Box<2> box = cb.bounding_box();
  const double size = std::max(box.extent().maxCoeff(), 1e-300);
  const double margin = 0.08 * size;
  const double sw = size / 500.0;  // stroke width: legible at any drawing size
  const double x0 = box.lo.x() - margin, y0 = -box.hi.y() - margin;
  const double w = box.extent().x() + 2 * margin, h = box.extent().y() + 2 * margin + 0.08 * size;
  std::ostringstream os;
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"" << num(x0) << " " << num(y0) << " " << num(w) << " "
     << num(h) << "\" width=\"900\" height=\"" << num(900.0 * h / w) << "\">\n";
  os << "<title>" << cb.domain().source << "</title>\n";
  os << "<rect x=\"" << num(x0) << "\" y=\"" << num(y0) << "\" width=\"" << num(w) << "\" height=\"" << num(h)
     << "\" fill=\"white\"/>\n";
  // the solid, lightly filled
  os << "<path fill=\"#dde6f3\" fill-rule=\"nonzero\" stroke=\"none\" d=\"";
  for (const auto& l : cb.loops()) os << loop_path(l) << " ";
  os << "\"/>\n";
  // control polygons and control points
  os << "<g fill=\"none\" stroke=\"#9a9a9a\" stroke-width=\"" << num(0.5 * sw) << "\" stroke-dasharray=\"" << num(3 * sw)
     << " " << num(2 * sw) << "\">\n";
  for (const auto& l : cb.loops()) {
    os << "<path d=\"M" << at(l.pieces.front()[0]);
    for (const Bezier& b : l.pieces) os << " L" << at(b[1]) << " L" << at(b[2]) << " L" << at(b[3]);
    os << "\"/>\n";
  }
  os << "</g>\n<g fill=\"#9a9a9a\">\n";
  for (const auto& l : cb.loops())
    for (const Bezier& b : l.pieces)
      for (int k = 1; k < 3; ++k) os << "<circle cx=\"" << num(b[k].x()) << "\" cy=\"" << num(-b[k].y()) << "\" r=\"" << num(1.2 * sw) << "\"/>\n";
  os << "</g>\n";
  // the curves: outer boundaries blue, holes red
  for (int i = 0; i < cb.n_loops(); ++i) {
    const auto& l = cb.loops()[std::size_t(i)];
    os << "<path fill=\"none\" stroke=\"" << (cb.is_hole(i) ? "#c0392b" : "#1f4e9c") << "\" stroke-width=\"" << num(1.6 * sw)
       << "\" d=\"" << loop_path(l) << "\"><title>" << l.name << "</title></path>\n";
  }
  // piece junctions and corners
  os << "<g fill=\"#333333\">\n";
  for (const auto& l : cb.loops())
    for (std::size_t k = 0; k < l.n_pieces(); ++k)
      if (!l.corner[k]) os << "<circle cx=\"" << num(l.pieces[k][0].x()) << "\" cy=\"" << num(-l.pieces[k][0].y()) << "\" r=\"" << num(1.5 * sw) << "\"/>\n";
  os << "</g>\n<g fill=\"#f39c12\" stroke=\"#7a4a00\" stroke-width=\"" << num(0.4 * sw) << "\">\n";
  const double cs = 3.5 * sw;
  for (const auto& c : cb.corners())
    os << "<rect x=\"" << num(c.point.x() - cs) << "\" y=\"" << num(-c.point.y() - cs) << "\" width=\"" << num(2 * cs)
       << "\" height=\"" << num(2 * cs) << "\"><title>corner, interior angle " << num(c.angle_deg) << " deg</title></rect>\n";
  os << "</g>\n";
  // interior control points
  os << "<g fill=\"none\" stroke=\"#1e8449\" stroke-width=\"" << num(0.8 * sw) << "\">\n";
  for (const auto& ic : cb.domain().interior) {
    const double x = ic.p.x(), y = -ic.p.y(), a = 3 * sw;
    os << "<path d=\"M" << num(x - a) << "," << num(y - a) << " L" << num(x + a) << "," << num(y + a) << " M" << num(x - a) << ","
       << num(y + a) << " L" << num(x + a) << "," << num(y - a) << "\"/>\n";
    if (ic.radius > 0) os << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y) << "\" r=\"" << num(ic.radius) << "\" stroke-dasharray=\"" << num(2 * sw) << "\"/>\n";
  }
  os << "</g>\n";
  // legend along the bottom
  const double fs = 0.03 * size;
  const double ly = -box.lo.y() + margin + 0.05 * size;
  double lx = x0 + margin;
  auto legend = [&](const std::string& swatch, const std::string& text) {
    os << swatch << "<text x=\"" << num(lx + 2.5 * fs) << "\" y=\"" << num(ly + 0.35 * fs) << "\" font-family=\"sans-serif\" font-size=\""
       << num(fs) << "\">" << text << "</text>\n";
    lx += (3.0 + 0.55 * static_cast<double>(text.size())) * fs;
  };
  auto line = [&](const char* colour, double width, const char* dash) {
    return "<path d=\"M" + num(lx) + "," + num(ly) + " h" + num(2 * fs) + "\" stroke=\"" + colour + "\" stroke-width=\"" + num(width) +
           "\"" + dash + " fill=\"none\"/>";
  };
  legend(line("#1f4e9c", 1.6 * sw, ""), "outer boundary");
  legend(line("#c0392b", 1.6 * sw, ""), "hole");
  legend(line("#9a9a9a", 0.5 * sw, (" stroke-dasharray=\"" + num(3 * sw) + " " + num(2 * sw) + "\"").c_str()), "control polygon");
  legend("<rect x=\"" + num(lx + fs - cs) + "\" y=\"" + num(ly - cs) + "\" width=\"" + num(2 * cs) + "\" height=\"" + num(2 * cs) +
             "\" fill=\"#f39c12\" stroke=\"#7a4a00\" stroke-width=\"" + num(0.4 * sw) + "\"/>",
         "corner (" + std::to_string(cb.corners().size()) + ")");
  os << "</svg>\n";
  return os.str();
}

/// Writes `text` to `path` atomically (a temporary file renamed over it): a failed run leaves no
/// partial output.
void write_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw InputError(path + ": cannot write");
    out << text;
    if (!out.flush()) {
      std::filesystem::remove(tmp);
      throw InputError(path + ": cannot write");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw InputError(path + ": cannot write: " + ec.message());
  }
}

int run_geometry(const std::vector<std::string>& argv) {
  Args args(argv, {}, {"--svg"});
  args.expect_positional({"INPUT"});
  const std::string input = args.positional()[0];
  const auto svg_out = args.value("--svg");
  if (svg_out && svg_out->empty()) throw UsageError("option --svg needs a file name");

  const CurveBoundary cb(dim2::read_domain(input));

  nlohmann::ordered_json j;
  j["source"] = input;
  j["area"] = cb.area();
  const Box<2> b = cb.bounding_box();
  j["bbox"] = {b.lo.x(), b.lo.y(), b.hi.x(), b.hi.y()};
  j["components"] = cb.n_components();
  j["holes"] = cb.n_holes();
  j["corners"] = cb.corners().size();
  j["loops"] = nlohmann::ordered_json::array();
  for (int i = 0; i < cb.n_loops(); ++i) {
    const auto& l = cb.loops()[std::size_t(i)];
    std::size_t corners = 0;
    for (auto c : l.corner) corners += c != 0;
    nlohmann::ordered_json lj;
    lj["name"] = l.name;
    lj["signed_area"] = cb.signed_area(i);
    lj["length"] = cb.length(i);
    lj["pieces"] = l.n_pieces();
    lj["corners"] = corners;
    lj["hole"] = cb.is_hole(i);
    j["loops"].push_back(lj);
  }
  j["interior"] = cb.domain().interior.size();
  if (cb.domain().default_level == dim2::no_level) j["default_level"] = nullptr;
  else j["default_level"] = cb.domain().default_level;

  if (svg_out) write_file(*svg_out, draw_svg(cb));
  std::cout << j.dump(2) << "\n";
  return exit_ok;
}

}  // namespace

FEBEMESH_COMMAND(Command{"geometry", "read a 2D geometry file and report its loops, area and corners (--svg draws it)",
                         geometry_help, run_geometry});

}  // namespace febemesh::cli
